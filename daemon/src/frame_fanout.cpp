#include "gpubridge/daemon/frame_fanout.hpp"

#include <optional>

#include "gpubridge/common/image.hpp"
#include "gpubridge/daemon/frame_diff.hpp"
#include "gpubridge/protocol/crc32.hpp"

namespace gpubridge::daemon {
namespace {

using protocol::FrameFormat;
using protocol::PixelFormat;

std::optional<PixelFormat> pixel_format_for(FrameFormat f, PixelFormat native) {
  switch (f) {
    case FrameFormat::Native: return native;
    case FrameFormat::RGBA8888: return PixelFormat::RGBA8888;
    case FrameFormat::RGB565: return PixelFormat::RGB565;
    case FrameFormat::RGBA2222: return PixelFormat::RGBA2222;
  }
  return std::nullopt;
}

}  // namespace

std::shared_ptr<const backends::ScanoutFrame> FrameFanout::picture(protocol::FrameSource source) {
  switch (source) {
    case protocol::FrameSource::Board: return frame_->pixels.empty() ? nullptr : frame_;
    case protocol::FrameSource::Sim:
      return frame_->reference && !frame_->reference->pixels.empty() ? frame_->reference : nullptr;
    case protocol::FrameSource::Diff:
      if (!diff_done_ && frame_->reference) diff_ = diff_frame(*frame_, *frame_->reference);
      diff_done_ = true;
      return diff_;
  }
  return nullptr;
}

FrameFanout::Buffer FrameFanout::message(protocol::FrameSource source, FrameFormat format) {
  const auto src = static_cast<std::size_t>(source);
  const auto slot = static_cast<std::size_t>(format) & 3;
  if (src >= 3) return nullptr;
  if (encoded_[src][slot]) return encoded_[src][slot];
  const auto shown = picture(source);
  if (!shown) return nullptr;
  const auto& f = *shown;
  const PixelFormat target = pixel_format_for(format, f.format).value_or(f.format);
  std::vector<std::uint8_t> converted;
  std::span<const std::uint8_t> pixels = f.pixels;
  if (target != f.format) {
    converted = device_from_image(target, image_from_device(f.format, f.width, f.height, f.pixels));
    pixels = converted;
  }
  protocol::FrameData d;
  d.number = frame_->number;  // every picture of a swap carries the board's frame number and swap time
  d.width = static_cast<std::uint16_t>(f.width);
  d.height = static_cast<std::uint16_t>(f.height);
  d.format = target;
  d.crc = target == f.format ? f.crc : protocol::crc32(pixels);
  d.swap_ns = static_cast<std::uint64_t>(
      std::chrono::duration_cast<std::chrono::nanoseconds>(frame_->swap_time.time_since_epoch()).count());
  d.pixels = pixels;
  d.source = source;
  auto bytes = std::make_shared<std::vector<std::uint8_t>>();
  protocol::encode(protocol::Message{0, d}, *bytes);
  encoded_[src][slot] = std::move(bytes);
  return encoded_[src][slot];
}

}  // namespace gpubridge::daemon
