// Random register garbage: every input has a defined result (the suite also runs under UBSan in
// the sanitizer build), the device keeps answering, and RESET brings it back.
#include <gtest/gtest.h>

#include <cstdint>
#include <new>
#include <random>
#include <utility>

#include "sim_test_util.hpp"
#include "video_memory.hpp"

namespace gpubridge::sim::test {
namespace {

using namespace protocol;

TEST(SimRobustness, RandomFramesNeverBreakTheDevice) {
  std::mt19937_64 rng(42);
  DeviceOptions o;
  o.vram_bytes = 256 << 10;  // small: framebuffers and textures often reach beyond VRAM
  o.max_width = 96;
  o.max_height = 64;
  // Both rasterisers: the exact one and the preview one (float planes: every conversion of a lane
  // to an integer must meet a clamped value, whatever the registers hold).
  for (const auto& [threads, preview] : {std::pair{1u, false}, std::pair{3u, false}, std::pair{1u, true}, std::pair{3u, true}}) {
    o.threads = threads;
    o.accuracy.preview = preview;
    auto d = make_device(o);
    const std::uint8_t interesting[] = {0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x09, 0x0A, 0x0B,
                                        0x0C, 0x0D, 0x0E, 0x0F, 0x10, 0x11, 0x12, 0x13, 0x14, 0x15, 0x16, 0x18,
                                        0x70, 0x71, 0x7E, 0x7F, 0x42};
    for (int i = 0; i < 30000; ++i) {
      Frame f;
      f.index = interesting[rng() % std::size(interesting)];
      f.read = rng() % 8 == 0;
      switch (rng() % 4) {
        case 0: f.data = rng(); break;
        case 1: f.data = rng() & 0xFFFF'FFFF; break;
        case 2: f.data = rng() & 0x00FF'FFFF'FFFF'FFFFull; break;
        default: f.data = (rng() % 3 == 0) ? 0 : (rng() & 0x0FFF'0FFF); break;
      }
      if (f.index == index_of(Reg::RESET) && rng() % 4 == 0) f.data = kResetMagic;
      if (f.index == index_of(Reg::LINK_CTRL))  // strict mode on, off (with the key half the time)
        f.data = (f.data & 1) | (rng() % 2 ? std::uint64_t{kLinkClearKey} << 32 : 0);
      if (rng() % 500 == 0) d->frame_aborted();
      d->write(f);
    }
    d->write(write_frame(Reg::LINK_CTRL, std::uint64_t{kLinkClearKey} << 32));
    d->write(write_frame(Reg::RESET, kResetMagic));
    EXPECT_EQ(d->read(index_of(Reg::ID)) >> 32, kIdMagic);
    EXPECT_EQ(d->read(index_of(Reg::STATUS)) >> 48, 0u);
    EXPECT_EQ(d->read(index_of(Reg::TRI_MODE)), 0u);
    EXPECT_GT(d->stats().triangles_kicked, 0u);
  }
}

// The memory is rounded up to whole pages before it is allocated: a size whose rounding would wrap
// must be refused, not turned into a tiny buffer that size() and contains() then overstate.
TEST(SimRobustness, VideoMemoryRefusesASizeWhoseRoundingWraps) {
  EXPECT_THROW(VideoMemory(SIZE_MAX - 5), std::bad_alloc);
  EXPECT_THROW(VideoMemory(SIZE_MAX - (std::uint64_t{2} << 20) + 1), std::bad_alloc);
  const VideoMemory small(3);
  EXPECT_EQ(small.size(), 3u);
  EXPECT_FALSE(small.contains(0, 4));
  const VideoMemory huge(std::uint64_t{4} << 20);
  EXPECT_EQ(huge.size(), std::uint64_t{4} << 20);
  EXPECT_EQ(huge.data()[(std::uint64_t{4} << 20) - 1], 0);
}

// Memories of at least one huge page are mapped 2 MiB-aligned (whole huge pages for the kernel to
// grant) and read zero everywhere; a size that is not a whole number of huge pages keeps its size.
TEST(SimRobustness, VideoMemoryOfHugePagesIsAlignedAndZero) {
  constexpr std::uint64_t kHuge = std::uint64_t{2} << 20;
  for (const std::uint64_t size : {kHuge, 3 * kHuge + 5, 16 * kHuge}) {
    VideoMemory mem(size);
    EXPECT_EQ(mem.size(), size);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(mem.data()) % kHuge, 0u) << size;
    std::uint64_t nonzero = 0;
    for (std::uint64_t i = 0; i < size; ++i) nonzero += mem.data()[i] != 0;
    EXPECT_EQ(nonzero, 0u) << size;
    const std::uint8_t last = 0xA5;  // the last byte is writable and read back
    EXPECT_TRUE(mem.write(size - 1, &last, 1));
    EXPECT_EQ(mem.data()[size - 1], last);
    EXPECT_FALSE(mem.contains(size - 1, 2));
  }
}

}  // namespace
}  // namespace gpubridge::sim::test
