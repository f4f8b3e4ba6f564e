#include "gpubridge/draw/vram_allocator.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace gpubridge::draw {

VramAllocator::VramAllocator(std::uint64_t bytes)
    : capacity_(std::min(bytes, kAddressLimit) / kAlignment * kAlignment) {
  if (capacity_ > 0) free_.push_back({0, capacity_});
}

Result<std::uint32_t> VramAllocator::allocate(std::uint64_t bytes) {
  if (bytes == 0) return make_error("video memory: a block of 0 bytes was requested");
  // Checked before rounding so that rounding can never overflow.
  const std::uint64_t size =
      bytes > capacity_ ? bytes : (bytes + kAlignment - 1) / kAlignment * kAlignment;
  const auto fit = std::find_if(free_.begin(), free_.end(), [&](const Range& r) { return r.size >= size; });
  if (bytes > capacity_ || fit == free_.end())
    return make_error(fmt::format("video memory full: {} bytes requested, largest free block {} bytes (of {} bytes); "
                                  "release textures or use a smaller format",
                                  bytes, largest_free_block(), capacity_));
  const std::uint64_t address = fit->address;
  fit->address += size;
  fit->size -= size;
  if (fit->size == 0) free_.erase(fit);
  used_.emplace(address, size);
  return static_cast<std::uint32_t>(address);
}

bool VramAllocator::release(std::uint32_t address) {
  const auto used = used_.find(address);
  if (used == used_.end()) return false;
  Range block{used->first, used->second};
  used_.erase(used);
  // The first free range after the block; merge with it and with the one before when they touch.
  auto next = std::lower_bound(free_.begin(), free_.end(), block.address,
                               [](const Range& r, std::uint64_t a) { return r.address < a; });
  if (next != free_.end() && block.address + block.size == next->address) {
    block.size += next->size;
    next = free_.erase(next);
  }
  if (next != free_.begin()) {
    auto prev = std::prev(next);
    if (prev->address + prev->size == block.address) {
      prev->size += block.size;
      return true;
    }
  }
  free_.insert(next, block);
  return true;
}

std::uint64_t VramAllocator::free_bytes() const {
  std::uint64_t total = 0;
  for (const auto& r : free_) total += r.size;
  return total;
}

std::uint64_t VramAllocator::largest_free_block() const {
  std::uint64_t largest = 0;
  for (const auto& r : free_) largest = std::max(largest, r.size);
  return largest;
}

std::uint64_t VramAllocator::block_size(std::uint32_t address) const {
  const auto it = used_.find(address);
  return it == used_.end() ? 0 : it->second;
}

}  // namespace gpubridge::draw
