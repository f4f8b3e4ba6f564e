#pragma once
// Video memory blocks for the drawing API.
//
// Address-ordered first-fit over a free list whose neighbours are always coalesced. Why first-fit
// and not best-fit: with nothing ever released it hands out addresses exactly like the old bump
// allocator (so traces and golden images do not change); it keeps long-lived blocks packed at
// low addresses and leaves the large hole at the top, which is where a later big texture fits;
// and for the few dozen blocks a drawing program has, address-ordered first-fit fragments about
// as little as best-fit while staying a simple, deterministic scan. Every block starts on a
// 256-byte boundary and its size is rounded up to 256 bytes.
#include <cstdint>
#include <map>
#include <vector>

#include "gpubridge/common/result.hpp"

namespace gpubridge::draw {

class VramAllocator {
 public:
  static constexpr std::uint64_t kAlignment = 256;
  // Addresses are 32 bits on the wire: memory beyond 4 GiB is never handed out.
  static constexpr std::uint64_t kAddressLimit = std::uint64_t{1} << 32;

  // Manages [0, bytes) (capped at kAddressLimit, rounded down to the alignment).
  explicit VramAllocator(std::uint64_t bytes);

  // The lowest free block that fits `bytes` (> 0). The error names the request and the largest
  // free block ("video memory full: ...").
  Result<std::uint32_t> allocate(std::uint64_t bytes);
  // Returns the block at `address` (an address allocate() returned) to the free list, merging it
  // with free neighbours. False, and nothing changes, when no block is allocated there (a double
  // release is harmless).
  bool release(std::uint32_t address);

  std::uint64_t capacity() const { return capacity_; }
  std::uint64_t free_bytes() const;
  std::uint64_t largest_free_block() const;
  std::size_t free_block_count() const { return free_.size(); }
  std::size_t allocated_block_count() const { return used_.size(); }
  // Size (rounded) of the block allocated at `address`, 0 when none is.
  std::uint64_t block_size(std::uint32_t address) const;

 private:
  struct Range {
    std::uint64_t address, size;
  };
  std::uint64_t capacity_;
  std::vector<Range> free_;                   // sorted by address; no two touch (always coalesced)
  std::map<std::uint64_t, std::uint64_t> used_;  // address → rounded size
};

}  // namespace gpubridge::draw
