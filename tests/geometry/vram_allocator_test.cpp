// The drawing API's video-memory allocator: first-fit placement, reuse after release, coalescing
// of free neighbours, clear errors when full, harmless double release. Expected addresses follow
// from the documented rules (256-byte blocks, lowest address that fits).
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

#include "gpubridge/draw/vram_allocator.hpp"

namespace gpubridge::draw {
namespace {

constexpr std::uint64_t K = 1024;

TEST(VramAllocator, HandsOutAlignedBlocksUpwardsLikeABumpAllocator) {
  VramAllocator a(64 * K);
  EXPECT_EQ(*a.allocate(1), 0u);         // rounded up to 256
  EXPECT_EQ(*a.allocate(300), 256u);     // rounded up to 512
  EXPECT_EQ(*a.allocate(256), 768u);
  EXPECT_EQ(a.block_size(256), 512u);
  EXPECT_EQ(a.free_bytes(), 64 * K - 1024);
  EXPECT_EQ(a.free_block_count(), 1u);
  EXPECT_EQ(a.allocated_block_count(), 3u);
}

TEST(VramAllocator, ReleaseThenAllocateReusesTheAddress) {
  VramAllocator a(64 * K);
  ASSERT_TRUE(a.allocate(K));
  const auto b = a.allocate(2 * K);
  ASSERT_TRUE(b);
  ASSERT_TRUE(a.allocate(K));
  ASSERT_TRUE(a.release(*b));
  EXPECT_EQ(*a.allocate(2 * K), *b);  // same size: the hole it left
  ASSERT_TRUE(a.release(*b));
  EXPECT_EQ(*a.allocate(K), *b);      // smaller: first fit still takes the lowest hole
}

TEST(VramAllocator, FragmentationAndCoalescing) {
  VramAllocator a(8 * K);
  const std::uint32_t A = *a.allocate(K), B = *a.allocate(K), C = *a.allocate(K);
  EXPECT_EQ(A, 0u);
  EXPECT_EQ(B, K);
  EXPECT_EQ(C, 2 * K);
  ASSERT_TRUE(a.release(B));
  EXPECT_EQ(a.free_block_count(), 2u);  // [1K, 2K) and [3K, 8K)
  // 2 KiB does not fit the 1 KiB hole: first fit moves on to the top.
  const std::uint32_t D = *a.allocate(2 * K);
  EXPECT_EQ(D, 3 * K);
  // A's block merges with B's hole (neighbour after it): one hole [0, 2K).
  ASSERT_TRUE(a.release(A));
  EXPECT_EQ(a.free_block_count(), 2u);
  EXPECT_EQ(a.largest_free_block(), 3 * K);  // [5K, 8K)
  EXPECT_EQ(*a.allocate(2 * K), 0u);         // fits the merged hole now
  ASSERT_TRUE(a.release(0));
  // C merges with the hole before it; then D with both neighbours: everything is one block again.
  ASSERT_TRUE(a.release(C));
  EXPECT_EQ(a.free_block_count(), 2u);
  ASSERT_TRUE(a.release(D));
  EXPECT_EQ(a.free_block_count(), 1u);
  EXPECT_EQ(a.largest_free_block(), 8 * K);
  EXPECT_EQ(a.free_bytes(), 8 * K);
  EXPECT_EQ(*a.allocate(8 * K), 0u);
}

TEST(VramAllocator, FullIsAnErrorNamingTheSizes) {
  VramAllocator a(8 * K);
  ASSERT_TRUE(a.allocate(K));
  const auto mid = a.allocate(K);
  ASSERT_TRUE(a.allocate(2 * K));
  ASSERT_TRUE(a.release(*mid));
  // Free: [1K, 2K) and [4K, 8K): 5 KiB free in total but no 5000-byte block.
  auto r = a.allocate(5000);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("video memory full: 5000 bytes requested, largest free block 4096 bytes"),
            std::string::npos)
      << r.error().message;
  EXPECT_NE(r.error().message.find("release textures or use a smaller format"), std::string::npos);
  EXPECT_EQ(a.free_bytes(), 5 * K);  // a failed request changes nothing
  EXPECT_FALSE(a.allocate(0));
  EXPECT_FALSE(a.allocate(std::numeric_limits<std::uint64_t>::max()));  // no overflow when rounding
  EXPECT_FALSE(a.allocate(8 * K + 1));
}

TEST(VramAllocator, DoubleReleaseAndUnknownAddressesAreHarmless) {
  VramAllocator a(8 * K);
  const auto x = a.allocate(K);
  ASSERT_TRUE(a.allocate(K));
  ASSERT_TRUE(a.release(*x));
  const auto free_before = a.free_bytes();
  EXPECT_FALSE(a.release(*x));
  EXPECT_FALSE(a.release(512));        // inside a block, not its start
  EXPECT_FALSE(a.release(7 * K));      // free memory
  EXPECT_EQ(a.free_bytes(), free_before);
  EXPECT_EQ(a.free_block_count(), 2u);
}

TEST(VramAllocator, AddressesStayWithin32Bits) {
  VramAllocator a(std::uint64_t{1} << 40);
  EXPECT_EQ(a.capacity(), std::uint64_t{1} << 32);
  VramAllocator odd(1000);  // only whole 256-byte blocks
  EXPECT_EQ(odd.capacity(), 768u);
}

}  // namespace
}  // namespace gpubridge::draw
