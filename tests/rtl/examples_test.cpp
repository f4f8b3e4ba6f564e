// Every demo example through the bridge path on both profiles. On ecp5 (ULX3S, FT232H) the
// gateware's scanned-out golden frame must equal examples/golden/<name>.png pixel for pixel; on
// up5k (iCEBreaker, FT2232H) the examples keep their own framebuffer size and layout, which the small
// device partly refuses (sizes above 320 x 240, memory beyond 128 KiB) with the same error flags as
// the simulator configured like it. Video memory and frames are compared with the simulator on the
// same wires in both.
#include <gtest/gtest.h>

#include "gateware_board.hpp"
#include "gpubridge/common/image.hpp"
#include "gpubridge/draw/context.hpp"
#include "gpubridge/draw/sink.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/examples/golden.hpp"

namespace gpubridge::test {
namespace {

// The board as a drawing sink that lays buffers out as for an 8 MiB device: uploads beyond the
// board's VRAM are cut at its end (what lies beyond reads 0 on both devices).
class LayoutSink final : public draw::CommandSink {
 public:
  LayoutSink(backends::Backend& b, std::uint64_t layout_bytes) : b_(b), layout_(layout_bytes) {}
  Result<void> write_frames(protocol::FrameView frames) override { return b_.write_frames(frames); }
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override {
    const std::uint64_t vram = b_.info().vram_bytes;
    if (address >= vram) return {};
    return b_.upload(address, bytes.first(std::min<std::uint64_t>(bytes.size(), vram - address)));
  }
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override {
    return b_.readback(address, length);
  }
  Result<void> flush() override { return b_.flush(); }
  // An 8 MiB device without framebuffer limits, so that the examples keep their own layout and sizes
  // (the drawing context would otherwise fit them to the board): the small device then refuses what
  // it lacks, as the simulator configured like it does.
  backends::DeviceInfo device() const override {
    backends::DeviceInfo d = b_.info();
    d.vram_bytes = std::max(layout_, d.vram_bytes);
    d.max_width = protocol::kMaxFramebufferDim;
    d.max_height = protocol::kMaxFramebufferDim;
    return d;
  }

 private:
  backends::Backend& b_;
  std::uint64_t layout_;
};

struct ExampleCase {
  std::string example;
  std::string board;
};
void PrintTo(const ExampleCase& c, std::ostream* os) { *os << c.example << " on " << c.board; }

class Examples : public ::testing::TestWithParam<ExampleCase> {};

TEST_P(Examples, GoldenFrameOnTheGateware) {
  if (!rtl::RtlDevice::available()) GTEST_SKIP() << rtl::RtlDevice::unavailable_reason();
  auto profile = board_profile(GetParam().board);
  profile.scanout = usb::ScanoutMode::CrcOnly;  // the gateware's own scanout is captured; no SPI readback of each frame
  auto g = GatewareBoard::open(profile);
  ASSERT_TRUE(g) << g.error().message;
  auto ex = examples::make_example(GetParam().example);
  ASSERT_NE(ex, nullptr);
  LayoutSink sink((*g)->backend(), 8u << 20);
  auto ctx = draw::Context::create(sink, ex->options());
  ASSERT_TRUE(ctx) << ctx.error().message;
  const auto r = examples::run_frames(*ex, *ctx, examples::kGoldenFrame, 1);
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_EQ((*g)->compare(), "");
  ASSERT_FALSE((*g)->gateware_frames().empty());
  const auto c = (*g)->gateware().counters();
  std::printf("  %s on %s: %llu triangles, %llu pixels, %llu textured, %llu work cycles, %llu SPI frames\n",
              GetParam().example.c_str(), GetParam().board.c_str(), static_cast<unsigned long long>(c.triangles),
              static_cast<unsigned long long>(c.pixels), static_cast<unsigned long long>(c.textured),
              static_cast<unsigned long long>(c.work_cycles), static_cast<unsigned long long>(c.spi_frames));
  if (profile.gateware != "ecp5") return;
  const auto& f = (*g)->gateware_frames().back();
  const Image got = image_from_device(f.format, f.width, f.height, f.bytes);
  auto golden = load_png(examples::golden_path(GPUBRIDGE_GOLDEN_DIR, GetParam().example));
  ASSERT_TRUE(golden) << golden.error().message;
  const auto d = examples::compare_images(*golden, got);
  EXPECT_TRUE(d.identical()) << GetParam().example << ": " << d.summary();
}

std::vector<ExampleCase> cases() {
  std::vector<ExampleCase> out;
  for (const auto& n : examples::example_names())
    for (const char* b : {"ulx3s", "icebreaker"}) out.push_back({n, b});
  return out;
}

INSTANTIATE_TEST_SUITE_P(All, Examples, ::testing::ValuesIn(cases()),
                         [](const auto& p) {
                           std::string n = p.param.example + "_" + p.param.board;  // torus-temporal: no '-' in test names
                           for (char& c : n)
                             if (c == '-') c = '_';
                           return n;
                         });

}  // namespace
}  // namespace gpubridge::test
