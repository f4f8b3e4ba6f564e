#pragma once
// A frame source that needs no daemon: it generates a deterministic pattern so the display path
// (texture upload, scaling, overlay, screenshots) can be exercised on its own. Hidden CLI flag
// `--test-source WxH[:FORMAT][@FPS]`.
#include <string_view>

#include "gpubridge/common/result.hpp"
#include "gpubridge/viewer/frame_source.hpp"

namespace gpubridge::viewer {

struct TestPatternSpec {
  unsigned width = 320, height = 240;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  unsigned fps = 60;  // 1 .. 1000
};

// Parses "WxH", "WxH:FORMAT", "WxH@FPS", "WxH:FORMAT@FPS" (FORMAT: rgba8888 | rgb565 | rgba2222).
Result<TestPatternSpec> parse_test_pattern_spec(std::string_view text);

// The pattern's colour at (x, y) of frame `number`, before it is stored in the frame's format:
//   r = (x + number) mod 256, g = y mod 256, b = 255 on the 8x8 checker squares where
//   (x/8 + y/8) is odd else 0, a = 255.
// The frame bytes are these colours stored with protocol::store_pixel (truncation).
Frame make_test_frame(const TestPatternSpec& spec, std::uint32_t number, std::uint64_t swap_ns);

class TestFrameSource final : public FrameSource {
 public:
  explicit TestFrameSource(TestPatternSpec spec) : spec_(spec) {}
  ~TestFrameSource() override { stop(); }

 private:
  void run(std::stop_token stop) override;
  TestPatternSpec spec_;
};

}  // namespace gpubridge::viewer
