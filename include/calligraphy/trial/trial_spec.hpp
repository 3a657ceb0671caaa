#pragma once
/// \file trial_spec.hpp
/// The one trial specification: what to write, on which device, with which guidance, pacing, writer and
/// recording. A value type with one parser and one serialiser for each of its two forms, JSON and the
/// command line's option strings (`calligraphy trial CHARS --guidance off ...`), which round-trip, and one
/// `validate()` whose errors name the field; a checked specification is a `Checked<TrialSpec>`
/// (checked.hpp), which its runner `run_trial_spec` (trial_spec_runner.hpp) takes as it is. `calligraphy
/// trial`, the trainer, study sessions and Python all go through it. The simulated writer's profile and
/// settings are named here and checked by the simulated writer (calligraphy/sim's `writer_profile_of`); a
/// replay's teacher file is read by the front-end (calligraphy/report's teacher_recording.hpp). The fields,
/// their JSON keys, options and meaning: docs/cli.md ("The trial specification").
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "calligraphy/core/checked.hpp"
#include "calligraphy/core/errors.hpp"
#include "calligraphy/core/schema.hpp"
#include "calligraphy/devices/servo_loop.hpp"
#include "calligraphy/model/stroke_progress.hpp"
#include "calligraphy/render/force_law.hpp"
#include "calligraphy/render/guidance_mode.hpp"
#include "calligraphy/trial/options.hpp"
#include "calligraphy/trial/writer_setting.hpp"

namespace calligraphy {

/// What TrialSpec::validate throws for a field at fault: its message names the field's JSON key and option,
/// and `key()` is that key, so that a reader of a record names the field's JSON pointer.
class InvalidTrialSpecField : public InvalidArgument {
 public:
  InvalidTrialSpecField(std::string key, const std::string& message)
      : InvalidArgument(message), key_(std::move(key)) {}
  [[nodiscard]] const std::string& key() const { return key_; }

 private:
  std::string key_;
};

/// Who writes: the device's own writer (the simulated writer on a device it can move, a person on any
/// other), a person, or the simulated writer. Spelled "auto", "person", "simulated".
enum class TrialWriter : std::uint8_t { automatic, person, simulated };

template <>
struct EnumTable<TrialWriter> {
  static constexpr std::string_view name = "TrialWriter";
  static constexpr std::array<EnumEntry<TrialWriter>, 3> entries{{
      {TrialWriter::automatic, "auto",
       "the device's own: the simulated writer on a device it moves, else a person"},
      {TrialWriter::person, "person", "a person holds the device"},
      {TrialWriter::simulated, "simulated", "the simulated writer moves the device"},
  }};
};

/// "auto", "person" or "simulated" (EnumTable).
[[nodiscard]] const char* to_string(TrialWriter writer) noexcept;

/// Where a replay's teacher comes from: the recording file `TrialSpec::teacher`, or the teacher's samples
/// given to the runner (a session keeps its teacher in its folder; Python passes a TeacherRecording).
enum class TeacherSource { file, samples };

/// One trial, as a person or a script states it. Lengths in m, times in s, rates in Hz.
struct TrialSpec {
  std::string characters;                            ///< UTF-8, written left to right (1..1000)
  std::string device = "simulated";                  ///< a device name of `calligraphy devices`
  bool guidance = true;                              ///< in-plane guidance (the paper force stays)
  GuidanceMode guidance_mode = GuidanceMode::fixed;  ///< the paper's fixture or another mode
  /// K_et [N/m] per unit attraction factor (eq. 8), in ForceLawParameters' range; at its default, capped at
  /// the device's stable maximum (stated_force_law, whole_trial.hpp)
  double guidance_stiffness_n_per_m = ForceLawParameters{}.guidance_stiffness_n_per_m;
  double guidance_gain = 1.0;  ///< fading only: gain in [0, 1]
  /// assist-as-needed only: the band's half-width [m] >= 0 (AssistAsNeededGuidance::band_m)
  double assist_band_m = AssistAsNeededGuidance{}.band_m;
  /// error-amplification only: the repulsive stiffness's share of K_et, in [0, 1]
  double amplification_gain = ErrorAmplificationGuidance{}.gain;
  /// timing only: the target's mean speed along each stroke [m/s] > 0
  double timing_speed_m_s = TimingGuidance{}.speed_m_s;
  std::string teacher;                           ///< replay only: a teacher's recording (JSON file)
  TrialWriter writer = TrialWriter::automatic;   ///< who writes
  std::string writer_profile = "novice";         ///< the simulated writer's profile (docs/writer.md)
  std::vector<WriterSetting> writer_parameters;  ///< settings applied to the profile in turn (typed)
  std::uint64_t seed = 0;                        ///< the simulated writer's seed
  double rate_hz = 1000.0;                       ///< servo rate [Hz]: [100, 100000], real time [100, 10000]
  TrialPacing pacing = TrialPacing::automatic;   ///< lock-step, real time, or the device's own
  RealtimeMode realtime = RealtimeMode::ignore;  ///< real time: require SCHED_FIFO, pinning, locked memory
  /// real time: longest stall [s] in [0, kMaxStallTimeoutS], whole milliseconds; 0 off
  double watchdog_s = ServoLoopOptions{}.stall_timeout_s;
  double max_duration_s = 300.0;  ///< ends after max_duration_s x rate_hz ticks [s], (0, kMaxTrialDurationS]
  /// When a stroke counts as written, and the counts of refused attempts after which it is hinted and
  /// assisted (`hint_after_misses`, `assist_after_misses`): every field of StrokeAcceptance's table is a
  /// field of the specification of the same key, its option the key dashed (a length's "_m" dropped:
  /// `--hint-after-misses`, `--corridor`), in the table's range. The renderer judges strokes by it.
  StrokeAcceptance acceptance{};
  std::string json_file;    ///< the metrics as JSON ("-": standard output; "": none)
  std::string csv_file;     ///< the trace as CSV
  std::string svg_file;     ///< the reference and the trace as SVG
  std::string record_file;  ///< the trial as a teacher's recording (only "" or a file)

  /// Throws InvalidTrialSpecField (an InvalidArgument) naming the field (its JSON key and its option) when a
  /// value is out of range or two fields contradict each other: characters empty or over 1,000, a guidance
  /// mode or gain without the guidance it needs, a replay without a teacher or a teacher without a replay, a
  /// profile or settings for a person, an empty profile name or a setting without a key, a rate outside the
  /// pacing's range, more than 10^7 ticks, a teacher's recording on standard output, an acceptance
  /// StrokeAcceptance::validate refuses (a miss count that is not a whole number). The profile's name and its
  /// settings' keys and ranges are the simulated writer's to check (sim's `writer_profile_of`); outputs on
  /// one file are the front-end's to refuse (it resolves links: the CLI's file plan). `teacher_from`: where a
  /// replay's teacher comes from, the file `teacher` (required then; its front-end reads it) or samples the
  /// runner is given with no file named (`teacher` must then be empty: nothing would read it).
  void validate(TeacherSource teacher_from = TeacherSource::file) const;

  bool operator==(const TrialSpec&) const = default;
};

/// Throws InvalidArgument naming the field when one of `given` (JSON keys of fields a front-end was given
/// explicitly, whatever their value: the command line's options) is read only by a guidance setting `spec`
/// does not have: the guidance stiffness with guidance off, `guidance_gain` but for fading, `assist_band_m`,
/// `amplification_gain`, `timing_speed_m_s` but for their modes, `teacher` but for a replay. `validate` can
/// only refuse such a field when it is not at its default.
void refuse_inapplicable_fields(const TrialSpec& spec, const std::vector<std::string>& given);

/// The specification's schema (schema.hpp): every field's key, option, unit, range, default and doc; its JSON
/// and command-line forms, the checks of ranges and `calligraphy schema specification` come from it.
template <>
struct SchemaOf<TrialSpec> {
  static const Schema& get();
};
template <>
struct SchemaOf<WriterSetting> {
  static const Schema& get();
};

/// The stall bound [s] a front-end sets when its user gives none: `TrialSpec::watchdog_s` (50 ms, the
/// Phantom's own command watchdog) on a haptic device; 0 (off) on a device with no motors (simulated, mouse,
/// mouse-hand), which holds no force against a hand, so that a stall of a loop without real-time rights (tens
/// of ms on a busy desktop) does not end a person's trial.
[[nodiscard]] double default_watchdog_s(bool hardware_device) noexcept;

/// One field of the specification in both forms: its JSON key and its option on the command line.
struct TrialSpecField {
  std::string_view key;         ///< JSON key, e.g. "guidance_mode"
  std::string_view option;      ///< option, e.g. "--guidance-mode"; "CHARS" for the positional characters
  std::string_view value_name;  ///< what the value is, e.g. "fixed|fading|replay", "HZ", "FILE"
  std::string_view help;        ///< one line for --help and the docs
  bool repeated = false;        ///< given once per value (`--writer-param`), a JSON array
};

/// Every field, in the order the forms list them.
[[nodiscard]] std::span<const TrialSpecField> trial_spec_fields();

/// Sets the field with JSON key or option `name` from its text as the command line spells it ("on",
/// "lock-step", "0.5"); a repeated field appends. The one parser of both forms. Throws InvalidArgument
/// naming the field and the accepted values for an unknown name or a value that is not one; the range
/// checks are `validate()`'s.
void set_trial_spec_field(TrialSpec& spec, std::string_view name, std::string_view text);

/// The field's value as the command line spells it (one string per value of a repeated field; doubles with
/// 17 significant digits, so that parsing gives the same value back). Throws InvalidArgument for an
/// unknown name.
[[nodiscard]] std::vector<std::string> trial_spec_field_text(const TrialSpec& spec, std::string_view name);

/// The specification from command-line words: CHARS first, then "--option value" pairs (each option as
/// `trial_spec_fields()` names it), checked (`TrialSpec::validate`, with a replay's teacher from its file).
/// Throws InvalidArgument naming the word or the option at fault, then what `validate` throws.
[[nodiscard]] Checked<TrialSpec> trial_spec_from_args(std::span<const std::string> args);
/// The words `trial_spec_from_args` reads back as `spec`: CHARS, then every field that differs from a
/// default `TrialSpec`.
[[nodiscard]] std::vector<std::string> trial_spec_args(const TrialSpec& spec);

/// The specification from a JSON object whose keys are the fields' keys (numbers as numbers, `guidance` a
/// boolean, `writer_parameters` an array of {"key": name, "value": number}, or of "key=value" strings as
/// records before it wrote); a missing key keeps its default. Throws DataError
/// naming `source` and the JSON pointer of a value at fault or an unknown key, then checks it
/// (InvalidArgument naming the field) with a replay's teacher from `teacher_from` (TrialSpec::validate).
[[nodiscard]] Checked<TrialSpec> trial_spec_from_json(std::string_view text, const std::string& source,
                                                      TeacherSource teacher_from = TeacherSource::file);
/// The JSON object `trial_spec_from_json` reads back as `spec` (every field, keys in field order).
[[nodiscard]] std::string trial_spec_json(const TrialSpec& spec);

}  // namespace calligraphy
