#include "sim/writer_vision.hpp"

#include <algorithm>
#include <cmath>

namespace calligraphy::writer_detail {

namespace {

constexpr double kVisionSample_s = 1e-3;  // resolution of the seen (delayed) pen and display

}  // namespace

WriterVision::WriterVision(double visual_delay_s)
    : ring_(static_cast<std::size_t>(std::ceil(visual_delay_s / kVisionSample_s)) + 16) {}

void WriterVision::store(const RenderOutput& output, const DeviceState& pen) {
  pending_abandon_ = pending_abandon_ || output.stroke_abandoned;
  if (pen.time_s - last_stored_s_ < kVisionSample_s * (1.0 - 1e-9)) return;
  VisionSample& v = ring_[ring_next_];
  v.time_s = pen.time_s;
  v.pen = pen.position_m.head<2>();
  v.character = output.character;
  v.stroke = output.stroke;
  v.finished = output.finished;
  v.abandoned = pending_abandon_;
  v.sequence = ++sequence_;
  pending_abandon_ = false;
  last_stored_s_ = pen.time_s;
  ring_next_ = (ring_next_ + 1) % ring_.size();
  ring_count_ = std::min(ring_count_ + 1, ring_.size());
}

const VisionSample& WriterVision::stored(std::size_t k) const {
  return ring_[ring_next_ >= k ? ring_next_ - k : ring_next_ + ring_.size() - k];
}

const VisionSample* WriterVision::seen_at(double time_s) const {
  if (ring_count_ == 0) return nullptr;
  // The newest sample at or before time_s: the samples' times fall with k, so bisect for the least such k.
  std::size_t low = 1;
  std::size_t high = ring_count_;
  if (!(stored(high).time_s <= time_s + 1e-12)) return &stored(high);  // nothing that old yet: the earliest
  while (low < high) {
    const std::size_t k = low + (high - low) / 2;
    if (stored(k).time_s <= time_s + 1e-12) {
      high = k;
    } else {
      low = k + 1;
    }
  }
  return &stored(low);
}

bool WriterVision::take_in(const VisionSample& seen) {
  // The samples not taken in yet, oldest first; the k-th newest has sequence number sequence_ + 1 - k.
  bool cleared = false;
  const std::size_t newest_unseen = std::min<std::uint64_t>(ring_count_, sequence_ - taken_in_);
  for (std::size_t k = newest_unseen; k >= 1 && sequence_ + 1 - k <= seen.sequence; --k) {
    if (stored(k).abandoned) cleared = true;
  }
  taken_in_ = std::max(taken_in_, seen.sequence);
  return cleared;
}

}  // namespace calligraphy::writer_detail
