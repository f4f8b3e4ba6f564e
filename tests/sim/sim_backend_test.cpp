// SimBackend: the Backend interface over the device (what the daemon uses by default).
#include <gtest/gtest.h>

#include "gpubridge/sim/sim_backend.hpp"
#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

using namespace protocol;

TEST(SimBackendTest, FramesUploadReadbackAndScanout) {
  DeviceOptions o;
  o.vram_bytes = 1 << 20;
  auto b = SimBackend::create(o);
  ASSERT_TRUE(b.ok());
  auto& be = **b;
  EXPECT_EQ(be.info().backend, "sim");
  EXPECT_EQ(be.info().vram_bytes, 1u << 20);
  EXPECT_EQ(be.info().id >> 32, kIdMagic);

  std::vector<std::uint8_t> bytes = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
  ASSERT_TRUE(be.upload(0x1003, bytes).ok());
  auto rb = be.readback(0x1003, 11);
  ASSERT_TRUE(rb.ok());
  EXPECT_EQ(*rb, bytes);
  EXPECT_FALSE(be.upload((1 << 20) - 4, bytes).ok());
  EXPECT_FALSE(be.readback((1 << 20) - 4, 8).ok());

  int frames = 0;
  std::uint32_t crc = 0;
  be.set_scanout_callback([&](std::shared_ptr<const backends::ScanoutFrame> f) {
    ++frames;
    crc = f->crc;
  });
  std::vector<std::uint8_t> wire;
  append(wire, write_frame(Reg::FB_FORMAT, fb_format(4, 4)));
  append(wire, write_frame(Reg::CLEAR_COLOR, 0xFF0000FF));
  append(wire, write_frame(Reg::CLEAR, 0));
  append(wire, write_frame(Reg::FB_DISPLAY, 0));
  ASSERT_TRUE(be.write_frames(FrameView{wire}).ok());
  ASSERT_TRUE(be.flush().ok());
  EXPECT_EQ(frames, 1);
  auto fc = be.read_register(index_of(Reg::FRAME_CRC));
  ASSERT_TRUE(fc.ok());
  EXPECT_EQ(*fc & 0xFFFFFFFF, crc);

  std::vector<std::uint8_t> bad;
  append(bad, read_frame(Reg::STATUS));
  auto r = be.write_frames(FrameView{bad});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, backends::kBadRequest);

  ASSERT_TRUE(be.write_frames(FrameView{std::span<const std::uint8_t>(wire).first(9)}).ok());  // FB_FORMAT
  std::vector<std::uint8_t> tag;
  append(tag, write_frame(Reg::HOST_TAG, 5));
  ASSERT_TRUE(be.write_frames(FrameView{tag}).ok());
  ASSERT_TRUE(be.reset().ok());
  EXPECT_EQ(*be.read_register(index_of(Reg::HOST_TAG)), 0u);
  EXPECT_EQ(*be.read_register(index_of(Reg::FB_FORMAT)), describe(Reg::FB_FORMAT).reset);
}

}  // namespace
}  // namespace gpubridge::sim::test
