#include "study/trial_record.hpp"

#include <algorithm>
#include <array>
#include <nlohmann/json.hpp>

#include "calligraphy/core/json_text.hpp"
#include "calligraphy/core/unicode.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/legibility/legibility.hpp"
#include "calligraphy/model/polyline.hpp"
#include "calligraphy/model/typical_strokes.hpp"
#include "calligraphy/report/pen_trace_csv.hpp"
#include "core/schema_json.hpp"
#include "report/device_info_object.hpp"
#include "report/trial_outcome.hpp"
#include "study/manifest_json.hpp"
#include "study/remembered_writer.hpp"
#include "study/saved_sessions.hpp"
#include "trial/record_schema.hpp"
#include "trial/recorded_trial_object.hpp"

namespace calligraphy::study_detail {
namespace {

using nlohmann::json;

json vec(const Vec2& v) { return json::array({v.x(), v.y()}); }

const char* method_name(NearestPointMethod method) {
  switch (method) {
    case NearestPointMethod::exact:
      return "exact";
    case NearestPointMethod::newton:
      return "newton";
    case NearestPointMethod::subdivision:
      return "subdivision";
  }
  return "unknown";
}

// The record keeps every mode's parameters under their flat keys: the active law's, the defaults of the
// others.
template <typename Law>
Law law_or_default(const ForceLawParameters& f) {
  const Law* law = std::get_if<Law>(&f.guidance_law);
  return law != nullptr ? *law : Law{};
}

double max_lead_m(const GuidanceLaw& law) {
  if (const auto* replay = std::get_if<ReplayGuidance>(&law)) return replay->max_lead_m;
  if (const auto* timing = std::get_if<TimingGuidance>(&law)) return timing->max_lead_m;
  return kDefaultMaxLeadM;
}

json force_law_json(const ForceLawParameters& f) {
  return {{"guidance", f.guidance},
          {"guidance_mode", to_string(mode_of(f.guidance_law))},
          {"guidance_gain", law_or_default<FadingGuidance>(f).gain},
          {"replay_max_lead_m", max_lead_m(f.guidance_law)},
          {"assist_band_m", law_or_default<AssistAsNeededGuidance>(f).band_m},
          {"amplification_gain", law_or_default<ErrorAmplificationGuidance>(f).gain},
          {"amplification_max_force_n", law_or_default<ErrorAmplificationGuidance>(f).max_force_n},
          {"timing_speed_m_s", law_or_default<TimingGuidance>(f).speed_m_s},
          {"guidance_stiffness_n_per_m", f.guidance_stiffness_n_per_m},
          {"paper_stiffness_n_per_m", f.paper_stiffness_n_per_m},
          {"constraint_radius_m", f.constraint_radius_m},
          {"resistance_damping_n_s_per_m", f.resistance_damping_n_s_per_m},
          {"contact_hysteresis_m", f.contact_hysteresis_m},
          {"constraint_taper_m", f.constraint_taper_m},
          {"crossfade_s", f.crossfade_s},
          {"paper_fade_s", f.paper_fade_s},
          {"acceptance", acceptance_json(f.acceptance)},
          {"paper_damping_n_s_per_m", f.paper_damping_n_s_per_m},
          {"max_foot_speed_m_s", f.max_foot_speed_m_s},
          {"friction_coefficient", f.friction_coefficient},
          {"friction_stick_speed_m_s", f.friction_stick_speed_m_s},
          {"nearest",
           {{"method", method_name(f.nearest.method)},
            {"tolerance", f.nearest.tolerance},
            {"newton_starts", f.nearest.newton_starts},
            {"newton_iterations", f.nearest.newton_iterations}}}};
}

json renderer_json(const TrialOptions& o) {
  const SafetyChainParameters& s = o.safety;
  return {{"rate_hz", o.rate_hz},
          {"pacing", to_string(o.pacing)},
          {"max_duration_s", o.max_duration_s},
          {"safety",
           {{"max_force_n", s.max_force_n},
            {"max_continuous_force_n", s.max_continuous_force_n},
            {"continuous_time_constant_s", s.continuous_time_constant_s},
            {"start_ramp_n_per_s", s.start_ramp_n_per_s},
            {"max_force_change_n_per_tick", s.max_force_change_n_per_tick},
            {"low_pass_cutoff_hz", s.low_pass_cutoff_hz}}},
          {"passivity",
           {{"enabled", o.passivity.enabled},
            {"max_damping_n_s_per_m", o.passivity.max_damping_n_s_per_m},
            {"min_speed_m_s", o.passivity.min_speed_m_s}}},
          {"loop",
           {{"realtime", o.loop.realtime == RealtimeMode::enforce ? "enforce" : "ignore"},
            {"priority", o.loop.priority},
            {"cpu", o.loop.cpu},
            {"lock_memory", o.loop.lock_memory},
            {"max_force_age_s", o.loop.max_force_age_s},
            {"stall_timeout_s", o.loop.stall_timeout_s}}}};
}

json writer_json(const TrialRecordContext& c) {
  if (!c.simulated_writer) return {{"kind", "person"}, {"subject", c.session->setup.subject.id}};
  const WriterProfile& w = c.simulation.writer;
  json writer = {{"kind", "simulated"},
                 {"seed", c.simulation.seed},
                 {"subject_seed", c.session->setup.writer_seed},
                 {"profile",
                  {{"name", w.name},
                   {"hand_stiffness_n_per_m", w.hand_stiffness_n_per_m},
                   {"hand_damping_n_s_per_m", w.hand_damping_n_s_per_m},
                   {"writing_speed_m_s", w.writing_speed_m_s},
                   {"travel_speed_m_s", w.travel_speed_m_s},
                   {"press_depth_m", w.press_depth_m},
                   {"lift_height_m", w.lift_height_m},
                   {"bias_offset_m", w.bias_offset_m},
                   {"scale_error", w.scale_error},
                   {"stroke_jitter_m", w.stroke_jitter_m},
                   {"noise_fraction", w.noise_fraction},
                   {"tremor_amplitude_n", w.tremor_amplitude_n},
                   {"tremor_frequency_hz", w.tremor_frequency_hz},
                   {"corner_cut_m", w.corner_cut_m},
                   {"end_short_m", w.end_short_m},
                   {"end_past_m", w.end_past_m},
                   {"follow_through_m", w.follow_through_m},
                   {"correction_per_attempt", w.correction_per_attempt},
                   {"max_attempts_per_stroke", w.max_attempts_per_stroke}}}};
  const SubjectTraits traits = subject_traits(c.session->setup);
  if (traits.drawn) {
    // Who this subject is among the others of its profile (docs/writer.md, "Individual differences").
    writer["subject_traits"] = {{"writing_speed_factor", traits.writing_speed_factor},
                                {"spatial_error_factor", traits.spatial_error_factor},
                                {"error_rate_factor", traits.error_rate_factor},
                                {"motor_noise_factor", traits.motor_noise_factor},
                                {"fast_learning_per_trial", traits.learning.fast_learning},
                                {"slow_learning_per_trial", traits.learning.slow_learning},
                                {"fast_retention_per_trial", traits.learning.fast_retention},
                                {"slow_retention_per_trial", traits.learning.slow_retention}};
  }
  if (c.writer_log) {
    // The writer's own account (docs/writer.md, "Give-up and retries"): how often it wrote a stroke again,
    // and which strokes it left after its last attempt.
    writer["log"] = {{"attempts", c.writer_log->attempts.size()},
                     {"refusals", c.writer_log->refusals},
                     {"not_accepted", c.writer_log->not_accepted},
                     {"strokes_given_up", c.writer_log->strokes_given_up}};
  }
  if (c.writer_skills) {
    writer["memory"] = {{"model", std::string(enum_spelling(c.session->setup.writer_learning))},
                        {"shape_skill", c.writer_skills->shape},
                        {"order_skill", c.writer_skills->order},
                        {"timing_skill", c.writer_skills->timing}};
  }
  return writer;
}

// The files written beside the record: `trace` (HDF5) for a saved trial, `csv` for trial --csv (kept, empty,
// when neither was written, as records always had it), `svg`.
json files_json(const TrialRecordContext& c) {
  json files = json::object();
  if (!c.csv_file.empty() || c.trace_file.empty()) files["csv"] = c.csv_file;
  if (!c.trace_file.empty()) files["trace"] = c.trace_file;
  if (!c.trace_sha256.empty()) files["trace_sha256"] = c.trace_sha256;
  files["svg"] = c.svg_file;
  return files;
}

json scene_json(const Scene& scene) {
  json characters = json::array();
  for (const PlacedCharacter& c : scene.characters) {
    json strokes = json::array();
    for (const PlacedStroke& s : c.strokes) {
      json polyline = json::array();
      for (const StrokeElement& e : s.elements) {
        const auto points = sample_element(e, e.degree == 1 ? 1 : 16);
        for (std::size_t i = polyline.empty() ? 0 : 1; i < points.size(); ++i)
          polyline.push_back(vec(points[i]));
      }
      strokes.push_back({{"typical_id", s.typical_id},
                         {"acronym", std::string(typical_stroke(s.typical_id).acronym)},
                         {"start_m", vec(s.start())},
                         {"polyline_m", polyline}});
    }
    characters.push_back(
        {{"character", encode_utf8(c.code_point)},
         {"code_point", describe_character(c.code_point)},
         {"placement",
          {{"origin_m", vec(c.placement.origin_m)}, {"metres_per_unit", c.placement.metres_per_unit}}},
         {"strokes", strokes}});
  }
  const SceneLayout& l = scene.layout;
  return {{"layout",
           {{"character_size_m", l.character_size_m},
            {"spacing_m", l.spacing_m},
            {"centre_m", vec(l.centre_m)},
            {"paper_z_m", l.paper_z_m},
            {"box_margin_m", l.box_margin_m},
            {"start_radius_m", l.start_radius_m}}},
          {"characters", characters}};
}

json loop_json(const ServoLoopStats& s) {
  return {{"rate_hz", s.rate_hz},
          {"ticks", s.ticks},
          {"late_ticks", s.late_ticks},
          {"forces_withheld", s.forces_withheld},
          {"longest_stall_s", s.longest_stall_s},
          {"period_jitter_us_p99", s.period_jitter_us_p99},
          {"period_jitter_us_max", s.period_jitter_us_max},
          {"callback_us_max", s.callback_us_max},
          {"device_clock", s.realtime.device_clock}};
}

}  // namespace

json acceptance_json(const StrokeAcceptance& a) {
  return schema_detail::to_json(SchemaOf<StrokeAcceptance>::get(), &a);
}

namespace {

// The written characters as an independent recogniser reads them (legibility/legibility.hpp): null when no
// recogniser is available. top1 and top5 are the shares of the trial's characters recognised first, or
// among the first five.
json legibility_json(const Scene& scene, const TrialResult& result) {
  const std::vector<CharacterLegibility> verdicts = trial_legibility(scene, result.trace);
  if (verdicts.empty()) return nullptr;
  json characters = json::array();
  std::size_t first = 0, among_five = 0;
  for (const CharacterLegibility& v : verdicts) {
    first += v.rank == 1 ? 1 : 0;
    among_five += v.rank >= 1 ? 1 : 0;
    characters.push_back({{"character", encode_utf8(v.expected)}, {"rank", v.rank}, {"top1", v.top1}});
  }
  const double count = static_cast<double>(verdicts.size());
  return {{"recogniser", "zinnia"},
          {"model", legibility_model_path()},
          {"candidates", kLegibilityCandidates},
          {"top1", static_cast<double>(first) / count},
          {"top5", static_cast<double>(among_five) / count},
          {"characters", characters}};
}

}  // namespace

nlohmann::json trial_record(const TrialRecordContext& c, const Scene& scene, const TrialResult& result,
                            const WritingMetrics& writing, const std::vector<std::vector<QuizEvent>>* quiz) {
  json per_stroke = json::array();
  for (const StrokeMetrics& s : result.metrics.per_stroke) {
    const bool has_trace = s.trace_end > s.trace_begin && s.trace_end <= result.trace.size();
    // The renderer's view of the stroke (attempts, completed in turn) and when it was written.
    json stroke = report_detail::renderer_stroke_object(s);
    stroke["start_s"] = has_trace ? json(result.trace[s.trace_begin].time_s) : json(nullptr);
    stroke["end_s"] = has_trace ? json(result.trace[s.trace_end - 1].time_s) : json(nullptr);
    per_stroke.push_back(std::move(stroke));
  }
  const PlannedTrial& t = *c.trial;
  // How the trial ended, the renderer's figures and the one metrics record, as every trial record holds
  // them; then what a study adds.
  json document = report_detail::trial_outcome_object(result, writing);
  // Version 2: the trial's block and item count from 1, as its index and repetition (version 1: from 0).
  document.update({{"format", kTrialRecordFormat},
                   {"version", kTrialRecordVersion},
                   {"subject", c.session->setup.subject.id},
                   {"subject_number", c.session->setup.subject.number},
                   {"session", c.session->session_id},
                   {"trial", planned_trial_json(t)},
                   {"phase", to_string(t.phase)},
                   {"condition", t.condition},
                   {"mode", to_string(condition_mode(*c.condition))},
                   {"characters", encode_utf8(t.characters)},
                   {"repetition", t.repetition},
                   {"start_time_utc", c.start_utc},
                   {"end_time_utc", c.end_utc},
                   {"wall_time_s", c.wall_time_s},
                   {"protocol",
                    {{"name", c.session->protocol.protocol.name},
                     {"path", c.session->protocol.path.string()},
                     {"sha256", c.session->protocol.sha256}}},
                   {"library", library_build_json(library_build())},
                   {"session_library", library_build_json(c.session->library)},
                   {"device",
                    {{"name", c.device_name},
                     {"hardware", c.hardware},
                     {"info", report_detail::device_info_object(c.device_info)},
                     {"time_at_start_s", result.device_time_at_start_s}}},
                   {"writer", writer_json(c)},
                   {"force_law", force_law_json(c.options->force)},
                   {"renderer", renderer_json(*c.options)},
                   {"scene", scene_json(scene)},
                   {"per_stroke", per_stroke},
                   {"samples", result.trace.size()},
                   {"files", files_json(c)}});
  if (json legibility = legibility_json(scene, result); !legibility.is_null())
    document["legibility"] = legibility;
  if (c.device_name == "simulated")
    document["device"]["simulated_device"] =
        trial_detail::simulated_device_object(SimulatedDeviceParameters{});  // the registry's
  // The whole specification that ran, which `calligraphy trial --spec` runs again (recorded_trial.hpp).
  if (c.spec != nullptr) {
    document["specification"] = trial_detail::recorded_trial_object(
        recorded_trial(*c.spec, *c.options, c.simulated_writer ? &c.simulation.writer : nullptr, scene));
  }
  if (!c.condition->guidance_parameters.empty())
    document["guidance_parameters"] = c.condition->guidance_parameters;
  if (!c.guidance.is_null()) document["guidance"] = c.guidance;
  if (result.loop) document["loop"] = loop_json(*result.loop);
  if (quiz) {
    json characters = json::array();
    int misses = 0;
    std::size_t accepted = 0, assisted = 0, hints = 0, quiz_backwards = 0;
    for (std::size_t i = 0; i < quiz->size(); ++i) {
      json events = json::array();
      for (const QuizEvent& e : (*quiz)[i]) {
        json event = {{"kind", to_string(e.kind)},
                      {"stroke", e.stroke},
                      {"backwards", e.backwards},
                      {"misses_on_stroke", e.misses_on_stroke},
                      {"total_misses", e.total_misses},
                      {"time_s", e.time_s},
                      {"samples", e.samples}};
        event["refusal"] = to_string(e.refusal);
        if (e.written_stroke) event["written_stroke"] = *e.written_stroke;
        events.push_back(event);
        accepted += e.kind == QuizEvent::Kind::stroke_accepted ? 1 : 0;
        assisted += e.kind == QuizEvent::Kind::stroke_assisted ? 1 : 0;
        hints += e.kind == QuizEvent::Kind::hint ? 1 : 0;
        quiz_backwards += e.backwards ? 1 : 0;
        misses += e.kind == QuizEvent::Kind::stroke_missed ? 1 : 0;
      }
      characters.push_back({{"character", encode_utf8(scene.characters[i].code_point)}, {"events", events}});
    }
    const QuizOptions q = c.condition->quiz.value_or(QuizOptions{});
    document["quiz"] = {{"acceptance", acceptance_json(q.acceptance)},
                        {"start_radius_m", q.start_radius_m},
                        {"hint_after_misses", q.hint_after()},
                        {"assist_after_misses", q.assist_after()},
                        {"accept_backwards", q.accept_backwards},
                        {"strokes_accepted", accepted},
                        {"strokes_assisted", assisted},
                        {"misses", misses},
                        {"hints", hints},
                        {"backwards", quiz_backwards},
                        {"characters", characters}};
  }
  return document;
}

std::string trial_record_json(const TrialRecordContext& context, const Scene& scene,
                              const TrialResult& result, const WritingMetrics& writing,
                              const std::vector<std::vector<QuizEvent>>* quiz) {
  return json_text(trial_record(context, scene, result, writing, quiz), 2) + "\n";
}

}  // namespace calligraphy::study_detail
