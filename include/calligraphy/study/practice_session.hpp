#pragma once
/// \file practice_session.hpp
/// `calligraphy train --session DIR`: free practice saved as a study session folder
/// (study/session_folder.hpp), so that practice and study sessions share one layout, one record format and
/// the same never-overwrite rules. The practice has no fixed plan (R repeats, N moves on, G toggles
/// guidance): the folder is created for a protocol named "train" that lists the row's characters once under
/// the starting condition, and each trial the window runs is saved as the next trial of the session, whatever
/// it is.
#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <utility>

#include "calligraphy/core/device_types.hpp"
#include "calligraphy/model/scene.hpp"
#include "calligraphy/sim/simulated_hand.hpp"
#include "calligraphy/study/protocol.hpp"
#include "calligraphy/study/session_folder.hpp"
#include "calligraphy/trial/options.hpp"
#include "calligraphy/trial/result.hpp"
#include "calligraphy/trial/trial_spec.hpp"

namespace calligraphy {

/// The practice's conditions, as named in its session folder: "haptic" (guidance on), "vision" (off),
/// "quiz" (off, each stroke judged as the pen lifts).
inline constexpr const char* kHapticCondition = "haptic";
inline constexpr const char* kVisionCondition = "vision";
inline constexpr const char* kQuizCondition = "quiz";
inline constexpr const char* kFadingCondition = "fading";            ///< guidance faded trial by trial
inline constexpr const char* kReplayCondition = "replay";            ///< guidance along a teacher's recording
inline constexpr const char* kAssistCondition = "assist-as-needed";  ///< force only beyond a band
inline constexpr const char* kAmplificationCondition = "error-amplification";  ///< a repulsive field
inline constexpr const char* kTimingCondition = "timing";  ///< a target along the stroke, no shape guidance

/// What the session folder is created with.
struct PracticeSetup {
  std::filesystem::path root;         ///< the session goes to ROOT/SUBJECT/train-YYYYMMDD-HHMMSS
  std::string subject = "anonymous";  ///< [A-Za-z0-9_-], 1..64 characters
  std::string characters_utf8;        ///< the row, each character an item
  std::string first_condition;        ///< one of the three above
  std::string device;                 ///< the device's registry name
  DeviceInfo device_info;
  bool hardware = false;
  bool simulated_writer = false;
  std::string writer_profile = "novice";
  std::uint64_t writer_seed = 0;
  QuizOptions quiz;  ///< the "quiz" condition's options
};

/// One finished trial of the practice.
struct PracticeTrial {
  std::size_t item = 0;  ///< the character's index in the row
  char32_t character = 0;
  std::string condition;         ///< one of the three conditions
  const Scene* scene = nullptr;  ///< the trial's scene
  const TrialOptions* options = nullptr;
  const TrialSpec* spec = nullptr;  ///< the trial's specification, recorded whole; nullptr: not recorded
  SimulationOptions simulation;     ///< the simulated writer, when the setup has one
  std::string start_utc, end_utc;
  double wall_time_s = 0.0;
};

/// The session folder of one `train` run. Not thread-safe; used by the window thread.
class PracticeSession {
 public:
  /// Creates the folder. Throws InvalidArgument for a bad subject id, DataError naming the path when the
  /// folder cannot be made.
  explicit PracticeSession(const PracticeSetup& setup);

  /// Saves the trial (scored as a study trial; a quiz trial with its quiz events): completed, timed-out
  /// and given-up trials as the session's next trial, interrupted and failed ones as attempts. Returns
  /// the JSON's path and whether it is a saved trial (true) or an attempt (false). Throws DataError when
  /// a file cannot be written.
  std::pair<std::filesystem::path, bool> save(const PracticeTrial& trial, const TrialResult& result);

  /// Logs `session_stopped` with `reason` (e.g. "display_lost", "SIGTERM", "device_fault") and the number
  /// of trials run.
  void log_stop(const std::string& reason);

  [[nodiscard]] const std::filesystem::path& path() const noexcept { return folder_.path(); }

 private:
  PracticeSetup setup_;
  SessionFolder folder_;
  std::size_t trials_ = 0;
  std::map<std::pair<std::size_t, std::string>, int> repetitions_;
};

}  // namespace calligraphy
