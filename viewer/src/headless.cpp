#include "headless.hpp"

#include <chrono>
#include <iostream>

#include <fmt/format.h>

#include "capture.hpp"
#include "exit_codes.hpp"
#include "gpubridge/viewer/overlay.hpp"

namespace gpubridge::viewer {

std::string failure_message(const SourceStatus& s) { return "gpubridge-view: " + status_line(s); }

int run_headless(const Options& options, FrameSource& source) {
  using Clock = std::chrono::steady_clock;
  const std::uint32_t target = options.frames.value_or(1);
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(options.timeout_s));
  source.start();
  std::uint32_t taken = 0;
  std::uint64_t seen_version = 0;
  while (Clock::now() < deadline) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
    source.wait(std::min(left, std::chrono::milliseconds(100)), seen_version);
    seen_version = source.status_version();
    const SourceStatus status = source.status();
    if (status.state == SourceStatus::State::Failed) {
      std::cerr << failure_message(status) << "\n";
      return kExitUnreachable;
    }
    auto frame = source.take_newest();
    if (!frame || ++taken < target) continue;
    auto rgba = frame_to_image(*frame);
    if (!rgba) {
      std::cerr << "gpubridge-view: " << rgba.error().message << "\n";
      return kExitFailure;
    }
    source.stop();
    CaptureResult result;
    result.frames_taken = taken;
    result.dropped = source.counters().dropped;
    if (auto done = finish_capture(options, *frame, *rgba, result); !done) {
      std::cerr << "gpubridge-view: " << done.error().message << "\n";
      return kExitFailure;
    }
    return kExitOk;
  }
  const SourceStatus status = source.status();
  std::string why = status_line(status);
  std::cerr << fmt::format("gpubridge-view: frame {} did not arrive within {} s (got {}){}{}\n", target,
                           options.timeout_s, taken, why.empty() ? "" : "; ", why);
  return kExitFailure;
}

}  // namespace gpubridge::viewer
