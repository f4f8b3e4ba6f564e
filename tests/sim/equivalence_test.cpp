// Fast paths give the bytes of the general path: Gouraud with equal colours vs flat, the direct
// RGBA8888 store vs the blend path (ADD onto zero), "no work when nothing is written", and
// identical output for any thread count.
#include <gtest/gtest.h>

#include <random>

#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

using namespace protocol;

struct RandomScene {
  std::uint32_t seed;
  unsigned triangles;
  int max_size;  // in pixels
  void draw(Canvas& c, std::uint64_t tri_mode) const {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> px(-20 * 16, static_cast<int>(c.width + 20) * 16);
    std::uniform_int_distribution<int> py(-20 * 16, static_cast<int>(c.height + 20) * 16);
    std::uniform_int_distribution<int> d(-max_size * 16, max_size * 16);
    std::uniform_int_distribution<std::uint32_t> col(0, 0xFFFFFFFFu), z(0, 0xFFFFFF);
    w(*c.dev, Reg::TRI_MODE, tri_mode);
    for (unsigned i = 0; i < triangles; ++i) {
      const int x = px(rng), y = py(rng);
      c.tri(x, y, x + d(rng), y + d(rng), x + d(rng), y + d(rng), col(rng), col(rng), col(rng), z(rng), z(rng), z(rng));
    }
  }
};

std::vector<std::uint8_t> render(const RandomScene& s, std::uint64_t mode, unsigned threads, unsigned w_ = 200,
                                 unsigned h_ = 150) {
  DeviceOptions o;
  o.threads = threads;
  Canvas c(w_, h_, 0, o);
  w(*c.dev, Reg::CLEAR_DEPTH, 0xFFFFFF);
  w(*c.dev, Reg::CLEAR_Z, 0);
  s.draw(c, mode);
  auto bytes = c.color_bytes();
  const auto m = c.dev->memory();
  bytes.insert(bytes.end(), m.begin() + Canvas::kZBase, m.begin() + Canvas::kZBase + w_ * h_ * 4);
  return bytes;
}

TEST(SimEquivalence, ThreadCountDoesNotChangeBytes) {
  const std::uint64_t gouraud_z = 1 | 4 | (1u << 3) | (1u << 6);  // Gouraud, LESS, Z write
  const std::uint64_t blended = 1 | (1u << 7);                    // Gouraud, alpha blend
  for (const RandomScene& s : {RandomScene{1, 400, 12}, RandomScene{2, 60, 150}}) {
    for (std::uint64_t mode : {gouraud_z, blended}) {
      const auto one = render(s, mode, 1);
      for (unsigned t : {2u, 3u, 4u, 7u}) EXPECT_EQ(render(s, mode, t), one) << "threads " << t << " mode " << mode;
    }
  }
}

// Several batches in flight one after another (more than Renderer::kMaxBatch triangles), render
// state changes between them, and video memory written and read back in the middle of the stream:
// the front end prepares the next batch while the workers draw, and the bytes must not depend on it.
TEST(SimEquivalence, PipelinedBatchesMatchOneThread) {
  auto run = [](unsigned threads) {
    DeviceOptions o;
    o.threads = threads;
    Canvas c(160, 120, 0, o);
    w(*c.dev, Reg::CLEAR_DEPTH, 0xFFFFFF);
    w(*c.dev, Reg::CLEAR_Z, 0);
    std::mt19937 rng(77);
    std::uniform_int_distribution<int> px(0, 160 * 16), py(0, 120 * 16), d(-12 * 16, 12 * 16);
    std::vector<std::uint64_t> readback;
    for (int i = 0; i < 11000; ++i) {
      if (i % 3000 == 0) w(*c.dev, Reg::TRI_MODE, 1 | 4 | (1u << 3) | (1u << 6) | ((i / 3000 % 2) << 7));
      if (i == 5000) {  // a memory write and a prefetching read between batches
        w(*c.dev, Reg::MEM_ADDR, 8 * 160 * 4);
        w(*c.dev, Reg::MEM_DATA, 0x0123456789ABCDEFull);
        w(*c.dev, Reg::MEM_ADDR, 40 * 160 * 4);
        readback.push_back(rd(*c.dev, Reg::MEM_DATA));
      }
      const int x = px(rng), y = py(rng);
      c.tri(x, y, x + d(rng), y + d(rng), x + d(rng), y + d(rng), rng(), rng(), rng(), rng() & 0xFFFFFF,
            rng() & 0xFFFFFF, rng() & 0xFFFFFF);
    }
    c.dev->drain();
    auto bytes = c.color_bytes();
    const auto m = c.dev->memory();
    bytes.insert(bytes.end(), m.begin() + Canvas::kZBase, m.begin() + Canvas::kZBase + 160 * 120 * 4);
    for (std::uint64_t r : readback)
      for (int k = 0; k < 8; ++k) bytes.push_back(static_cast<std::uint8_t>(r >> (8 * k)));
    return std::make_pair(bytes, c.dev->stats());
  };
  const auto one = run(1);
  EXPECT_GT(one.second.pixels_depth_passed, 50000u);  // the scene draws
  EXPECT_GT(one.second.by_mode[3].rows, 10000u);      // Gouraud + Z: the timing counters count
  for (unsigned t : {2u, 3u}) {
    const auto many = run(t);
    EXPECT_EQ(many.first, one.first) << "threads " << t;
    EXPECT_TRUE(many.second == one.second) << "threads " << t << ": every counter, the timing ones included";
  }
}

TEST(SimEquivalence, GouraudWithEqualColoursEqualsFlat) {
  Canvas a(40, 40), b(40, 40);
  w(*a.dev, Reg::TRI_MODE, 1);
  w(*b.dev, Reg::TRI_MODE, 0);
  a.tri(3, 7, 600, 40, 100, 620, 0x12345678, 0x12345678, 0x12345678);
  b.tri(3, 7, 600, 40, 100, 620, 0x12345678, 0x9ABCDEF0, 0x0F0F0F0F);
  EXPECT_EQ(a.color_bytes(), b.color_bytes());
  EXPECT_GT(a.count_nonzero(), 100u);
}

TEST(SimEquivalence, DirectStoreEqualsBlendPathOntoZero) {
  const RandomScene s{5, 80, 40};
  const auto direct = render(s, 1, 1);
  const auto add = render(s, 1 | (2u << 7), 1);  // ADD onto a zero buffer is the source colour
  // Compare colour only, up to the first triangle overlap: draw single triangles instead.
  for (int i = 0; i < 20; ++i) {
    const RandomScene one{static_cast<std::uint32_t>(100 + i), 1, 60};
    const auto a = render(one, 1, 1), b = render(one, 1 | (2u << 7), 1);
    EXPECT_EQ(a, b) << i;
  }
  EXPECT_NE(direct, add);  // sanity: overlapping triangles do differ between the two modes
}

TEST(SimEquivalence, NothingWrittenMeansNothingChanges) {
  const RandomScene s{9, 50, 60};
  Canvas c(64, 64);
  w(*c.dev, Reg::CLEAR_DEPTH, 0x123456);
  w(*c.dev, Reg::CLEAR_Z, 0);
  const auto before = c.dev->memory();
  std::vector<std::uint8_t> snapshot(before.begin(), before.begin() + Canvas::kZBase + 64 * 64 * 4);
  s.draw(c, 1 | 4 | (0u << 3) | (1u << 6));  // Z test NEVER with Z write: nothing passes
  s.draw(c, 1 | (15u << 10));                // every channel masked, no Z write
  const auto after = c.dev->memory();
  EXPECT_TRUE(std::equal(snapshot.begin(), snapshot.end(), after.begin()));
  EXPECT_EQ(c.dev->stats().triangles_kicked, 100u);
}

}  // namespace
}  // namespace gpubridge::sim::test
