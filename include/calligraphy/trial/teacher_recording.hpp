#pragma once
/// \file teacher_recording.hpp
/// A teacher's recorded trial, kept for the `replay` guidance mode (guidance_mode.hpp: record and replay,
/// Henmi & Yoshikawa 1998; Feygin, Keehner & Tendick 2002). Made by `calligraphy trial ... --record FILE`
/// or in the trainer; read by `--guidance-mode replay --teacher FILE`, protocols and Python.
///
/// Format (JSON, docs/force-rendering.md, "Guidance modes"): an object with
///   "format": "calligraphy-teacher-recording", "version": 1,
///   "characters": the scene's characters (UTF-8; the recording only guides the same characters laid out
///                 the same way, Scene::lay_out),
///   "writer", "device": who wrote it on what (text; provenance),
///   "rate_hz": the servo rate it was recorded at, "library_version",
///   "samples": {"t_s": [...], "x_m": [...], "y_m": [...], "z_m": [...]}: the pen in the device frame
///              [m] at times [s], four arrays of the same length >= 2, times non-decreasing.
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "calligraphy/render/guidance_mode.hpp"
#include "calligraphy/trial/result.hpp"

namespace calligraphy {

struct TeacherRecording {
  std::string characters;  ///< UTF-8, the scene's characters left to right
  std::string writer;      ///< "person", or the simulated writer's profile
  std::string device;      ///< registry name of the device it was written on
  double rate_hz = 1000.0;
  std::string library_version;  ///< of the library that recorded it (empty when unknown)
  std::vector<TeacherSample> samples;
};

/// A recording of `trace` (a trial's `TrialResult::trace`: every tick's time and pen position).
/// Throws InvalidArgument when the trace has fewer than 2 samples (a trial run without keep_trace).
[[nodiscard]] TeacherRecording teacher_recording_from_trace(std::string characters, std::string writer,
                                                            std::string device, double rate_hz,
                                                            const std::vector<TrialSample>& trace);

/// The recording as JSON text (the format above; numbers printed so that they read back exactly).
[[nodiscard]] std::string teacher_recording_json(const TeacherRecording& recording);

/// Parses the JSON format above. `source` names the text in errors. Throws DataError naming the source
/// and the key (and the sample index) for malformed JSON, another format or version, a missing key, a
/// value of the wrong type, arrays of different lengths, fewer than 2 samples, a value that is not finite
/// or a time below the previous one.
[[nodiscard]] TeacherRecording parse_teacher_recording(std::string_view json_text, const std::string& source);

/// Largest recording file read: 256 MiB (about 2 hours at 1 kHz).
inline constexpr std::uintmax_t kMaxTeacherRecordingBytes = std::uintmax_t{256} << 20;

/// Reads a recording file. Throws DataError naming the path when it does not exist, is not a regular
/// file, is larger than kMaxTeacherRecordingBytes or cannot be read, and as `parse_teacher_recording`.
[[nodiscard]] TeacherRecording read_teacher_recording(const std::filesystem::path& path);

/// Throws InvalidArgument naming both when the recording was made on other characters than `characters`
/// (UTF-8) and so cannot guide them.
void require_teacher_for(const TeacherRecording& recording, std::string_view characters);

}  // namespace calligraphy
