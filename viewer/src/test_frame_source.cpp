#include "gpubridge/viewer/test_frame_source.hpp"

#include <charconv>

#include <fmt/format.h>

#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/protocol/pixel.hpp"
#include "gpubridge/viewer/clock.hpp"

namespace gpubridge::viewer {
namespace {

bool parse_unsigned(std::string_view s, unsigned& out) {
  if (s.empty()) return false;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
  return ec == std::errc() && end == s.data() + s.size();
}

}  // namespace

Result<TestPatternSpec> parse_test_pattern_spec(std::string_view text) {
  const auto bad = [&](std::string_view why) {
    return make_error(fmt::format("test source '{}': {} (expected WxH[:FORMAT][@FPS], e.g. 320x240:rgb565@60)",
                                  text, why));
  };
  TestPatternSpec spec;
  std::string_view rest = text;
  if (const auto at = rest.find('@'); at != std::string_view::npos) {
    if (!parse_unsigned(rest.substr(at + 1), spec.fps) || spec.fps == 0 || spec.fps > 1000)
      return bad("FPS must be a whole number from 1 to 1000");
    rest = rest.substr(0, at);
  }
  if (const auto colon = rest.find(':'); colon != std::string_view::npos) {
    const auto format = protocol::parse_pixel_format(rest.substr(colon + 1));
    if (!format) return bad("unknown pixel format");
    spec.format = *format;
    rest = rest.substr(0, colon);
  }
  const auto x = rest.find('x');
  if (x == std::string_view::npos || !parse_unsigned(rest.substr(0, x), spec.width) ||
      !parse_unsigned(rest.substr(x + 1), spec.height)) {
    return bad("size must be WIDTHxHEIGHT");
  }
  if (spec.width == 0 || spec.height == 0 || spec.width > kMaxFrameDim || spec.height > kMaxFrameDim)
    return bad(fmt::format("each side must be 1 .. {}", kMaxFrameDim));
  return spec;
}

Frame make_test_frame(const TestPatternSpec& spec, std::uint32_t number, std::uint64_t swap_ns) {
  Frame f;
  f.number = number;
  f.width = spec.width;
  f.height = spec.height;
  f.format = spec.format;
  f.swap_ns = swap_ns;
  const unsigned bpp = protocol::bytes_per_pixel(spec.format);
  f.pixels.resize(std::size_t{spec.width} * spec.height * bpp);
  for (unsigned y = 0; y < spec.height; ++y) {
    for (unsigned x = 0; x < spec.width; ++x) {
      const protocol::Rgba8 c{static_cast<std::uint8_t>((x + number) & 255u), static_cast<std::uint8_t>(y & 255u),
                              static_cast<std::uint8_t>(((x / 8 + y / 8) & 1u) ? 255 : 0), 255};
      protocol::store_pixel(spec.format, f.pixels.data() + (std::size_t{y} * spec.width + x) * bpp, c);
    }
  }
  f.crc = protocol::crc32(f.pixels);
  return f;
}

void TestFrameSource::run(std::stop_token stop) {
  SourceStatus status;
  status.state = SourceStatus::State::Streaming;
  status.address = "test pattern";
  status.backend = "test";
  publish_status(status);
  const auto period = std::chrono::microseconds(1'000'000 / spec_.fps);
  auto next = std::chrono::steady_clock::now();
  for (std::uint32_t number = 0; !stop.stop_requested(); ++number) {
    publish_frame(make_test_frame(spec_, number, monotonic_ns()));
    next += period;
    const auto now = std::chrono::steady_clock::now();
    if (next < now) next = now;  // running late: do not burst to catch up
    if (!sleep_for(stop, std::chrono::duration_cast<std::chrono::microseconds>(next - now))) break;
  }
}

}  // namespace gpubridge::viewer
