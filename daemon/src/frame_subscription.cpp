#include "gpubridge/daemon/frame_subscription.hpp"

namespace gpubridge::daemon {

void FrameSubscription::subscribe(protocol::FrameFormat format, protocol::FrameSource source, std::uint16_t max_fps) {
  active_ = true;
  format_ = format;
  source_ = source;
  max_fps_ = max_fps;
}

void FrameSubscription::unsubscribe() {
  active_ = false;
  pending_.reset();
}

void FrameSubscription::offer(std::shared_ptr<FrameFanout> swap) {
  if (active_) pending_ = std::move(swap);
}

FrameFanout::Buffer FrameSubscription::take(Clock::time_point now, std::optional<Clock::time_point>& due) {
  due.reset();
  if (!pending_) return nullptr;
  if (max_fps_ != 0 && last_sent_ != Clock::time_point{}) {
    const auto next = last_sent_ + std::chrono::microseconds(1000000 / max_fps_);
    if (now < next) {
      due = next;
      return nullptr;
    }
  }
  const auto swap = std::move(pending_);
  pending_.reset();
  auto message = swap->message(source_, format_);
  if (message) last_sent_ = now;
  return message;
}

}  // namespace gpubridge::daemon
