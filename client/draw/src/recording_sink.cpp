#include <fmt/format.h>

#include "gpubridge/draw/sink.hpp"

namespace gpubridge::draw {

Result<void> RecordingSink::write_frames(protocol::FrameView frames) {
  if (frames.size() == 0) return {};
  protocol::FramesCmd cmd;
  cmd.bytes.assign(frames.bytes.begin(), frames.bytes.end());
  stream_.commands.push_back({0, std::move(cmd)});
  return {};
}

Result<void> RecordingSink::upload(std::uint32_t address, std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) return {};
  if (std::uint64_t{address} + bytes.size() > device_.vram_bytes)
    return make_error(fmt::format("upload of {} bytes at 0x{:x} runs past the end of video memory ({} bytes)", bytes.size(),
                                  address, device_.vram_bytes));
  stream_.commands.push_back({0, protocol::UploadCmd{address, {bytes.begin(), bytes.end()}}});
  return {};
}

Result<std::vector<std::uint8_t>> RecordingSink::readback(std::uint32_t, std::uint32_t) {
  return make_error("a RecordingSink only records commands: there is no device to read back from");
}

}  // namespace gpubridge::draw
