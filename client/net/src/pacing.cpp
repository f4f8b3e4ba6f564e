#include "gpubridge/client/pacing.hpp"

#include <algorithm>
#include <string>
#include <thread>

namespace gpubridge::client {

Result<void> check_pace_options(const PaceOptions& o, std::string_view option) {
  // Written so NaN fails too (every comparison with NaN is false).
  if (o.fps == 0 || (o.fps >= kMinFps && o.fps <= kMaxFps)) return {};
  return make_error(std::string(option) + " must be 0 (unpaced) or " + std::to_string(kMinFps) + " .. " +
                    std::to_string(static_cast<unsigned>(kMaxFps)) + " frames per second; got " + std::to_string(o.fps));
}

FramePacer::FramePacer(Client& client, PaceOptions options, const std::atomic<bool>* interrupt)
    : client_(client), options_(options), interrupt_(interrupt) {
  options_.window = std::max(options_.window, 1u);
  if (!check_pace_options(options_, "fps")) options_.fps = 0;
}

Result<void> FramePacer::fence(Timeout timeout) {
  if (options_.sync) return client_.fence(timeout);
  if (auto h = client_.fence_async(timeout); !h) return h.error();
  return client_.wait_fences(options_.window, timeout);
}

Result<void> FramePacer::frames_sent(std::uint64_t frames, Timeout timeout) {
  frames_ += frames;
  if (auto r = fence(timeout); !r) return r;
  if (options_.fps <= 0) return {};
  const auto due = start_ + std::chrono::duration_cast<Clock::duration>(
                                std::chrono::duration<double>(static_cast<double>(frames_) / options_.fps));
  // In slices, so Ctrl-C ends a long wait (a low --fps) at once.
  while (!(interrupt_ && interrupt_->load()) && Clock::now() < due)
    std::this_thread::sleep_for(std::min<Clock::duration>(due - Clock::now(), std::chrono::milliseconds(50)));
  return {};
}

double FramePacer::elapsed_seconds() const { return std::chrono::duration<double>(Clock::now() - start_).count(); }

Result<void> require_device_kind(const Client& client, std::string_view what, protocol::DeviceKind kind) {
  const auto served = client.session().device_kind;
  if (served == kind) return {};
  const auto& have = protocol::device_kind_info(served);
  const auto& want = protocol::device_kind_info(kind);
  return make_error(std::string(what) + " is a " + std::string(want.label) + " stream, but the daemon at " +
                    client.address().to_string() + " serves a " + std::string(have.label) +
                    " (`gpubridge status` shows its device kind); start gpubridged " +
                    (kind == protocol::DeviceKind::Dmc1 ? "--backend dmc1 (or a DMC-1 board: --backend icebreaker-dmc1)"
                                                        : "with a spigpu backend (--backend sim, a board)") +
                    " for it");
}

}  // namespace gpubridge::client
