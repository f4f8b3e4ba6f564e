#pragma once
// Lease: who may change the device. One holder, waiters in FIFO order. The device is reset before
// the lease is handed on, so every holder starts from the reset state: after a release, and also
// when the lease was free and a client without it read a register through the device (such a read
// counts in the device's link CRC and LINK_STATUS, so it would show in the next holder's first
// link group). While someone holds the lease, clients without it never reach the device
// (RequestHandler answers their reads from what the daemon knows, docs/daemon.md "Lease").
// Network thread only; no I/O here.
#include <cstdint>
#include <deque>
#include <functional>

#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::daemon {

class Lease {
 public:
  // Resets the device and calls `done` on the network thread when it is finished.
  using ResetDevice = std::function<void(std::function<void()> done)>;
  // Hands the lease to session `id`; false when that session is gone (the next waiter is tried).
  using Grant = std::function<bool(std::uint32_t id)>;

  Lease(ResetDevice reset, Grant grant) : reset_(std::move(reset)), grant_(std::move(grant)) {}

  enum class Outcome { Granted, Queued, Busy };
  Outcome acquire(std::uint32_t id, protocol::LeaseMode mode);
  // The holder releases (the device is reset, then the next waiter gets it) or a waiter leaves the
  // queue. Returns true if `id` held the lease.
  bool release(std::uint32_t id);

  bool held_by(std::uint32_t id) const { return id != 0 && holder_ == id; }
  std::uint32_t holder() const { return holder_; }
  std::size_t waiters() const { return waiters_.size(); }
  // Nobody holds it, waits for it or is being handed it: a read through the device disturbs no one.
  bool idle() const { return holder_ == 0 && waiters_.empty() && !resetting_; }
  // A client without the lease used the device while it was idle: reset before the next grant.
  void touched() { touched_ = true; }

 private:
  void reset_then_grant();
  void grant_next();

  ResetDevice reset_;
  Grant grant_;
  std::uint32_t holder_ = 0;  // 0 = free
  std::deque<std::uint32_t> waiters_;
  bool resetting_ = false;
  bool touched_ = false;
};

}  // namespace gpubridge::daemon
