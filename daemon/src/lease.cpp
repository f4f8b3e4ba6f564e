#include "gpubridge/daemon/lease.hpp"

#include <algorithm>

namespace gpubridge::daemon {

Lease::Outcome Lease::acquire(std::uint32_t id, protocol::LeaseMode mode) {
  if (holder_ == id) return Outcome::Granted;
  if (idle() && !touched_) {
    holder_ = id;
    return Outcome::Granted;
  }
  if (idle()) {  // free, but a reader without the lease went through the device since the last reset
    waiters_.push_back(id);
    reset_then_grant();
    return Outcome::Queued;
  }
  if (mode == protocol::LeaseMode::FailIfBusy) return Outcome::Busy;
  waiters_.push_back(id);
  return Outcome::Queued;
}

bool Lease::release(std::uint32_t id) {
  std::erase(waiters_, id);
  if (!held_by(id)) return false;
  holder_ = 0;
  reset_then_grant();
  return true;
}

void Lease::reset_then_grant() {
  resetting_ = true;
  touched_ = false;
  reset_([this] {
    resetting_ = false;
    grant_next();
  });
}

void Lease::grant_next() {
  while (holder_ == 0 && !resetting_ && !waiters_.empty()) {
    const auto id = waiters_.front();
    waiters_.pop_front();
    holder_ = id;
    if (!grant_(id)) holder_ = 0;
  }
}

}  // namespace gpubridge::daemon
