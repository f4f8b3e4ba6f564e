// Device::write(FrameView) takes the per-vertex writes (COLOR, TEXCOORD, VERTEX) straight from the
// wire and folds their link CRC in runs (device.cpp, write_frames); frame-by-frame arrival through
// write(Frame), the SPI target's path, is the reference. Random streams mix those writes (some
// with reserved bits set) with everything that changes how a frame is handled: strict mode on and
// off (with and without CLEAR_KEY), matching and wrong LINK_CHECKs, reads, immediate writes,
// undefined and read-only registers, RESET, clears, swaps, memory writes and random frames. The two
// devices must agree on every register, the statistics, the error flags and video memory.
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <random>
#include <vector>

#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

using namespace protocol;

// A frame stream as a host would send it, keeping the host's link CRC so LINK_CHECKs can match.
class StreamWriter {
 public:
  explicit StreamWriter(std::uint32_t seed) : rng_(seed) {}

  std::vector<std::uint8_t> make(std::size_t frames) {
    put(write_frame(Reg::FB_FORMAT, fb_format(64, 48)));
    put(write_frame(Reg::FB_Z, 0x10000));
    put(write_frame(Reg::CLEAR, 0));
    put(write_frame(Reg::CLEAR_Z, 0));
    put(write_frame(Reg::TRI_MODE, 1 | 4 | (1u << 3) | (1u << 6)));  // Gouraud, Z LESS, Z write
    while (out_.size() < frames * kFrameBytes) put(next());
    return out_;
  }

 private:
  std::uint64_t bits() { return (std::uint64_t{rng_()} << 32) | rng_(); }
  unsigned pick(unsigned n) { return rng_() % n; }

  Frame next() {
    const unsigned r = pick(200);
    if (r < 120) return vertex_frame();
    if (r < 126) return write_frame(Reg::PRIM, pick(4));  // 3 is undefined: ERR_BAD_VALUE
    if (r < 130) return write_frame(Reg::TRI_MODE, pick(2) ? 1 | 4 | (1u << 3) | (1u << 6) : bits() & 0xFFFFF);
    if (r < 138) return write_frame(Reg::LINK_CHECK, static_cast<std::uint32_t>(crc_));
    if (r < 142) return write_frame(Reg::LINK_CHECK, static_cast<std::uint32_t>(crc_) ^ (1u << pick(32)));
    if (r < 148) return write_frame(Reg::LINK_CTRL, 1);
    if (r < 151) return write_frame(Reg::LINK_CTRL, std::uint64_t{kLinkClearKey} << 32);
    if (r < 153) return write_frame(Reg::LINK_CTRL, 0);  // refused while strict
    if (r < 160) return read_frame(static_cast<Reg>(pick(0x19)));
    if (r < 162) return write_frame(Reg::HOST_TAG, bits());
    if (r < 164) return Frame{false, static_cast<std::uint8_t>(pick(2) ? 0x40 + pick(0x30) : 0x10), bits()};
    if (r < 166) return write_frame(Reg::ERR_CLEAR, bits() & 0xFFFF);
    if (r < 167) return write_frame(Reg::RESET, pick(3) ? kResetMagic : bits());
    if (r < 169) return write_frame(Reg::CLEAR, 0);
    if (r < 171) return write_frame(Reg::FB_DISPLAY, 0);
    if (r < 174) return write_frame(pick(2) ? Reg::MEM_ADDR : Reg::MEM_DATA, pick(2) ? pick(0x4000) : bits());
    if (r < 176) return write_frame(Reg::FENCE, bits());
    return Frame{pick(8) == 0, static_cast<std::uint8_t>(pick(0x80)), bits()};  // anything
  }

  Frame vertex_frame() {
    const std::uint64_t reserved = pick(20) == 0 ? bits() & 0xFF00000000000000ull : 0;
    switch (pick(3)) {
      case 0: return write_frame(Reg::COLOR, bits());
      case 1: return write_frame(Reg::TEXCOORD, bits());
      default: return write_frame(Reg::VERTEX, vtx(static_cast<int>(pick(66 * 16)) - 16, static_cast<int>(pick(50 * 16)) - 16,
                                                  rng_() & 0xFFFFFF) | reserved);
    }
  }

  void put(const Frame& f) {
    const auto b = encode(f);
    out_.insert(out_.end(), b.begin(), b.end());
    if (f.index == index_of(Reg::LINK_CHECK) || f.index == index_of(Reg::LINK_CTRL)) crc_ = crc32(0L, Z_NULL, 0);
    else crc_ = crc32(crc_, b.data(), static_cast<uInt>(b.size()));
  }

  std::mt19937 rng_;
  std::vector<std::uint8_t> out_;
  uLong crc_ = crc32(0L, Z_NULL, 0);
};

void expect_same_device(Device& bulk, Device& reference, const std::string& where) {
  for (std::uint8_t i = 0; i < 0x80; ++i) {
    if (i == index_of(Reg::MEM_DATA)) continue;  // a read advances MEM_ADDR: compared through memory
    ASSERT_EQ(bulk.read_register(i), reference.read_register(i)) << where << ": register 0x" << std::hex << int{i};
  }
  ASSERT_EQ(bulk.errors(), reference.errors()) << where;
  ASSERT_TRUE(bulk.stats() == reference.stats()) << where << ": statistics differ (frames received "
                                                 << bulk.stats().frames_received << " vs "
                                                 << reference.stats().frames_received << ")";
  const auto a = bulk.memory(), b = reference.memory();
  ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end())) << where << ": video memory differs";
}

void compare_on_random_streams(const DeviceOptions& options) {
  for (std::uint32_t seed = 1; seed <= 12; ++seed) {
    const auto bytes = StreamWriter(seed).make(6000);
    auto bulk = make_device(options), reference = make_device(options);
    std::mt19937 cut(seed * 7919);
    std::size_t at = 0;
    while (at < bytes.size()) {
      // Batches of random length, so runs and CRC folds start and end anywhere.
      const std::size_t n = std::min<std::size_t>(bytes.size() - at, (1 + cut() % 300) * kFrameBytes);
      const FrameView batch{std::span(bytes.data() + at, n)};
      bulk->write(batch);
      for (std::size_t i = 0; i < batch.size(); ++i) reference->write(batch[i]);
      at += n;
      const std::string where = "seed " + std::to_string(seed) + ", frame " + std::to_string(at / kFrameBytes);
      ASSERT_EQ(bulk->read_register(index_of(Reg::LINK_STATUS)), reference->read_register(index_of(Reg::LINK_STATUS)))
          << where;
      ASSERT_EQ(bulk->read_register(index_of(Reg::STATUS)), reference->read_register(index_of(Reg::STATUS))) << where;
    }
    expect_same_device(*bulk, *reference, "seed " + std::to_string(seed));
    EXPECT_GT(reference->stats().triangles_kicked, 0u) << "the streams must draw";
  }
}

TEST(SimFrameBatch, BulkWriteEqualsFrameByFrameArrival) { compare_on_random_streams({}); }

TEST(SimFrameBatch, BulkWriteEqualsFrameByFrameArrivalWithWorkerThreads) {
  DeviceOptions o;
  o.threads = 2;
  compare_on_random_streams(o);
}

// Timed FIFO: nothing executes at once, so every frame takes the general path.
TEST(SimFrameBatch, BulkWriteEqualsFrameByFrameArrivalWhenTimed) {
  DeviceOptions o;
  o.fifo_drain_per_frame = 1;
  o.fifo_drain_interval = 3;
  compare_on_random_streams(o);
}

TEST(SimFrameBatch, BulkWriteEqualsFrameByFrameArrivalWithoutStrictLink) {
  DeviceOptions o;
  o.features = static_cast<std::uint8_t>(kAllFeatures & ~FEATURE_STRICT_LINK);
  compare_on_random_streams(o);
}

// The streams above must reach the cases they are there for; a generator that never did would
// compare nothing.
TEST(SimFrameBatch, RandomStreamsExerciseStrictModeAndBothCheckOutcomes) {
  const auto bytes = StreamWriter(1).make(6000);
  auto d = make_device();
  d->write(FrameView{bytes});
  const std::uint64_t link = d->read_register(index_of(Reg::LINK_STATUS));
  EXPECT_GT((link >> 32) & 0xFFFF, 0u) << "no LINK_CHECK matched";
  EXPECT_GT(link >> 48, 0u) << "no LINK_CHECK failed";
  EXPECT_GT(d->stats().triangles_rasterised, 0u);
}

}  // namespace
}  // namespace gpubridge::sim::test
