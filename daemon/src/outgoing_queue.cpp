#include "gpubridge/daemon/outgoing_queue.hpp"

#include <algorithm>

namespace gpubridge::daemon {

void OutgoingQueue::push(Buffer message) {
  counted_ += message->size();
  queue_.push_back(std::move(message));
}

std::size_t OutgoingQueue::take(std::vector<Buffer>& batch, std::size_t max_buffers, std::size_t max_bytes) {
  std::size_t bytes = 0, n = 0;
  while (!queue_.empty() && n < max_buffers && (n == 0 || bytes + queue_.front()->size() <= max_bytes)) {
    bytes += queue_.front()->size();
    batch.push_back(std::move(queue_.front()));
    queue_.pop_front();
    ++n;
  }
  return bytes;
}

void OutgoingQueue::written(std::size_t bytes) { counted_ -= std::min<std::uint64_t>(counted_, bytes); }

void OutgoingQueue::clear() {
  queue_.clear();
  counted_ = 0;
}

}  // namespace gpubridge::daemon
