// sim: what a simulated writer did (include/calligraphy/sim/writer_log.hpp), its profiles by name with
// settings (writer_profile.hpp) and learning across repetitions (writer_learning.hpp), so that a Python
// script can train a writer over repetitions: trial -> result.writer_log -> RepetitionOutcome.from_log
// -> next_repetition_profile -> the next trial.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <string>

#include "arguments.hpp"
#include "bindings.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/sim/writer_learning.hpp"
#include "calligraphy/sim/writer_log.hpp"
#include "calligraphy/trial/writer_profile.hpp"
#include "parameter_class.hpp"
#include "writer_settings.hpp"

namespace calligraphy::python {
namespace {

void bind_writer_log(py::module_& m) {
  py::enum_<AttemptEnd>(m, "AttemptEnd", "How a simulated writer's attempt at a stroke ended.")
      .value("unfinished", AttemptEnd::unfinished, "the trial ended during the attempt")
      .value("completed", AttemptEnd::completed, "the whole path written and the pen lifted")
      .value("refused", AttemptEnd::refused, "the writer felt resistance and broke the attempt off")
      .value("interrupted", AttemptEnd::interrupted,
             "the stroke was cleared after a lift in the middle and started again")
      .value("not_accepted", AttemptEnd::not_accepted,
             "written whole at the stroke the display showed as next, and seen not taken: written again");
  py::class_<WriterAttempt>(m, "WriterAttempt", "One attempt of a simulated writer at one stroke.")
      .def_readonly("character", &WriterAttempt::character, "character index in the scene, 0-based")
      .def_readonly("stroke", &WriterAttempt::stroke, "stroke index within the character the writer meant")
      .def_readonly("scene_stroke", &WriterAttempt::scene_stroke, "the same stroke counted over the scene")
      .def_readonly("reversed", &WriterAttempt::reversed, "written from its end to its start")
      .def_readonly("out_of_order", &WriterAttempt::out_of_order,
                    "an earlier stroke of the reference order was not written yet when it started")
      .def_readonly("follows_hint", &WriterAttempt::follows_hint,
                    "the writer wrote the stroke the display hinted, after a refusal")
      .def_readonly("outside_touch", &WriterAttempt::outside_touch,
                    "the pen touched the paper outside the character's box before it")
      .def_readonly("hesitation", &WriterAttempt::hesitation, "a pause before the stroke or at a turn")
      .def_readonly("mid_stroke_lift", &WriterAttempt::mid_stroke_lift, "the pen lifted in the middle")
      .def_readonly("attempt", &WriterAttempt::attempt, "1 for the first attempt at this stroke, 2, ...")
      .def_readonly("start_s", &WriterAttempt::start_s, "the writer set off towards the stroke [s]")
      .def_readonly("touch_down_s", &WriterAttempt::touch_down_s, "pen down at the start [s]; -1 never")
      .def_readonly("end_s", &WriterAttempt::end_s, "the attempt ended [s]; -1 unfinished")
      .def_readonly("end", &WriterAttempt::end, "an AttemptEnd");
  py::class_<WriterLog>(
      m, "WriterLog", "What a simulated writer did in a trial, attempt by attempt (TrialResult.writer_log).")
      .def_readonly("attempts", &WriterLog::attempts, "list of WriterAttempt, in the order made")
      .def_readonly("refusals", &WriterLog::refusals, "attempts broken off because of resistance")
      .def_readonly("not_accepted", &WriterLog::not_accepted,
                    "attempts written whole that the display was seen not to take")
      .def_readonly("gave_up", &WriterLog::gave_up,
                    "the writer gave up on a stroke after max_attempts_per_stroke attempts and moved on")
      .def_readonly(
          "strokes_given_up", &WriterLog::strokes_given_up,
          "strokes the writer left after its last attempt (docs/writer.md, \"Give-up and retries\")")
      .def("out_of_order_attempts", &WriterLog::out_of_order_attempts, "strokes started out of order")
      .def("backwards_attempts", &WriterLog::backwards_attempts, "strokes started from their end")
      .def("refused_out_of_order", &WriterLog::refused_out_of_order, "out-of-order attempts refused")
      .def("refused_backwards", &WriterLog::refused_backwards, "backwards attempts refused")
      .def("mid_stroke_lifts", &WriterLog::mid_stroke_lifts, "attempts lifted in the middle")
      .def("outside_touches", &WriterLog::outside_touches, "attempts preceded by a touch outside the box")
      .def("hesitations", &WriterLog::hesitations, "attempts with a pause")
      .def("completed_order", &WriterLog::completed_order,
           "scene stroke indices of the completed attempts, in the order written")
      .def("__repr__", [](const WriterLog& log) {
        return "WriterLog(attempts=" + std::to_string(log.attempts.size()) +
               ", out_of_order=" + std::to_string(log.out_of_order_attempts()) +
               ", backwards=" + std::to_string(log.backwards_attempts()) +
               ", refusals=" + std::to_string(log.refusals) +
               ", gave_up=" + (log.gave_up ? "True" : "False") + ")";
      });
}

void bind_learning(py::module_& m) {
  ParameterClass<RepetitionOutcome>(
      m, "RepetitionOutcome",
      "What one repetition gave a learning writer (include/calligraphy/sim/writer_learning.hpp): the share "
      "of haptic feedback and the order and direction errors it made and felt. Usually made with "
      "RepetitionOutcome.from_log(result.writer_log, guidance_share).",
      [](const RepetitionOutcome& outcome) { outcome.validate(); })
      .field("guidance_share", &RepetitionOutcome::guidance_share,
             "haptic feedback in [0, 1], 0 unguided, the gain of fading guidance, 1 fixed or replay")
      .field("out_of_order_attempts", &RepetitionOutcome::out_of_order_attempts,
             "strokes the writer started out of order")
      .field("refused_out_of_order", &RepetitionOutcome::refused_out_of_order,
             "of which the display refused (the writer felt it)")
      .field("backwards_attempts", &RepetitionOutcome::backwards_attempts,
             "strokes the writer started from their end")
      .field("refused_backwards", &RepetitionOutcome::refused_backwards, "of which the display refused")
      .finish()
      .def_static(
          "from_log",
          [](const WriterLog& log, const PyArgument<double>& guidance_share) {
            const RepetitionOutcome outcome =
                RepetitionOutcome::from_log(log, take(guidance_share, "guidance_share"));
            outcome.validate();
            return outcome;
          },
          py::arg("log"), py::arg("guidance_share"),
          "The outcome of a repetition whose writer kept `log` (TrialResult.writer_log) under guidance of "
          "share `guidance_share` in [0, 1]. Raises InvalidArgument for a share outside [0, 1].");
  m.def(
      "next_repetition_profile",
      [](const WriterProfile& profile, const RepetitionOutcome& outcome) {
        return next_repetition_profile(profile, outcome);
      },
      py::arg("profile"), py::arg("outcome"),
      R"(The writer's profile for the next repetition (include/calligraphy/sim/writer_learning.hpp, docs/writer.md
"Learning"): bias, fluency and order/direction error rates move towards the skilled writer's by an
exponential law of practice (Heathcote, Brown & Mewhort 2000) at the profile's `learning_rate`, weighted by
the feedback in `outcome`. A model, not a finding. With learning_rate 0 the profile comes back unchanged.
Raises InvalidArgument for a bad profile or outcome.)");
  m.def(
      "writer_profile",
      [](const Annotated<WriterTag>& writer, const std::optional<Annotated<WriterParamsTag>>& params) {
        return writer_with_settings(writer.object, params ? params->object : py::none());
      },
      py::arg("writer"), py::arg("params") = py::none(),
      R"(A simulated writer's profile: `writer` a name ('novice', 'skilled', 'foreign') or a WriterProfile
(copied), with `params` ({'key': value}) set one by one by set_writer_parameter (keys as
writer_parameter_names(), docs/writer.md). Raises InvalidArgument naming an unknown profile, an unknown
key or a value out of range, TypeError for a value that is not a number.)");
  m.def("writer_parameter_names", &writer_parameter_names,
        "Names of the numeric WriterProfile fields writer_params / set_writer_parameter know.");
}

}  // namespace

void bind_writer_learning(py::module_& m) {
  bind_writer_log(m);
  bind_learning(m);
}

}  // namespace calligraphy::python
