#include "trainer/panel.hpp"

#include <imgui.h>

#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <string_view>

#include "calligraphy/model/typical_strokes.hpp"
#include "trainer/learner_text.hpp"

namespace calligraphy::trainer {
namespace {

// The next trial's mode, with its gain where the gain means something (fading).
std::string next_mode_text(const PanelInput& input) {
  if (input.next_mode != "fading") return input.next_mode;
  char gain[32];
  std::snprintf(gain, sizeof gain, ", gain %.2f", input.next_gain);
  return input.next_mode + gain;
}

const char* state_meaning(InteractionState state) {
  switch (state) {
    case InteractionState::separation:
      return "pen off the paper";
    case InteractionState::adjusting:
      return "on the paper, outside the character";
    case InteractionState::calibration:
      return "in the character: go to the red hint";
    case InteractionState::writing:
      return "writing the stroke";
  }
  return "";
}

ImVec4 state_colour(InteractionState state) {
  switch (state) {
    case InteractionState::separation:
      return ImVec4(0.45f, 0.45f, 0.45f, 1.0f);
    case InteractionState::adjusting:
      return ImVec4(0.75f, 0.45f, 0.0f, 1.0f);
    case InteractionState::calibration:
      return ImVec4(0.1f, 0.35f, 0.8f, 1.0f);
    case InteractionState::writing:
      return ImVec4(0.1f, 0.55f, 0.15f, 1.0f);
  }
  return ImVec4(0, 0, 0, 1);
}

void results_table(const TrialView& view) {
  if (view.results.empty()) {
    if (view.refused) return;  // the refusal above says what happened
    ImGui::TextDisabled("no stroke written yet");
    return;
  }
  if (ImGui::BeginTable("strokes", 5, ImGuiTableFlags_RowBg | ImGuiTableFlags_BordersInnerH)) {
    ImGui::TableSetupColumn("stroke");
    ImGui::TableSetupColumn("mean mm");
    ImGui::TableSetupColumn("max mm");
    ImGui::TableSetupColumn("time s");
    ImGui::TableSetupColumn("tries");
    ImGui::TableHeadersRow();
    for (const StrokeResult& r : view.results) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      std::string_view type = "?";  // an id outside the typical strokes' table shows as '?'
      try {
        type = typical_stroke(r.typical_id).acronym;
      } catch (const std::exception&) {
      }
      ImGui::Text("%u %.*s", r.stroke + 1, static_cast<int>(type.size()), type.data());
      ImGui::TableNextColumn();
      ImGui::Text("%.2f", r.mean_deviation_m * 1e3);
      ImGui::TableNextColumn();
      ImGui::Text("%.2f", r.max_deviation_m * 1e3);
      ImGui::TableNextColumn();
      ImGui::Text("%.2f", r.time_s);
      ImGui::TableNextColumn();
      ImGui::Text("%d", r.attempts);
    }
    ImGui::EndTable();
  }
}

const ImVec4 kGood(0.1f, 0.55f, 0.15f, 1);
const ImVec4 kBad(0.8f, 0.1f, 0.1f, 1);
const ImVec4 kHintText(0.35f, 0.35f, 0.9f, 1);  // a stroke shown: hinted, or assisted

// The last refused attempt, until the pen touches the paper again: what it did, large, and what to do.
void refusal(const TrialView& view, const PanelInput& input) {
  const RefusedStroke& r = *view.refused;
  const RefusalWords words = learner_words(r.refusal);
  ImGui::Text("stroke %u not written:", r.stroke + 1);
  if (input.large_font != nullptr) ImGui::PushFont(input.large_font);
  ImGui::TextColored(kBad, "%s", words.what);
  if (input.large_font != nullptr) ImGui::PopFont();
  ImGui::PushStyleColor(ImGuiCol_Text, kBad);
  ImGui::TextWrapped("%s", words.advice);
  ImGui::PopStyleColor();
  ImGui::Separator();
}

// The quiz's state: per character, stroke k of n and the misses; the last verdict, why a stroke was missed
// (in the learner's words, as a refused stroke), the hint, a stroke shown and counted as assisted, and
// "complete, M misses" (", K strokes assisted") once every stroke is accepted or assisted.
void quiz_state(const TrialView& view, const PanelInput& input) {
  const LiveQuiz& quiz = *view.quiz;
  ImGui::Text("Quiz: write each stroke in order");
  for (std::size_t c = 0; c < quiz.sessions().size(); ++c) {
    const QuizSession& session = quiz.sessions()[c];
    const std::size_t n = session.character().strokes.size();
    const std::string label = quiz.sessions().size() > 1 ? "character " + std::to_string(c + 1) + ": " : "";
    if (input.large_font != nullptr) ImGui::PushFont(input.large_font);
    if (session.complete()) {
      // Assisted strokes said apart: shown and counted, not written.
      const std::string assisted =
          session.strokes_assisted() > 0
              ? ", " + count_of(session.strokes_assisted(), "stroke", "strokes") + " assisted"
              : "";
      // Wrapped: in the large font this line is wider than the panel at 800 px.
      ImGui::PushStyleColor(ImGuiCol_Text, kGood);
      ImGui::TextWrapped("%scomplete, %s%s", label.c_str(),
                         count_of(static_cast<std::size_t>(session.total_misses()), "miss", "misses").c_str(),
                         assisted.c_str());
      ImGui::PopStyleColor();
    } else {
      ImGui::TextWrapped("%sstroke %zu of %zu", label.c_str(), session.current_stroke() + 1, n);
    }
    if (input.large_font != nullptr) ImGui::PopFont();
    if (!session.complete()) {
      ImGui::Text("misses on this stroke %d, in all %d", session.misses_on_stroke(), session.total_misses());
    }
    if (quiz.hinted()[c]) ImGui::TextColored(kHintText, "hint: stroke %zu shown", *quiz.hinted()[c] + 1);
  }
  if (const auto& last = quiz.last_event()) {
    const QuizEvent& e = last->second;
    switch (e.kind) {
      case QuizEvent::Kind::stroke_accepted:
      case QuizEvent::Kind::stroke_assisted:
      case QuizEvent::Kind::character_completed:  // by the last stroke, accepted or assisted
        if (quiz.assisted(last->first, e.stroke)) {
          ImGui::TextColored(kHintText, "stroke %zu shown and counted as assisted", e.stroke + 1);
        } else {
          ImGui::TextColored(kGood, "stroke %zu accepted", e.stroke + 1);
        }
        break;
      case QuizEvent::Kind::stroke_missed:
      case QuizEvent::Kind::hint:
        ImGui::TextColored(kBad, "stroke %zu missed", e.stroke + 1);
        break;
      case QuizEvent::Kind::too_short:
        ImGui::TextDisabled("too short to judge");
        break;
    }
    const StrokeRefusal refusal = quiz.last_refusal()[last->first];
    if (refusal != StrokeRefusal::none) {
      const RefusalWords words = learner_words(refusal);
      ImGui::TextColored(kBad, "%s: %s", words.what, words.advice);
    } else if (quiz.last_backwards()[last->first]) {
      ImGui::TextColored(kBad, "backwards: written from its end");
    }
  }
  if (quiz.dropped_points() > 0)
    ImGui::TextColored(kBad, "%llu pen samples missed",
                       static_cast<unsigned long long>(quiz.dropped_points()));
}

void summary(const TrialView& view, const PanelInput& input) {
  ImGui::Separator();
  const TrialMetrics& m = view.metrics;
  const bool complete = view.end == TrialEnd::completed;
  ImGui::TextColored(complete ? ImVec4(0.1f, 0.55f, 0.15f, 1) : ImVec4(0.8f, 0.2f, 0.1f, 1), "Trial %s: %s",
                     complete ? "complete" : "ended", to_string(view.end));
  if (!view.end_reason.empty()) ImGui::TextWrapped("%s", view.end_reason.c_str());
  ImGui::Text("strokes in order   %zu / %zu", m.strokes_completed, m.strokes_total);
  if (m.mean_deviation_m && m.max_deviation_m) {
    ImGui::Text("mean deviation     %.2f mm", *m.mean_deviation_m * 1e3);
    ImGui::Text("max deviation      %.2f mm", *m.max_deviation_m * 1e3);
  } else {
    ImGui::Text("deviation          - (nothing written)");
  }
  ImGui::Text("time               %.1f s", m.time_s);
  ImGui::Text("strokes abandoned  %zu", view.abandoned);
  if (!view.saved_as.empty()) ImGui::TextWrapped("saved %s", view.saved_as.c_str());
  if (!view.save_error.empty())
    ImGui::TextColored(ImVec4(0.8f, 0.1f, 0.1f, 1), "%s", view.save_error.c_str());
  ImGui::Spacing();
  if (input.unattended) {
    ImGui::TextDisabled("unattended run (--exit-after)");
  } else if (!input.session.empty()) {
    ImGui::Text("Space  start the next trial   Esc  end the session");
  } else {
    ImGui::Text("R  repeat   N  next character");
    if (!input.quiz) {
      ImGui::Text("G  guidance (next trial: %s)", input.next_guidance ? "on" : "off");
      ImGui::TextWrapped("M  guidance mode (next trial: %s)", next_mode_text(input).c_str());
    }
    ImGui::Text("Q / Esc  quit");
  }
}

}  // namespace

RefusalWords learner_words(StrokeRefusal refusal) noexcept {
  switch (refusal) {
    case StrokeRefusal::too_short:
      return {"too short", "carry the stroke to its end"};
    case StrokeRefusal::backwards:
      return {"backwards", "start from the other end"};
    case StrokeRefusal::wrong_place:
      return {"wrong place", "follow the outline"};
    case StrokeRefusal::wrong_stroke:
      return {"wrong stroke", "that is another stroke"};
    case StrokeRefusal::wrong_order:
      return {"wrong order", "that stroke comes later"};
    case StrokeRefusal::none:
      break;
  }
  return {"not written", "try it again"};
}

namespace {

// The engineer's panel (--engineer): the trial as the library sees it.
void engineer_panel(const PanelInput& input) {
  if (input.demonstrating) {
    ImGui::Text("demonstration: stroke %zu / %zu (no trial runs)", input.demonstrating->first,
                input.demonstrating->second);
    ImGui::TextWrapped("device %s: %s", input.device.c_str(), input.device_line.c_str());
    if (input.view == nullptr) return;
  }
  const TrialView* view = input.view;
  const DisplaySnapshot& s = view->snapshot;
  ImGui::Text("Trial %zu: %s  (%zu of %zu)", view->number, input.character.c_str(), view->character + 1,
              input.characters);
  ImGui::Text("device %s", input.device.c_str());
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.35f, 0.35f, 0.35f, 1));
  ImGui::TextWrapped("%s", input.device_line.c_str());
  ImGui::PopStyleColor();
  // "guidance on" only where it is felt (guidance_words): the mouse outputs no force, mouse-hand's pulls a
  // simulated pen.
  ImGui::TextWrapped("%s, %s", view->condition.c_str(),
                     guidance_words(input.device_kind, view->guidance).c_str());
  if (input.session.empty() && !input.quiz)
    ImGui::TextWrapped("next: %s, %s", guidance_words(input.device_kind, input.next_guidance).c_str(),
                       next_mode_text(input).c_str());
  ImGui::Separator();
  if (input.large_font != nullptr) ImGui::PushFont(input.large_font);
  ImGui::TextColored(state_colour(s.state), "%s", to_string(s.state));
  if (input.large_font != nullptr) ImGui::PopFont();
  ImGui::SameLine();
  // "Go to the red hint" is advice for a stroke still to write: none is left once every stroke is.
  // The quiz shows no hint.
  const bool without_advice = s.state == InteractionState::calibration && (view->quiz || s.finished);
  ImGui::TextColored(state_colour(s.state), "%s",
                     without_advice ? "in the character" : state_meaning(s.state));
  const std::uint32_t shown_stroke = s.finished ? s.strokes_total : s.stroke_index + 1;
  if (s.finished) {
    ImGui::Text("stroke %u / %u   every stroke written", shown_stroke, s.strokes_total);
  } else {
    ImGui::Text("stroke %u / %u   element %u", shown_stroke, s.strokes_total, s.element + 1);
  }
  ImGui::Text("written %u   time %.1f s   tick %llu", s.strokes_completed, s.time_s,
              static_cast<unsigned long long>(s.tick));
  ImGui::Text("pen height %+.1f mm", s.pen_height_m * 1e3);
  ImGui::Text("force in plane %.2f N, normal %.2f N", std::hypot(s.force_n.x, s.force_n.y), s.force_n.z);
  ImGui::Separator();
  if (view->quiz) {
    quiz_state(*view, input);
    ImGui::Separator();
  }
  if (view->refused) refusal(*view, input);
  results_table(*view);
  if (view->have_result) {
    summary(*view, input);
  } else if (!input.unattended && input.session.empty()) {
    ImGui::Spacing();
    ImGui::TextDisabled(input.quiz ? "R repeat  N next  Q quit" : "R repeat  N next  G guidance  Q quit");
  }
}

}  // namespace

namespace {

const ImVec4 kHintColour(0.3f, 0.3f, 0.85f, 1);
const ImVec4 kQuiet(0.35f, 0.35f, 0.35f, 1);

ImVec4 tone_colour(FeedbackTone tone) {
  switch (tone) {
    case FeedbackTone::good:
      return kGood;
    case FeedbackTone::fix:
      return kBad;
    case FeedbackTone::hint:
      return kHintColour;
  }
  return kQuiet;
}

void large(const PanelInput& input, const ImVec4& colour, const std::string& text) {
  if (input.large_font != nullptr) ImGui::PushFont(input.large_font);
  ImGui::PushStyleColor(ImGuiCol_Text, colour);
  ImGui::TextWrapped("%s", text.c_str());
  ImGui::PopStyleColor();
  if (input.large_font != nullptr) ImGui::PopFont();
}

// The end of a trial in the learner's words: strokes in order, how far off on average, how long.
void learner_summary(const TrialView& view) {
  const TrialMetrics& m = view.metrics;
  const bool complete = view.end == TrialEnd::completed;
  ImGui::TextColored(complete ? kGood : kBad, "%s: %zu of %zu strokes in order",
                     complete ? "Done" : "Stopped", m.strokes_completed, m.strokes_total);
  // An assisted stroke was shown and counted, not written: said apart, so "2 of 3" is not a riddle.
  if (m.strokes_assisted > 0) {
    ImGui::Text("%zu shown and counted as assisted", m.strokes_assisted);
  }
  if (m.mean_deviation_m) {
    ImGui::Text("%.1f mm off on average, %.1f s", *m.mean_deviation_m * 1e3, m.time_s);
  } else {
    ImGui::Text("nothing written, %.1f s", m.time_s);
  }
  if (!view.saved_as.empty()) ImGui::TextDisabled("saved");
  if (!view.save_error.empty()) ImGui::TextColored(kBad, "%s", view.save_error.c_str());
}

void learner_panel(const PanelInput& input) {
  const TrialView* view = input.view;
  if (input.large_font != nullptr) ImGui::PushFont(input.large_font);
  ImGui::Text("%s", input.character.c_str());
  if (input.large_font != nullptr) ImGui::PopFont();
  if (input.characters > 1 && view != nullptr && input.session.empty()) {
    ImGui::SameLine();
    ImGui::TextDisabled("character %zu of %zu", view->character + 1, input.characters);
  }
  ImGui::PushStyleColor(ImGuiCol_Text, kQuiet);
  ImGui::TextWrapped("%s", input.device_line.c_str());
  ImGui::PopStyleColor();
  ImGui::Separator();
  if (input.demonstrating) {
    large(input, kHintColour, "Watch: " + stroke_of(input.demonstrating->first, input.demonstrating->second));
    ImGui::TextWrapped("Each stroke is drawn in order, from its start; writing starts after the last one.");
  } else if (view != nullptr) {
    const DisplaySnapshot& s = view->snapshot;
    if (view->quiz) {
      quiz_state(*view, input);
    } else if (s.strokes_total > 0) {
      const std::size_t k = s.finished ? s.strokes_total + 1u : s.stroke_index + 1u;
      large(input, ImVec4(0.1f, 0.1f, 0.1f, 1), stroke_of(k, s.strokes_total));
      // A hinted stroke is filled in the hint colour over its yellow (scene_view.cpp): the line names that.
      const bool hinted =
          view->hint && view->hint->character == s.character && view->hint->stroke == s.stroke;
      if (!s.finished && !view->ended)
        ImGui::TextWrapped(hinted ? "Start at the red circle; the stroke to write is the light blue one."
                           : input.outlined
                               ? "Start at the red circle; the stroke to write is the darker yellow one."
                               : "Start at the red circle and follow the blue line from there.");
    }
    if (view->feedback && !view->quiz) {
      ImGui::Spacing();
      large(input, tone_colour(view->feedback->tone), view->feedback->text);
    }
    if (view->have_result) {
      ImGui::Separator();
      learner_summary(*view);
    }
  }
}

}  // namespace

PanelAction draw_panel(const WindowLayout& layout, double panel_width_px, const PanelInput& input) {
  ImGui::SetNextWindowPos(ImVec2(static_cast<float>(layout.area_width_px()), 0));
  ImGui::SetNextWindowSize(
      ImVec2(static_cast<float>(panel_width_px), static_cast<float>(layout.height_px())));
  // A scroll bar where the panel is taller than a small window (the engineer's tables at 800x480): its
  // buttons and lines are never cut off out of reach.
  ImGui::Begin("trainer", nullptr,
               ImGuiWindowFlags_NoTitleBar | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                   ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoSavedSettings |
                   ImGuiWindowFlags_NoBringToFrontOnFocus);
  if (!input.session.empty()) {
    ImGui::TextWrapped("%s", input.session.c_str());
    if (!input.prompt.empty()) {
      if (input.large_font != nullptr) ImGui::PushFont(input.large_font);
      ImGui::TextColored(ImVec4(0.1f, 0.35f, 0.8f, 1.0f), "%s", input.prompt.c_str());
      if (input.large_font != nullptr) ImGui::PopFont();
    }
    ImGui::Separator();
  }
  if (input.view == nullptr && !input.demonstrating) {
    ImGui::TextWrapped("%s", input.status.c_str());
    ImGui::End();
    return PanelAction::none;
  }
  if (input.engineer) {
    engineer_panel(input);
  } else {
    learner_panel(input);
  }
  PanelAction action = PanelAction::none;
  if (input.practice_buttons) {
    ImGui::Separator();
    if (ImGui::Button(input.demonstrating ? "Skip (D)" : "Demonstrate (D)"))
      action = PanelAction::demonstrate;
    ImGui::SameLine();
    if (!input.demonstrating) {  // a demonstration is followed by the character's trial anyway
      if (ImGui::Button("Restart (R)")) action = PanelAction::restart;
      ImGui::SameLine();
    }
    if (ImGui::Button("Next (N)")) action = PanelAction::next;
    if (!input.engineer) ImGui::TextDisabled("Q / Esc  quit");
  }
  if (!input.status.empty()) ImGui::TextWrapped("%s", input.status.c_str());
  if (input.engineer) {
    // At the foot of the panel where there is room below the rest, else after it (never over it).
    const float foot = static_cast<float>(layout.height_px()) - 30.0f;
    if (ImGui::GetCursorPosY() < foot) ImGui::SetCursorPosY(foot);
    ImGui::TextDisabled("%.0f frames/s", input.frame_rate_hz);
  }
  ImGui::End();
  return action;
}

}  // namespace calligraphy::trainer
