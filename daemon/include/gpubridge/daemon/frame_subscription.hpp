#pragma once
// FrameSubscription: a subscriber's choice (picture, format, rate) and the one swap it has not been
// sent yet. A new swap replaces the pending one (latest wins), and a swap is encoded in the
// subscriber's format only when it is taken for writing, so a subscriber costs at most its pending
// swap and the FRAME being written, whatever the swap rate. With max_fps a swap that comes early
// stays pending until its interval ends; take() says until when. No I/O here.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>

#include "gpubridge/daemon/frame_fanout.hpp"

namespace gpubridge::daemon {

class FrameSubscription {
 public:
  using Clock = std::chrono::steady_clock;

  void subscribe(protocol::FrameFormat format, protocol::FrameSource source, std::uint16_t max_fps);
  void unsubscribe();
  bool active() const { return active_; }
  protocol::FrameSource source() const { return source_; }

  void offer(std::shared_ptr<FrameFanout> swap);
  // The FRAME message to write at `now`, or null: nothing pending, the pending swap has no such
  // picture, or the rate limit holds it (then `due` is when it may go).
  FrameFanout::Buffer take(Clock::time_point now, std::optional<Clock::time_point>& due);

 private:
  bool active_ = false;
  protocol::FrameFormat format_ = protocol::FrameFormat::Native;
  protocol::FrameSource source_ = protocol::FrameSource::Board;
  std::uint16_t max_fps_ = 0;
  Clock::time_point last_sent_{};
  std::shared_ptr<FrameFanout> pending_;
};

}  // namespace gpubridge::daemon
