#pragma once
// OutgoingQueue: the replies and events a session still has to write, in order. A reply is never
// dropped; its bytes count against the queue's limit (limits.queue_bytes) from the moment it is
// queued until the write that carries it has completed. The session stops reading and dispatching
// while full(), so the limit holds per message whatever a client pipelines: it is exceeded by at
// most the replies of the one message that crossed it, and the largest reply (READBACK) is
// produced a step at a time, each step only once has_room() says it fits. Frames do not go through
// this queue (a subscriber holds one pending swap, FrameSubscription). No I/O here.
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <vector>

namespace gpubridge::daemon {

class OutgoingQueue {
 public:
  using Buffer = std::shared_ptr<const std::vector<std::uint8_t>>;

  explicit OutgoingQueue(std::uint64_t limit) : limit_(limit) {}

  void push(Buffer message);
  // Moves queued messages to the end of `batch` for one write: at most max_buffers of them and no
  // more than max_bytes (the first one always). Returns the bytes moved.
  std::size_t take(std::vector<Buffer>& batch, std::size_t max_buffers, std::size_t max_bytes);
  // A write carrying `bytes` taken earlier has completed.
  void written(std::size_t bytes);
  void clear();

  bool empty() const { return queue_.empty(); }  // nothing left to take (a write may be in flight)
  bool full() const { return counted_ >= limit_; }
  bool has_room(std::uint64_t bytes) const { return counted_ + bytes <= limit_; }
  std::uint64_t bytes() const { return counted_; }
  std::uint64_t limit() const { return limit_; }

 private:
  std::deque<Buffer> queue_;
  std::uint64_t counted_ = 0;  // queued, plus taken and not yet written
  std::uint64_t limit_;
};

}  // namespace gpubridge::daemon
