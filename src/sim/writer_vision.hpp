#pragma once
// What the simulated writer sees, late (private to the sim module): its pen and the display sampled every
// millisecond into a ring that reaches back past the visual delay, read as they were a delay ago.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "calligraphy/core/device_types.hpp"
#include "calligraphy/render/renderer.hpp"

namespace calligraphy::writer_detail {

/// The pen and the display at one moment.
struct VisionSample {
  double time_s = 0.0;
  Vec2 pen = Vec2::Zero();    // in the paper's plane [m]
  std::size_t character = 0;  // the active stroke
  std::size_t stroke = 0;
  bool finished = false;       // the display finished the scene
  bool abandoned = false;      // the display cleared a stroke since the previous sample
  std::uint64_t sequence = 0;  // 1 for the first sample, counting on
};

class WriterVision {
 public:
  /// A ring long enough to look `visual_delay_s` [s] back.
  explicit WriterVision(double visual_delay_s);

  /// Keeps what the display shows (`output`) and where the pen is (`pen`), at most once a sample period.
  void store(const RenderOutput& output, const DeviceState& pen);
  /// The newest sample at or before `time_s` [s] (the earliest kept when none is that old); nullptr before
  /// the first.
  [[nodiscard]] const VisionSample* seen_at(double time_s) const;
  /// Takes in the samples up to `seen` not taken in before; true when one of them shows a stroke cleared.
  bool take_in(const VisionSample& seen);

 private:
  [[nodiscard]] const VisionSample& stored(std::size_t k) const;  // the k-th newest, k in [1, ring_count_]

  std::vector<VisionSample> ring_;
  std::size_t ring_next_ = 0;
  std::size_t ring_count_ = 0;
  std::uint64_t sequence_ = 0;
  std::uint64_t taken_in_ = 0;  // the newest sequence taken in
  double last_stored_s_ = -std::numeric_limits<double>::infinity();
  bool pending_abandon_ = false;
};

}  // namespace calligraphy::writer_detail
