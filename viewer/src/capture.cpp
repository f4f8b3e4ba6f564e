#include "capture.hpp"

#include <filesystem>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "gpubridge/viewer/frame_source.hpp"
#include "gpubridge/common/json_text.hpp"

namespace gpubridge::viewer {

Result<void> finish_capture(const Options& options, const Frame& frame, const Image& rgba,
                            const CaptureResult& result) {
  if (!options.screenshot.empty()) {
    if (auto saved = save_png(options.screenshot, rgba); !saved) return saved.error();
  }
  const bool crc_ok = crc_matches(frame);
  if (options.json) {
    nlohmann::json j = {
        {"frame", frame.number},       {"width", frame.width},
        {"height", frame.height},      {"format", std::string(protocol::to_string(frame.format))},
        {"crc", fmt::format("{:08x}", frame.crc)}, {"crc_ok", crc_ok},
        {"frames_taken", result.frames_taken},     {"dropped", result.dropped},
    };
    j["source"] = std::string(protocol::to_string(frame.source));
    if (!options.screenshot.empty()) j["screenshot"] = options.screenshot;
    if (!result.window_grab.empty()) j["window_grab"] = result.window_grab;
    if (result.fps_drawn) j["fps_drawn"] = *result.fps_drawn;
    if (result.latency_ms_mean) j["latency_ms_mean"] = *result.latency_ms_mean;
    if (result.latency_ms_max) j["latency_ms_max"] = *result.latency_ms_max;
    std::cout << json_text(j) << std::endl;
  } else {
    std::cout << fmt::format("frame {} ({}{}, crc {:08x}{})", frame.number, describe_size(frame),
                             frame.source == protocol::FrameSource::Board ? "" : ", " + picture_name(frame.source),
                             frame.crc, crc_ok ? "" : " MISMATCH");
    if (!options.screenshot.empty()) std::cout << " saved to " << options.screenshot;
    if (!result.window_grab.empty()) std::cout << "; window grab saved to " << result.window_grab;
    std::cout << std::endl;
  }
  return {};
}

std::string screenshot_path(const std::string& dir, std::uint32_t frame_number) {
  const std::filesystem::path base = std::filesystem::path(dir.empty() ? "." : dir);
  auto candidate = base / fmt::format("gpubridge-frame-{:06}.png", frame_number);
  for (int n = 2; std::filesystem::exists(candidate) && n < 1000; ++n) {
    candidate = base / fmt::format("gpubridge-frame-{:06}-{}.png", frame_number, n);
  }
  return candidate.string();
}

}  // namespace gpubridge::viewer
