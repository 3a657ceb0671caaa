#include "trainer/scene_view.hpp"

#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "calligraphy/model/polyline.hpp"
#include "trainer/triangulate.hpp"

namespace calligraphy::trainer {
namespace {

// Colours (RGBA): the paper's blue reference, yellow active character, light green trajectory, red hint.
constexpr ImU32 kPaper = IM_COL32(255, 255, 255, 255);
constexpr ImU32 kGrid = IM_COL32(225, 225, 225, 255);
constexpr ImU32 kOutline = IM_COL32(214, 214, 214, 255);
constexpr ImU32 kActive = IM_COL32(255, 214, 0, 255);
constexpr ImU32 kReference = IM_COL32(0, 60, 255, 255);
constexpr ImU32 kTrace = IM_COL32(110, 230, 110, 255);
// A refused attempt stays until the next touch-down, greyed so that it reads as not written next to the
// green of the written strokes, yet stays visible on the yellow of the active character.
constexpr ImU32 kRefused = IM_COL32(150, 150, 150, 255);
constexpr ImU32 kHint = IM_COL32(235, 0, 0, 255);
constexpr ImU32 kPen = IM_COL32(40, 40, 40, 255);
constexpr ImU32 kVirtualTip = IM_COL32(255, 120, 0, 255);
constexpr ImU32 kForce = IM_COL32(150, 0, 200, 255);
// The quiz (after Hanzi Writer's look: drawing colour #333, highlight #AAF): an accepted stroke filled in
// green, a miss's trace in red for kMissFlashS, the expected stroke in light blue-violet after a hint.
constexpr ImU32 kQuizAccepted = IM_COL32(20, 150, 60, 255);
constexpr ImU32 kQuizInk = IM_COL32(51, 51, 51, 255);
constexpr ImU32 kQuizMiss = IM_COL32(230, 0, 0, 255);
constexpr ImU32 kQuizHint = IM_COL32(170, 170, 255, 255);
constexpr double kMissFlashS = 0.5;
// The demonstration's ink (Hanzi Writer's stroke colour #555) and its stroke numbers; the active stroke of
// the learner's view (a deeper yellow than its character's).
constexpr ImU32 kDemoInk = IM_COL32(85, 85, 85, 255);
constexpr ImU32 kNumber = IM_COL32(200, 30, 30, 255);
constexpr ImU32 kActiveStroke = IM_COL32(250, 186, 0, 255);

// Window pixel of a point of the view's trial [m].
Vec2 trial_to_screen(const WindowLayout& layout, const TrialView& view, const Vec2& trial_m) {
  return view.whole_row ? layout.row_to_screen(trial_m) : layout.to_screen(view.character, trial_m);
}

ImVec2 im(const Vec2& v) { return ImVec2(static_cast<float>(v.x()), static_cast<float>(v.y())); }

void fill_polygon(ImDrawList& draw, const std::vector<ImVec2>& points,
                  const std::vector<std::array<int, 3>>& triangles, ImU32 colour) {
  for (const auto& t : triangles) {
    draw.AddTriangleFilled(points[static_cast<std::size_t>(t[0])], points[static_cast<std::size_t>(t[1])],
                           points[static_cast<std::size_t>(t[2])], colour);
  }
}

void draw_ellipse(ImDrawList& draw, const Vec2& centre, double rx, double ry, ImU32 colour, float thickness) {
  constexpr int kSegments = 48;
  for (int i = 0; i < kSegments; ++i) {
    const double a = 2.0 * 3.14159265358979 * i / kSegments;
    draw.PathLineTo(ImVec2(static_cast<float>(centre.x() + rx * std::cos(a)),
                           static_cast<float>(centre.y() + ry * std::sin(a))));
  }
  draw.PathStroke(colour, ImDrawFlags_Closed, thickness);
}

void draw_arrow(ImDrawList& draw, const Vec2& from, const Vec2& to, ImU32 colour) {
  const Vec2 d = to - from;
  const double length = d.norm();
  if (length < 3.0) return;
  const Vec2 u = d / length;
  const Vec2 n(-u.y(), u.x());
  const double head = std::min(12.0, 0.5 * length);
  draw.AddLine(im(from), im(to - head * u), colour, 3.0f);
  draw.AddTriangleFilled(im(to), im(to - head * u + 0.45 * head * n), im(to - head * u - 0.45 * head * n),
                         colour);
}

// The pen's height on a vertical gauge at the right edge of the drawing area: the paper at 0, +20 mm
// above, -10 mm below; the HIP as a dark bar, the VTP (on the paper when the HIP is below) as an orange
// ring.
void draw_height_gauge(ImDrawList& draw, const WindowLayout& layout, const DisplaySnapshot& s) {
  const float x = static_cast<float>(layout.area_width_px() - 48.0);
  const float top = 60.0f;
  const float bottom = static_cast<float>(layout.height_px() - 60.0);
  constexpr double kAboveM = 0.02;
  constexpr double kBelowM = 0.01;
  const auto y_of = [&](double height_m) {
    const double f = (kAboveM - std::clamp(height_m, -kBelowM, kAboveM)) / (kAboveM + kBelowM);
    return top + static_cast<float>(f) * (bottom - top);
  };
  draw.AddRectFilled(ImVec2(x - 6, top), ImVec2(x + 6, bottom), IM_COL32(240, 240, 240, 255), 3.0f);
  draw.AddLine(ImVec2(x - 14, y_of(0.0)), ImVec2(x + 14, y_of(0.0)), IM_COL32(120, 120, 120, 255), 2.0f);
  draw.AddText(ImVec2(x - 70, y_of(0.0) - 10), IM_COL32(90, 90, 90, 255), "paper");
  const float hip = y_of(s.pen_height_m);
  draw.AddRectFilled(ImVec2(x - 10, hip - 2), ImVec2(x + 10, hip + 2), kPen);
  if (s.hip_m.z != s.vtp_m.z) draw.AddCircle(ImVec2(x, y_of(0.0)), 7.0f, kVirtualTip, 16, 2.5f);
  char text[32];
  std::snprintf(text, sizeof text, "%+.1f mm", s.pen_height_m * 1e3);
  draw.AddText(ImVec2(x - 40, bottom + 6), IM_COL32(60, 60, 60, 255), text);
}

}  // namespace

CharacterArt prepare_art(const TrainerCharacter& character) {
  CharacterArt art;
  for (std::size_t s = 0; s < character.outlines.strokes.size(); ++s) {
    for (const OutlinePolygon& polygon : character.outlines.strokes[s]) {
      art.polygons.push_back(polygon);
      art.triangles.push_back(triangulate(polygon));
      art.polygon_stroke.push_back(s);
    }
  }
  for (const Stroke& stroke : character.model.strokes) {
    std::vector<Vec2> points;
    for (const StrokeElement& e : stroke.elements) {
      for (const Vec2& p : sample_element(e, e.degree == 1 ? 1 : 24)) {
        if (points.empty() || points.back() != p) points.push_back(p);
      }
    }
    art.reference.push_back(std::move(points));
  }
  return art;
}

namespace {

// A stroke's colour in a quiz: accepted, assisted (in the demonstration's ink, as a trial's assisted stroke
// stays), hinted, or the plain outline; per character of the row.
ImU32 quiz_fill(const TrialView& view, std::size_t row_character, std::size_t stroke) {
  const std::size_t q = view.whole_row ? row_character : 0;
  if (!view.whole_row && row_character != view.character) return kOutline;
  if (q >= view.quiz->sessions().size()) return kOutline;
  if (stroke < view.quiz->sessions()[q].current_stroke())
    return view.quiz->assisted(q, stroke) ? kDemoInk : kQuizAccepted;
  if (view.quiz->hinted()[q] == stroke) return kQuizHint;
  return kOutline;
}

void draw_ink(ImDrawList& draw, const WindowLayout& layout, const TrialView& view,
              const std::vector<Vec2>& points_m, ImU32 colour) {
  std::vector<ImVec2> points;
  for (const Vec2& p : points_m) points.push_back(im(trial_to_screen(layout, view, p)));
  if (points.size() == 1) draw.AddCircleFilled(points[0], 3.0f, colour);
  if (points.size() > 1) draw.AddPolyline(points.data(), static_cast<int>(points.size()), colour, 0, 6.0f);
}

// The quiz's ink over the outlines: the stroke being written, and each miss for a moment.
void draw_quiz_ink(ImDrawList& draw, const WindowLayout& layout, const TrialView& view) {
  const auto now = std::chrono::steady_clock::now();
  for (const QuizInk& ink : view.quiz->inks()) {
    if (ink.verdict != QuizEvent::Kind::stroke_missed) continue;
    if (std::chrono::duration<double>(now - ink.judged_at).count() < kMissFlashS)
      draw_ink(draw, layout, view, ink.points_m, kQuizMiss);
  }
  draw_ink(draw, layout, view, view.quiz->open_run(), kQuizInk);
}

void fill_stroke(ImDrawList& draw, const WindowLayout& layout, const CharacterArt& art, std::size_t box,
                 std::size_t stroke, ImU32 colour) {
  const ImDrawListFlags flags = draw.Flags;
  draw.Flags &= ~ImDrawListFlags_AntiAliasedFill;
  for (std::size_t p = 0; p < art.polygons.size(); ++p) {
    if (art.polygon_stroke[p] != stroke) continue;
    std::vector<ImVec2> points;
    for (const Vec2& v : art.polygons[p]) points.push_back(im(layout.data_to_screen(box, v)));
    fill_polygon(draw, points, art.triangles[p], colour);
  }
  draw.Flags = flags;
}

// Arc length along `line` (screen points) of the point of it nearest to `p`.
double arc_of_nearest(const std::vector<Vec2>& line, const Vec2& p) {
  double best_distance = std::numeric_limits<double>::infinity();
  double best_arc = 0.0;
  double arc = 0.0;
  for (std::size_t i = 1; i < line.size(); ++i) {
    const Vec2 d = line[i] - line[i - 1];
    const double length = d.norm();
    const double t = length > 0.0 ? std::clamp((p - line[i - 1]).dot(d) / (length * length), 0.0, 1.0) : 0.0;
    const double distance = (line[i - 1] + t * d - p).norm();
    if (distance < best_distance) {
      best_distance = distance;
      best_arc = arc + t * length;
    }
    arc += length;
  }
  return best_arc;
}

// Fills the part of triangle (a, b, c) whose pieces lie, along `median`, at most `reached` from its start:
// the triangle is split at its longest edge until the pieces are smaller than kPiecePx, so that the ink
// reveals the outline along the median as a brush would, never leaving it.
constexpr double kPiecePx = 5.0;
void fill_reached(ImDrawList& draw, const Vec2& a, const Vec2& b, const Vec2& c,
                  const std::vector<Vec2>& median, double reached, ImU32 colour, int depth) {
  const double ab = (b - a).norm();
  const double bc = (c - b).norm();
  const double ca = (a - c).norm();
  if (std::max({ab, bc, ca}) <= kPiecePx || depth > 14) {
    if (arc_of_nearest(median, (a + b + c) / 3.0) <= reached)
      draw.AddTriangleFilled(im(a), im(b), im(c), colour);
    return;
  }
  if (ab >= bc && ab >= ca) {
    const Vec2 m = (a + b) / 2.0;
    fill_reached(draw, a, m, c, median, reached, colour, depth + 1);
    fill_reached(draw, m, b, c, median, reached, colour, depth + 1);
  } else if (bc >= ca) {
    const Vec2 m = (b + c) / 2.0;
    fill_reached(draw, a, b, m, median, reached, colour, depth + 1);
    fill_reached(draw, a, m, c, median, reached, colour, depth + 1);
  } else {
    const Vec2 m = (c + a) / 2.0;
    fill_reached(draw, a, b, m, median, reached, colour, depth + 1);
    fill_reached(draw, m, b, c, median, reached, colour, depth + 1);
  }
}

// A stroke being drawn by a demonstration: its outline filled as far as the first `fraction` of its median
// (mapped to the screen by `to_screen`) reaches, as Hanzi Writer reveals a stroke through the outline; the
// whole outline once drawn. Without an outline, ink along the median.
template <typename ToScreen>
void draw_stroke_drawn(ImDrawList& draw, const WindowLayout& layout, const CharacterArt* art, std::size_t box,
                       std::size_t stroke, const std::vector<Vec2>& median_m, double fraction, ImU32 colour,
                       const ToScreen& to_screen) {
  const bool outlined = art != nullptr && std::find(art->polygon_stroke.begin(), art->polygon_stroke.end(),
                                                    stroke) != art->polygon_stroke.end();
  if (fraction >= 1.0 && outlined) {
    fill_stroke(draw, layout, *art, box, stroke, colour);
    return;
  }
  std::vector<Vec2> screen;
  for (const Vec2& p : median_m) screen.push_back(to_screen(p));
  if (outlined && screen.size() > 1) {
    const double reached = fraction * polyline_length(screen);
    const ImDrawListFlags flags = draw.Flags;
    draw.Flags &= ~ImDrawListFlags_AntiAliasedFill;  // no seams between the pieces
    for (std::size_t p = 0; p < art->polygons.size(); ++p) {
      if (art->polygon_stroke[p] != stroke) continue;
      std::vector<Vec2> points;
      for (const Vec2& v : art->polygons[p]) points.push_back(layout.data_to_screen(box, v));
      for (const auto& t : art->triangles[p]) {
        fill_reached(draw, points[static_cast<std::size_t>(t[0])], points[static_cast<std::size_t>(t[1])],
                     points[static_cast<std::size_t>(t[2])], screen, reached, colour, 0);
      }
    }
    draw.Flags = flags;
    return;
  }
  const std::vector<Vec2> head = polyline_head(screen, fraction);
  std::vector<ImVec2> points;
  for (const Vec2& p : head) points.push_back(im(p));
  constexpr float kInkPx = 10.0f;
  if (!points.empty()) draw.AddCircleFilled(points.front(), kInkPx / 2, colour, 24);
  if (points.size() > 1) draw.AddPolyline(points.data(), static_cast<int>(points.size()), colour, 0, kInkPx);
}

// A stroke's number (1-based) in a red-ringed white disc beside its start.
void draw_number(ImDrawList& draw, const Vec2& start_px, std::size_t number_1based) {
  const std::string text = std::to_string(number_1based);
  const float size = 22.0f;
  ImFont* font = ImGui::GetFont();
  const ImVec2 extent = font->CalcTextSizeA(size, 1000.0f, 0.0f, text.c_str());
  const ImVec2 centre(static_cast<float>(start_px.x()) - 16.0f, static_cast<float>(start_px.y()) - 16.0f);
  draw.AddCircleFilled(centre, 13.0f, IM_COL32(255, 255, 255, 235), 24);
  draw.AddCircle(centre, 13.0f, kNumber, 24, 2.0f);
  draw.AddText(font, size, ImVec2(centre.x - extent.x / 2, centre.y - extent.y / 2), kNumber, text.c_str());
}

// The stroke-order demonstration over the row's character demo.box.
void draw_demonstration(ImDrawList& draw, const WindowLayout& layout, const std::vector<CharacterArt>& art,
                        const DemoView& demo) {
  if (demo.placed == nullptr) return;
  const CharacterArt* character_art = demo.box < art.size() ? &art[demo.box] : nullptr;
  const auto to_screen = [&](const Vec2& p) { return layout.to_screen(demo.box, p); };
  const std::size_t shown = std::min(demo.frame.stroke + 1, demo.placed->strokes.size());
  for (std::size_t k = 0; k < shown; ++k) {
    const PlacedStroke& stroke = demo.placed->strokes[k];
    const double fraction = k < demo.frame.stroke ? 1.0 : demo.frame.fraction;
    if (fraction > 0.0)
      draw_stroke_drawn(draw, layout, character_art, demo.box, k, stroke.median_m, fraction, kDemoInk,
                        to_screen);
  }
  for (std::size_t k = 0; k < shown; ++k) {
    const PlacedStroke& stroke = demo.placed->strokes[k];
    if (!stroke.median_m.empty()) draw_number(draw, to_screen(stroke.median_m.front()), k + 1);
  }
}

// Over a running trial: a stroke the trial demonstrated and credited (drawn once at the demonstration's pace,
// then kept filled), and the active stroke's hint after misses (drawn once in the hint colour, then kept as
// the outline in that colour with its median). Over a quiz: the last stroke the quiz credited assisted, drawn
// once so (its fill is the quiz's, quiz_fill).
void draw_shown_strokes(ImDrawList& draw, const WindowLayout& layout, const std::vector<CharacterArt>& art,
                        const TrialView& view) {
  if (view.scene == nullptr) return;
  const auto box_of = [&](std::uint32_t character) {
    return view.whole_row ? static_cast<std::size_t>(character) : view.character;
  };
  const auto to_screen = [&](const Vec2& p) { return trial_to_screen(layout, view, p); };
  const auto now = std::chrono::steady_clock::now();
  const auto draw_once = [&](const TrialView::Shown& shown, ImU32 colour, bool number) {
    if (shown.character >= view.scene->characters.size()) return;
    const PlacedCharacter& placed = view.scene->characters[shown.character];
    if (shown.stroke >= placed.strokes.size()) return;
    const PlacedStroke& stroke = placed.strokes[shown.stroke];
    const std::size_t box = box_of(shown.character);
    const CharacterArt* character_art = box < art.size() ? &art[box] : nullptr;
    const DemoSchedule once({polyline_length(stroke.median_m)}, DemoPace{0.08, 0.0});
    const DemoFrame frame = once.at(std::chrono::duration<double>(now - shown.at).count());
    draw_stroke_drawn(draw, layout, character_art, box, shown.stroke, stroke.median_m,
                      frame.done ? 1.0 : frame.fraction, colour, to_screen);
    if (number && !stroke.median_m.empty())
      draw_number(draw, to_screen(stroke.median_m.front()), shown.stroke + 1);
  };
  if (view.quiz) {  // the quiz's own assisted credit; the renderer's events are not the quiz's verdicts
    if (const auto& a = view.quiz->last_assisted()) {
      draw_once({static_cast<std::uint32_t>(a->character), static_cast<std::uint32_t>(a->stroke), a->at},
                kDemoInk, true);
    }
    return;
  }
  if (view.assisted) draw_once(*view.assisted, kDemoInk, true);
  const DisplaySnapshot& s = view.snapshot;
  if (view.hint && !s.finished && view.hint->character == s.character && view.hint->stroke == s.stroke) {
    draw_once(*view.hint, kQuizHint, true);
  }
}

}  // namespace

void draw_scene(ImDrawList& draw, const WindowLayout& layout, const std::vector<CharacterArt>& art,
                const Scene& trial_scene, const TrialView* trial_view, const DemoView* demo, bool learner) {
  // A demonstration shows nothing of the trial, and a trial that has ended keeps its look for the summary.
  const TrialView* view = demo != nullptr ? nullptr : trial_view;
  const bool quiz = view != nullptr && view->quiz.has_value();
  draw.AddRectFilled(
      ImVec2(0, 0),
      ImVec2(static_cast<float>(layout.area_width_px()), static_cast<float>(layout.height_px())), kPaper);
  const ImDrawListFlags flags = draw.Flags;
  for (std::size_t c = 0; c < art.size(); ++c) {
    const ScreenBox& box = layout.box(c);
    const ImVec2 corner(static_cast<float>(box.x_px), static_cast<float>(box.y_px));
    const float side = static_cast<float>(box.size_px);
    // The practice grid (a square with its middle lines, as a 田字格 practice sheet).
    draw.AddRect(corner, ImVec2(corner.x + side, corner.y + side), kGrid, 0.0f, 0, 2.0f);
    draw.AddLine(ImVec2(corner.x + side / 2, corner.y), ImVec2(corner.x + side / 2, corner.y + side), kGrid,
                 1.0f);
    draw.AddLine(ImVec2(corner.x, corner.y + side / 2), ImVec2(corner.x + side, corner.y + side / 2), kGrid,
                 1.0f);
    const bool active =
        view != nullptr && (view->whole_row ? view->snapshot.character == c : view->character == c);
    // Adjacent triangles must not show anti-aliasing seams.
    draw.Flags &= ~ImDrawListFlags_AntiAliasedFill;
    for (std::size_t p = 0; p < art[c].polygons.size(); ++p) {
      std::vector<ImVec2> points;
      for (const Vec2& v : art[c].polygons[p]) points.push_back(im(layout.data_to_screen(c, v)));
      ImU32 colour = quiz ? quiz_fill(*view, c, art[c].polygon_stroke[p]) : active ? kActive : kOutline;
      if (learner && active && !quiz && !view->snapshot.finished && !view->ended &&
          art[c].polygon_stroke[p] == view->snapshot.stroke)
        colour = kActiveStroke;
      fill_polygon(draw, points, art[c].triangles[p], colour);
    }
    draw.Flags = flags;
  }
  if (quiz) {  // Hanzi Writer's quiz shows the outline only: no reference, no start of the next stroke
    draw_quiz_ink(draw, layout, *view);
  } else if (view !=
             nullptr) {  // the trace under the reference, so that both stay visible where they overlap
    for (const TraceSegment& segment : view->segments) {
      std::vector<ImVec2> points;
      for (const Vec2& p : segment.points_m) points.push_back(im(trial_to_screen(layout, *view, p)));
      if (points.size() == 1) draw.AddCircleFilled(points[0], 2.5f, kTrace);
      if (points.size() > 1)
        draw.AddPolyline(points.data(), static_cast<int>(points.size()), kTrace, 0, 5.0f);
    }
  }
  if (demo != nullptr) {
    draw_demonstration(draw, layout, art, *demo);
    return;
  }
  if (view != nullptr) draw_shown_strokes(draw, layout, art, *view);
  // The last refused attempt over the hint that its misses brought (a learner sees both where the pen went
  // and the stroke to write), under the reference.
  if (view != nullptr && !quiz && view->refused)
    draw_ink(draw, layout, *view, view->refused->points_m, kRefused);
  for (std::size_t c = 0; c < art.size() && !quiz; ++c) {
    for (const std::vector<Vec2>& stroke : art[c].reference) {
      std::vector<ImVec2> points;
      for (const Vec2& p : stroke) points.push_back(im(layout.data_to_screen(c, p)));
      draw.AddPolyline(points.data(), static_cast<int>(points.size()), kReference, 0, 2.5f);
    }
  }
  if (view == nullptr) return;
  const DisplaySnapshot& s = view->snapshot;
  const double r = trial_scene.layout.start_radius_m * layout.scale_px_per_m();
  if (quiz) {
    // no start hints: the order is what the quiz asks
  } else if (view->ended || s.finished) {  // the writing result: every stroke's start (Fig. 31)
    for (const PlacedCharacter& placed : trial_scene.characters) {
      for (const PlacedStroke& stroke : placed.strokes)
        draw_ellipse(draw, trial_to_screen(layout, *view, stroke.start()), r, 0.7 * r, kHint, 2.5f);
    }
  } else {
    draw_ellipse(draw, trial_to_screen(layout, *view, Vec2(s.hint_m.x, s.hint_m.y)), r, 0.7 * r, kHint, 3.0f);
  }
  if (s.tick == 0) return;
  const Vec2 tip = trial_to_screen(layout, *view, Vec2(s.hip_m.x, s.hip_m.y));
  // The force arrow and the height gauge are the engineer's: a learner sees the pen only.
  if (!learner) {
    Vec2 in_plane_px = Vec2(s.force_n.x, -s.force_n.y) * 150.0;  // 150 px per newton, at most 220 px
    if (in_plane_px.norm() > 220.0) in_plane_px *= 220.0 / in_plane_px.norm();
    draw_arrow(draw, tip, tip + in_plane_px, kForce);
  }
  if (s.pen_height_m <= 0.0) {
    draw.AddCircleFilled(im(tip), 6.0f, kPen);
    if (s.hip_m.z != s.vtp_m.z)
      draw.AddCircle(im(tip), 10.0f, kVirtualTip, 24, 2.0f);  // the VTP on the paper
  } else {
    const float radius =
        6.0f + static_cast<float>(std::min(0.02, s.pen_height_m) * 600.0);  // bigger when higher
    draw.AddCircle(im(tip), radius, kPen, 24, 2.0f);
    draw.AddCircleFilled(im(tip), 2.0f, kPen);
  }
  if (!learner) draw_height_gauge(draw, layout, s);
}

}  // namespace calligraphy::trainer
