#include "sim/writer_error_injector.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "sim/writer_random.hpp"

namespace calligraphy::writer_detail {

namespace {

constexpr double kMidLiftHeight_m = 0.003;  // a lift in the middle of a stroke: how high,
constexpr double kMidLift_s = 0.12;         // how long up and down,
constexpr double kMidLiftHold_s = 0.1;      // and how long the pen stays up
constexpr double kStrayDistance_m = 0.004;  // a touch outside the box lands this far outside it
constexpr double kStrayLength_m = 0.004;    // and slides this far along it

}  // namespace

Vec2 WriterErrorInjector::draw_character_offset(std::mt19937_64& rng) const {
  const double angle = 2.0 * std::numbers::pi * uniform(rng);
  return profile_->bias_offset_m * Vec2(std::cos(angle), std::sin(angle));
}

std::vector<std::size_t> WriterErrorInjector::draw_stroke_order(std::size_t stroke_count,
                                                                std::mt19937_64& rng) const {
  std::vector<std::size_t> order(stroke_count);
  for (std::size_t i = 0; i < stroke_count; ++i) order[i] = i;
  for (std::size_t i = 0; i + 1 < stroke_count;) {
    if (uniform(rng) < profile_->order_error_probability) {
      std::swap(order[i], order[i + 1]);
      i += 2;
    } else {
      i += 1;
    }
  }
  return order;
}

bool WriterErrorInjector::draw_backwards(std::mt19937_64& rng) const {
  return uniform(rng) < profile_->backwards_probability;
}

AttemptErrors WriterErrorInjector::draw_attempt(double care, std::mt19937_64& rng) const {
  const WriterProfile& p = *profile_;
  AttemptErrors e;
  e.outside_touch = uniform(rng) < care * p.outside_touch_probability;
  e.hesitate = uniform(rng) < care * p.hesitation_probability;
  e.hesitation_where = uniform(rng);
  e.hesitation_s = p.hesitation_s * (0.5 + uniform(rng));
  e.mid_stroke_lift = uniform(rng) < care * p.mid_stroke_lift_probability;
  e.lift_where = uniform(rng);
  e.lift_fraction = 0.3 + 0.4 * uniform(rng);
  e.jitter_m = care * p.stroke_jitter_m * gaussian_pair(rng);
  return e;
}

Vec3 WriterErrorInjector::add_outside_touch(std::vector<Segment>& program, const PlacedCharacter& character,
                                            const Vec3& from, double paper_z_m) const {
  const WriterProfile& profile = *profile_;
  const Eigen::AlignedBox2d& box = character.bounding_box;
  const Vec2 p = from.head<2>();
  const Vec2 lo = box.min();
  const Vec2 hi = box.max();
  const double y = std::clamp(p.y(), lo.y(), hi.y());
  const double x = std::clamp(p.x(), lo.x(), hi.x());
  const Vec2 candidates[4] = {Vec2(lo.x() - kStrayDistance_m, y), Vec2(hi.x() + kStrayDistance_m, y),
                              Vec2(x, lo.y() - kStrayDistance_m), Vec2(x, hi.y() + kStrayDistance_m)};
  std::size_t best = 0;
  for (std::size_t i = 1; i < 4; ++i) {
    if ((candidates[i] - p).norm() < (candidates[best] - p).norm()) best = i;
  }
  const Vec2 touch = candidates[best];
  const Vec2 centre = box.center();
  const Vec2 slide = best < 2 ? Vec2(0.0, centre.y() > touch.y() ? 1.0 : -1.0)
                              : Vec2(centre.x() > touch.x() ? 1.0 : -1.0, 0.0);
  const Vec2 end = touch + kStrayLength_m * slide;
  const double up = paper_z_m + profile.lift_height_m;
  const double down = paper_z_m - 0.5 * profile.press_depth_m;  // a light touch
  program.push_back(make_segment(SegmentKind::travel,
                                 {from, Vec3(p.x(), p.y(), std::max(from.z(), up)), on_plane(touch, up)},
                                 profile.travel_speed_m_s, kTravelMinimum_s));
  program.push_back(make_segment(SegmentKind::touch, {on_plane(touch, up), on_plane(touch, down)},
                                 profile.travel_speed_m_s, kTouchDown_s));
  program.push_back(make_segment(SegmentKind::stray, {on_plane(touch, down), on_plane(end, down)},
                                 profile.writing_speed_m_s, kMinimumLeg_s));
  program.push_back(make_segment(SegmentKind::lift, {on_plane(end, down), on_plane(end, up)},
                                 profile.travel_speed_m_s, kLift_s));
  return on_plane(end, up);
}

HesitationPlace WriterErrorInjector::place_hesitation(const AttemptErrors& errors, std::size_t leg_count) {
  HesitationPlace place;
  place.before_stroke = errors.hesitate && (leg_count < 2 || errors.hesitation_where < 0.5);
  place.after_leg =
      errors.hesitate && !place.before_stroke
          ? std::min(leg_count - 2, static_cast<std::size_t>(2.0 * (errors.hesitation_where - 0.5) *
                                                             static_cast<double>(leg_count - 1)))
          : leg_count;
  return place;
}

Segment WriterErrorInjector::hesitation(const Vec3& at, const AttemptErrors& errors) {
  return make_segment(SegmentKind::pause, {at}, 1.0, errors.hesitation_s);
}

std::size_t WriterErrorInjector::lifted_leg(const AttemptErrors& errors, std::size_t leg_count) {
  return errors.mid_stroke_lift
             ? std::min(leg_count - 1,
                        static_cast<std::size_t>(errors.lift_where * static_cast<double>(leg_count)))
             : leg_count;
}

void WriterErrorInjector::add_lifted_leg(std::vector<Segment>& program, const std::vector<Vec3>& path,
                                         double proper_m, double lift_fraction, double paper_z_m) const {
  const WriterProfile& profile = *profile_;
  // Split at lift_fraction of the leg: write, lift, hold, touch down again, write on.
  const double split_m = lift_fraction * proper_m;
  std::vector<Vec3> first{path.front()};
  std::vector<Vec3> second;
  double run_m = 0.0;
  std::size_t i = 1;
  for (; i < path.size(); ++i) {
    const double step = (path[i] - path[i - 1]).norm();
    if (run_m + step >= split_m && step > 0.0) {
      const Vec3 split = path[i - 1] + ((split_m - run_m) / step) * (path[i] - path[i - 1]);
      first.push_back(split);
      second.push_back(split);
      break;
    }
    run_m += step;
    first.push_back(path[i]);
  }
  for (; i < path.size(); ++i) second.push_back(path[i]);
  if (second.empty()) second.push_back(first.back());
  const Vec3 split = first.back();
  const Vec3 raised(split.x(), split.y(), paper_z_m + kMidLiftHeight_m);
  program.push_back(make_write_segment(std::move(first), profile.writing_speed_m_s));
  program.push_back(make_segment(SegmentKind::lift, {split, raised}, profile.travel_speed_m_s, kMidLift_s));
  program.back().mid_stroke = true;
  program.push_back(make_segment(SegmentKind::pause, {raised}, 1.0, kMidLiftHold_s));
  program.back().mid_stroke = true;
  program.push_back(make_segment(SegmentKind::touch, {raised, split}, profile.travel_speed_m_s, kMidLift_s));
  program.back().mid_stroke = true;
  program.push_back(
      make_write_segment(std::move(second), profile.writing_speed_m_s, std::max(0.0, proper_m - split_m)));
}

}  // namespace calligraphy::writer_detail
