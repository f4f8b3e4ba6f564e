#pragma once
// Streaming frames to gpubridged at a pace, shared by the programs that do it (gpubridge play,
// gpubridge-dmc1-demo stream): a FENCE marks each frame and at most `window` frames are in flight
// (pipelined completion, so a remote daemon costs no round trip per frame), or with `sync` each
// frame waits until the daemon has executed it; with `fps` frame n is not sent before n / fps
// seconds after the start. And the check that a daemon serves the device kind a stream is for.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <string_view>

#include "gpubridge/client/client.hpp"

namespace gpubridge::client {

struct PaceOptions {
  double fps = 0;       // frames per second; 0 = as fast as the daemon takes them
  unsigned window = 8;  // frames in flight before the next waits (at least 1)
  bool sync = false;    // wait for every frame to execute (a round trip each)
};

// The rates FramePacer takes: 0, or kMinFps .. kMaxFps (a lower rate would put the n-th frame's
// due time beyond what a clock can hold; NaN and Inf are no rate).
inline constexpr double kMinFps = 0.001, kMaxFps = 100000;
// An error naming `option` (the program's flag, "--fps") when o.fps is not 0 or within the range.
Result<void> check_pace_options(const PaceOptions& o, std::string_view option);

class FramePacer {
 public:
  // interrupt: the program's Ctrl-C flag (also given to the Client): a sleep ends when it is set.
  // Options check_pace_options refuses pace as fps 0 (programs check first and say why).
  FramePacer(Client& client, PaceOptions options, const std::atomic<bool>* interrupt = nullptr);
  // A fence as the options say: with sync, one round trip; else sent at once, waiting only while
  // `window` fences are unfinished.
  Result<void> fence(Timeout timeout);
  // After the commands of `frames` frames (1 for a DMC-1 frame; a spigpu batch may hold several
  // swaps) were sent: fences them, then sleeps until the next frame is due at `fps`.
  Result<void> frames_sent(std::uint64_t frames, Timeout timeout);
  std::uint64_t frames() const { return frames_; }
  double elapsed_seconds() const;

 private:
  using Clock = std::chrono::steady_clock;
  Client& client_;
  PaceOptions options_;
  const std::atomic<bool>* interrupt_;
  Clock::time_point start_ = Clock::now();
  std::uint64_t frames_ = 0;
};

// Succeeds when the daemon `client` is connected to serves `kind` (WELCOME "device_kind",
// docs/protocol.md 17.7); otherwise an error naming `what` (a stream file, a program's frames), the
// daemon's address and kind and the backend that serves `kind`. Said before the lease rather than
// by an ERROR WRONG_DEVICE per message.
Result<void> require_device_kind(const Client& client, std::string_view what, protocol::DeviceKind kind);

}  // namespace gpubridge::client
