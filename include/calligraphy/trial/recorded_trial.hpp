#pragma once
/// \file recorded_trial.hpp
/// A trial as it ran: its whole trial (whole_trial.hpp: the specification and every part a front-end may
/// give its builder: the force law (every field, the active guidance law with its values, the stroke
/// acceptance and the nearest-point search), the safety chain, the passivity controller, the simulated
/// writer's profile after every parameter (its traits and what it had learned folded in)), with its
/// provenance: the scene's layout, a SHA-256 of the characters placed, the library version. Every trial
/// record (`calligraphy trial --json`, study sessions and cohorts) holds one as its "specification" object
/// (format: docs/cli.md, "Re-running a trial"); `calligraphy trial --spec RECORD` and `rerun_trial` run it
/// again, and on the simulated device the trace is the same bit for bit. It is part of the trial layer, so an
/// application that links only `calligraphy::haptics` reads a record and runs it again; a record the
/// simulated writer wrote is re-run with sim's `recorded_writing` as the hand maker
/// (calligraphy/sim/simulated_writing.hpp).
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "calligraphy/core/schema.hpp"
#include "calligraphy/devices/simulated_device.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/passivity.hpp"
#include "calligraphy/render/safety_chain.hpp"
#include "calligraphy/trial/teacher_recording.hpp"
#include "calligraphy/trial/trial_spec.hpp"
#include "calligraphy/trial/trial_spec_runner.hpp"
#include "calligraphy/trial/whole_trial.hpp"
#include "calligraphy/trial/writer_profile.hpp"

namespace calligraphy {

/// The "format" of the specification object, and the version written: 9 since a simulated device made by the
/// caller states its figures (`simulated_device.info`: its peak force bounds the trial's forces; an earlier
/// record's device reports the simulated Phantom Desktop's); 8 since a refused pen-down that never
/// came near the stroke's start counts as a miss (`miss_min_path_m`; earlier records count a lift in WS
/// only, StrokeAcceptance::use_version_7_misses); 7 since the stroke acceptance writes a
/// path centred on a dot or a short tick that covers enough of it (`centred_coverage_fraction` and the three
/// fields after it; earlier records run without it, StrokeAcceptance::use_version_6_coverage); 6 since the
/// trial's specification
/// states its stroke acceptance (`TrialSpec::acceptance`: the miss counts of the hint and the assisted credit
/// among its fields; an earlier record's specification takes the acceptance its force law ran with); 5 since
/// the stroke acceptance has a floor of the gap left at either end of a stroke (`end_gap_m`,
/// `end_gap_fraction`; earlier records run without it, StrokeAcceptance::use_version_4_end_gaps); 4 since the
/// stroke acceptance has tolerances that grow with a stroke's length and scale with the character, and the
/// miss counts of the hint and the assisted credit (earlier records run with
/// StrokeAcceptance::use_fixed_tolerances), and since a replay's record names its teacher's recording by
/// SHA-256 (`teacher_sha256`; earlier records name none and are not checked); 3 since the trial states its
/// guidance stiffness
/// (`TrialSpec::guidance_stiffness_n_per_m`; earlier records take its default); 2 since the simulated
/// writer's settings are {"key", "value"} objects (version 1 wrote "key=value" strings). A reader reads
/// versions 1 to 9 and refuses any other by its number.
inline constexpr std::string_view kRecordedTrialFormat = "calligraphy-trial-specification";
inline constexpr int kRecordedTrialVersion = 9;
inline constexpr int kOldestRecordedTrialVersion = 1;
/// Largest trial record file read: 64 MiB.
inline constexpr std::uintmax_t kMaxRecordedTrialBytes = std::uintmax_t{64} << 20;

/// A trial as it ran: the whole trial (whole_trial.hpp: the specification, the force law, safety chain and
/// passivity controller it ran with, the simulated writer's profile when it wrote, a simulated device's
/// physics of the caller's own) and its provenance (layout, scene and teacher SHA-256, library version).
/// Lengths in m, forces in N, times in s. The whole trial's members, as recorded:
/// - `spec`: as stated, its output files cleared (a re-run names its own), `writer` the one who wrote and
///   `pacing` the one it ran with (never `automatic`), `acceptance` the force law's;
/// - `force_law`: the force law the renderer ran; a replay's teacher trajectory is not kept (`spec.teacher`
///   names its file, or the re-run is given the teacher's samples);
/// - `writer`: the profile the simulated writer wrote with (after every parameter, its traits and what it
///   had learned folded in); nullopt when a person wrote;
/// - `simulated_device`: the physics of a simulated device its caller made with its own parameters
///   (Python's `simulate_trial(device=...)`; its DeviceInfo stays the default's); nullopt: the device the
///   registry makes of `spec.device`.
struct RecordedTrial : WholeTrial {
  SceneLayout layout;           ///< where the characters were placed
  std::string scene_sha256;     ///< `scene_sha256` of the placed characters
  std::string library_version;  ///< the library that ran it (said, not checked)
  /// Lower-case hex SHA-256 (FIPS 180-4) of the teacher's recording file a replay ran on, as its front-end
  /// read it (`calligraphy trial --teacher`); empty when no file was read (not a replay, or a teacher given
  /// as samples). A re-run reads the teacher through `read_recorded_teacher`, which refuses another file.
  std::string teacher_sha256;
  /// Read from a record of an earlier version: the JSON pointers of fields added since, which took their
  /// documented defaults (empty for a record written by this version). Not written.
  std::vector<std::string> defaulted;
  /// A field of the stroke acceptance whose value the record's version fixes (fixed tolerances and no
  /// assisted credit before version 4, no end-gap floor before 5, no centred rule before 7), the record
  /// leaving it out (`given` empty) or giving another value: the value it runs with, as that version ran.
  struct VersionRule {
    std::string pointer;          ///< the field's JSON pointer in the record
    double taken = 0.0;           ///< the value it runs with
    std::optional<double> given;  ///< the value the record gave; empty when it left the field out
    int version = 0;              ///< the record's version
  };
  /// Read from a record of an earlier version: each acceptance field its version's rule set, in table order
  /// (empty for a record written by this version). Not written.
  std::vector<VersionRule> version_rules;
  /// `spec.teacher` is the copy of the teacher a session kept in its folder, found from the record's own
  /// place (`read_study_recorded_trial`), rather than the file named as `--teacher` was given. Not written.
  bool teacher_kept_by_session = false;
  /// What a whole record (`trial --json`, a study's trial record) says its run gave: `end_reason` and each
  /// run-level figure of the metric table it states (analysis/metric_table.hpp), by name, as the record's
  /// JSON text of the value; empty for a specification alone. A re-run compares them (report's
  /// `rerun_differences`). Not written.
  std::vector<std::pair<std::string, std::string>> recorded_outcome;
};

/// The schema of the specification object a trial record holds (format, version, trial, force_law, safety,
/// passivity, writer, simulated_device, scene, library_version), every part required: what
/// `calligraphy schema record` prints as JSON Schema (schema.hpp, `json_schema_text`).
[[nodiscard]] const Schema& recorded_trial_schema();

/// The JSON Schema (draft 2020-12) of a record's specification object, `calligraphy schema record`: the
/// record's schema, every part required but those a later version added (required by the record's
/// `version`), and what an older version the reader reads wrote otherwise: version 1's writer settings as
/// "key=value" text.
[[nodiscard]] std::string recorded_trial_json_schema_text();

/// What ran for `spec` on `scene` with the options `ran` (TrialRun::options) and, when the simulated writer
/// wrote, its profile `writer` (nullptr: a person). `teacher_sha256`: the SHA-256 of the teacher's recording
/// file a replay read (`read_recorded_teacher`'s), required when `spec` is a replay naming that file
/// (`spec.teacher`; a reader refuses such a record without it); empty when the teacher was given as
/// samples. Throws InvalidArgument for a replay naming its teacher's file without its SHA-256, or a SHA-256
/// that is not 64 lower-case hex digits or is given for a trial that read no teacher's file.
[[nodiscard]] RecordedTrial recorded_trial(const TrialSpec& spec, const TrialOptions& ran,
                                           const WriterProfile* writer, const Scene& scene,
                                           const std::string& teacher_sha256 = {});

/// Lower-case hex SHA-256 (FIPS 180-4) of the placed characters: each character's code point and, stroke by
/// stroke, its typical stroke ID, attraction factors, elements' control points [m] and median [m] (its
/// point count, 0 for none, then its points; bit patterns): equal for equal character data and layout,
/// whatever the data's source.
[[nodiscard]] std::string scene_sha256(const Scene& scene);
/// The SHA-256 records stated before it covered the medians: `scene_sha256` without them.
[[nodiscard]] std::string scene_models_sha256(const Scene& scene);
/// True when `recorded_sha256` (a record's `scene.sha256`) is `scene_sha256(scene)`, or, for a record
/// written before the SHA-256 covered the medians, `scene_models_sha256(scene)`: such a record cannot tell
/// characters with medians from the same models without them.
[[nodiscard]] bool scene_is_recorded_one(const Scene& scene, const std::string& recorded_sha256);

/// `recorded` as a JSON object (2-space indent): "format", "version", "trial" (trial_spec_json's keys),
/// "force_law", "safety", "passivity", "writer" (null for a person), "simulated_device" (null: the
/// registry's), "scene" {"layout", "sha256"} and "library_version". Numbers are JSON numbers that read back
/// to the same doubles.
[[nodiscard]] std::string recorded_trial_json(const RecordedTrial& recorded);

/// The specification in `text`: a trial record holding a "specification" object, or that object itself.
/// Every part is required (null only for "writer" and "simulated_device"), no key is unknown and every value
/// is in its field's range (the schema, `recorded_trial_schema`); each part is validated as its struct
/// validates it. A field added in a later version than the record's takes its default (`defaulted`). Throws
/// DataError naming `source` and the JSON pointer of a value at fault, a record with no specification
/// (written before records held one), or a format or version this library does not read.
[[nodiscard]] RecordedTrial read_recorded_trial(std::string_view text, const std::string& source);

/// `read_recorded_trial` of the regular file `path` (at most kMaxRecordedTrialBytes). Throws DataError naming
/// the path when it cannot be read, and InputError (a DataError; the command line's exit 2) for what
/// `read_recorded_trial` refuses in its content. A study session's replay names no teacher file (it ran on
/// the one kept in its session folder): study's `read_study_recorded_trial` finds it there.
[[nodiscard]] RecordedTrial read_recorded_trial_file(const std::string& path);

/// A teacher's recording as read from its file, with the file's lower-case hex SHA-256 (what a record names).
struct TeacherFile {
  TeacherRecording recording;
  std::string sha256;
};

/// The teacher's recording at `path` (a file named by `recorded.spec.teacher` or given instead; for a new
/// trial, a default `RecordedTrial`) for running the replay `recorded`: read whole as
/// `read_teacher_recording` reads it, and, when the record names the SHA-256 of the recording it ran on
/// (`teacher_sha256`), checked to be that one. Throws DataError naming the file and both SHA-256 when it is
/// another recording, and what `read_teacher_recording` throws.
[[nodiscard]] TeacherFile read_recorded_teacher(const RecordedTrial& recorded,
                                                const std::filesystem::path& path);

/// `read_recorded_teacher` of the file the record itself names (`recorded.spec.teacher`), for a re-run given
/// no other. A file not there is refused with a DataError `<source>: the replay's teacher <file> (<where the
/// name comes from>): no such file; give <give>, ...`: the name as `--teacher` was given when the trial ran
/// (a relative name is read from the working folder), or the copy its session kept.
[[nodiscard]] TeacherFile read_record_named_teacher(const RecordedTrial& recorded, std::string_view source,
                                                    std::string_view give);

/// The whole trial of `recorded` as it runs again, checked: the one builder (`build_whole_trial`) given
/// `spec` (`recorded.spec` as the caller checked it, `Checked<TrialSpec>::check`, its output files and a
/// replay's teacher file the caller's) and the record's force law, safety chain, passivity controller,
/// writer profile and simulated device physics (no figure of a device is read: the force law is the
/// record's). Throws InvalidArgument naming the part at fault (`build_whole_trial`).
[[nodiscard]] Checked<WholeTrial> recorded_whole_trial(const RecordedTrial& recorded,
                                                       const Checked<TrialSpec>& spec);

/// Runs `recorded` again on `scene` (laid out by the caller with `recorded.layout`) with `inputs` (the
/// registry, a stop flag, a replay's teacher samples, and, for a record the simulated writer wrote
/// (`recorded.writer`), sim's `recorded_writing(recorded)` as the hand maker; a person's record runs with the
/// hand `inputs` gives, if any): `run_whole_trial` of `recorded_whole_trial(recorded, spec)`, on the
/// simulated device of the record's physics when it states them (made by the runner), else on
/// `inputs.device` or the registry's `spec.device`. Throws InvalidArgument when `scene` is not the recorded
/// one (its SHA-256 differs: other character data), when the simulated writer wrote the record and `inputs`
/// gives no hand maker, and what `recorded_whole_trial` and `run_whole_trial` throw.
[[nodiscard]] TrialRun rerun_trial(const RecordedTrial& recorded, const Checked<TrialSpec>& spec,
                                   const Scene& scene, TrialRunInputs inputs = {});

}  // namespace calligraphy
