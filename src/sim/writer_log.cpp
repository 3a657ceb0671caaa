#include "calligraphy/sim/writer_log.hpp"

#include <algorithm>

namespace calligraphy {
namespace {

template <typename Predicate>
std::size_t count(const std::vector<WriterAttempt>& attempts, Predicate predicate) {
  return static_cast<std::size_t>(std::count_if(attempts.begin(), attempts.end(), predicate));
}

}  // namespace

std::size_t WriterLog::out_of_order_attempts() const noexcept {
  return count(attempts, [](const WriterAttempt& a) { return a.out_of_order; });
}
std::size_t WriterLog::backwards_attempts() const noexcept {
  return count(attempts, [](const WriterAttempt& a) { return a.reversed; });
}
std::size_t WriterLog::mid_stroke_lifts() const noexcept {
  return count(attempts, [](const WriterAttempt& a) { return a.mid_stroke_lift; });
}
std::size_t WriterLog::outside_touches() const noexcept {
  return count(attempts, [](const WriterAttempt& a) { return a.outside_touch; });
}
std::size_t WriterLog::hesitations() const noexcept {
  return count(attempts, [](const WriterAttempt& a) { return a.hesitation; });
}
std::size_t WriterLog::refused_out_of_order() const noexcept {
  return count(attempts,
               [](const WriterAttempt& a) { return a.out_of_order && a.end == AttemptEnd::refused; });
}
std::size_t WriterLog::refused_backwards() const noexcept {
  return count(attempts, [](const WriterAttempt& a) { return a.reversed && a.end == AttemptEnd::refused; });
}
std::vector<std::size_t> WriterLog::completed_order() const {
  std::vector<std::size_t> order;
  for (const WriterAttempt& a : attempts) {
    if (a.end == AttemptEnd::completed) order.push_back(a.scene_stroke);
  }
  return order;
}

}  // namespace calligraphy
