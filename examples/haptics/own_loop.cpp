// A haptic application's own servo loop on the simulated device, linking `calligraphy::haptics` only.
//
// The one way to tick from your own loop is `TrialSession::step` (trial/session.hpp): read the device, step,
// write the force. The one way to move a simulated pen is a `HandModel` attached to the device's hand port,
// and `advance(dt_s)` once per tick after the force is written: the simulated device's time passes only
// then. Forget it and the next `read_state` returns `DeviceFault::not_advanced` instead of a pen at rest.
//
// The hand here is the application's own: a spring-damper grip (150 N/m, 4 N s/m: a relaxed grip, as the
// simulated writers of `calligraphy::research` assume) pulled along each stroke's centre line at 4 cm/s,
// pressing 1 mm into the paper, lifted 1 cm between strokes.
#include <calligraphy/devices/simulated_device.hpp>
#include <calligraphy/model/character_library.hpp>
#include <calligraphy/model/scene.hpp>
#include <calligraphy/trial/session.hpp>
#include <cmath>
#include <cstdio>
#include <vector>

namespace {

using calligraphy::Vec2;
using calligraphy::Vec3;

// A point that moves along a polyline at a constant speed, and the spring-damper that pulls the pen to it.
class PathFollowingHand final : public calligraphy::HandModel {
 public:
  PathFollowingHand(std::vector<Vec3> path_m, double speed_m_s) : path_m_(std::move(path_m)), speed_(speed_m_s) {
    arc_m_.push_back(0.0);
    for (std::size_t i = 1; i < path_m_.size(); ++i) arc_m_.push_back(arc_m_.back() + (path_m_[i] - path_m_[i - 1]).norm());
  }
  [[nodiscard]] double duration_s() const { return arc_m_.back() / speed_; }

  Vec3 hand_force(double time_s, const Vec3& position_m, const Vec3& velocity_m_s) override {
    return kStiffness * (target(time_s) - position_m) - kDamping * velocity_m_s;
  }

 private:
  static constexpr double kStiffness = 150.0;  // [N/m]
  static constexpr double kDamping = 4.0;      // [N s/m]

  [[nodiscard]] Vec3 target(double time_s) const {
    const double s = std::min(time_s * speed_, arc_m_.back());
    std::size_t i = 1;
    while (i + 1 < arc_m_.size() && arc_m_[i] < s) ++i;
    const double span = arc_m_[i] - arc_m_[i - 1];
    const double t = span > 0.0 ? (s - arc_m_[i - 1]) / span : 1.0;
    return path_m_[i - 1] + t * (path_m_[i] - path_m_[i - 1]);
  }

  std::vector<Vec3> path_m_;
  std::vector<double> arc_m_;
  double speed_;
};

// Down onto each stroke's start, along its centre line, up, over to the next: the path a writer's hand takes.
std::vector<Vec3> writing_path(const calligraphy::Scene& scene, const Vec3& rest_m) {
  const double paper_z = scene.layout.paper_z_m;
  std::vector<Vec3> path{rest_m};
  for (const auto& character : scene.characters) {
    for (const auto& stroke : character.strokes) {
      const Vec2& start = stroke.centre_line.points_m.front();
      path.emplace_back(start.x(), start.y(), paper_z + 0.010);
      for (const Vec2& point : stroke.centre_line.points_m) path.emplace_back(point.x(), point.y(), paper_z - 0.001);
      const Vec2& end = stroke.centre_line.points_m.back();
      path.emplace_back(end.x(), end.y(), paper_z + 0.010);
    }
  }
  return path;
}

}  // namespace

int main() {
  using namespace calligraphy;
  const Scene scene = Scene::lay_out({CharacterLibrary::embedded().load(U'十')});

  SimulatedDevice device;  // a Phantom Desktop-like point mass; its time is the program's to advance
  device.open();
  PathFollowingHand hand(writing_path(scene, SimulatedDeviceParameters{}.initial_position_m), 0.04);
  device.hand_port()->attach_hand(&hand);

  TrialOptions options;  // the force law's defaults, 1 kHz
  TrialSession session(scene, device.info(), options);
  const double period_s = 1.0 / options.rate_hz;

  DeviceState state;
  DeviceFault fault = DeviceFault::none;
  for (;;) {  // the application's loop: here lock-step, as fast as it runs; on hardware, every 1 ms
    if ((fault = device.read_state(state)) != DeviceFault::none) break;
    const ServoCommand command = session.step(state);
    if ((fault = device.write_force(command.force_n)) != DeviceFault::none) break;
    if (command.stop || state.time_s > hand.duration_s() + 1.0) break;
    device.hand_port()->advance(period_s);  // the simulated pen moves only here
  }
  const TrialResult result = fault == DeviceFault::none
                                 ? session.finish(session.finished() ? TrialEnd::completed : TrialEnd::time_limit)
                                 : session.finish(TrialEnd::device_fault, device_fault_message(fault, device.info().model));
  device.hand_port()->attach_hand(nullptr);
  device.close();

  const TrialMetrics& m = result.metrics;
  std::printf("十 from the application's own loop: %zu/%zu strokes in %.2f s, mean deviation %.2f mm%s\n",
              m.strokes_completed, m.strokes_total, m.time_s, m.mean_deviation_m.value_or(std::nan("")) * 1e3,
              result.aborted ? " (aborted)" : "");

  // The misuse the simulated device refuses: read, command, read again without advance().
  SimulatedDevice forgetful;
  forgetful.open();
  forgetful.hand_port()->attach_hand(&hand);
  DeviceState first;
  (void)forgetful.read_state(first);
  (void)forgetful.write_force(Vec3::Zero());
  const DeviceFault refused = forgetful.read_state(first);
  std::printf("reading without advance(): %s\n", device_fault_name(refused));

  return !result.aborted && m.strokes_completed == m.strokes_total && refused == DeviceFault::not_advanced ? 0 : 1;
}
