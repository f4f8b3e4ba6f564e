#pragma once
// TraceRecorder: one session's device-affecting messages as a binary trace (gpubridged --record,
// docs/daemon.md), replayable with `gpubridge play`. Records carry the time since the handshake.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/device_kind.hpp"
#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::daemon {

class TraceRecorder {
 public:
  // Creates DIR/session-ID[-NAME].gbtrace (NAME reduced to [A-Za-z0-9_-]) and writes its header,
  // whose metadata names the device kind (docs/protocol.md 18.1): a DMC-1 session's trace holds its
  // DMC1_WORDS and FENCE messages.
  static Result<std::unique_ptr<TraceRecorder>> open(const std::filesystem::path& dir, std::uint32_t session,
                                                     const std::string& client_name,
                                                     protocol::DeviceKind kind = protocol::DeviceKind::Spigpu);
  void record(const protocol::Message& m);  // ignores messages that do not affect the device
  void flush() { out_.flush(); }

 private:
  using Clock = std::chrono::steady_clock;
  TraceRecorder() = default;
  std::ofstream out_;
  std::uint64_t records_ = 0;
  protocol::DeviceKind kind_ = protocol::DeviceKind::Spigpu;
  Clock::time_point start_ = Clock::now();
};

}  // namespace gpubridge::daemon
