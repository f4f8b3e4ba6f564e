#pragma once
// Video memory (docs/protocol.md section 6): one byte-addressed space. Accesses beyond the end are
// dropped (writes) or read 0 (reads); the caller raises ERR_MEM_RANGE when a check fails.
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>
#include <span>

#include <sys/mman.h>

namespace gpubridge::sim {

class VideoMemory {
 public:
  // Zero-filled. Backed by 2 MiB pages where the kernel grants them (transparent huge pages on
  // request): a bilinear sample of a 4 MiB texture reads two texel rows 4 KiB apart, so with 4 KiB
  // pages every sample of a minified texture walks two pages (the page size changes no byte).
  // Memories of at least one huge page get pages of their own from mmap, never touched before the
  // request: heap memory that malloc had already handed out (and the program touched) keeps its
  // 4 KiB pages, and the bench's 16 MiB memory got 2 to 8 huge pages of 8 from run to run.
  explicit VideoMemory(std::uint64_t size) : size_(size), bytes_(allocate(size)) {}

  std::uint64_t size() const { return size_; }
  std::uint8_t* data() { return bytes_.get(); }
  const std::uint8_t* data() const { return bytes_.get(); }
  std::span<std::uint8_t> span() { return {bytes_.get(), size_}; }
  std::span<const std::uint8_t> span() const { return {bytes_.get(), size_}; }

  // True when [address, address + length) lies inside memory (64-bit math: never wraps).
  bool contains(std::uint64_t address, std::uint64_t length) const {
    return address <= size_ && length <= size_ - address;
  }
  // Copies length bytes at address into out; bytes beyond the end read 0. Returns false when any
  // byte was out of range.
  bool read(std::uint64_t address, std::uint8_t* out, std::size_t length) const {
    if (contains(address, length)) {
      std::memcpy(out, bytes_.get() + address, length);
      return true;
    }
    for (std::size_t i = 0; i < length; ++i)
      out[i] = address + i < size_ ? bytes_[address + i] : 0;
    return false;
  }
  // Writes the bytes that fall inside memory; returns false when any byte was dropped.
  bool write(std::uint64_t address, const std::uint8_t* in, std::size_t length) {
    if (contains(address, length)) {
      std::memcpy(bytes_.get() + address, in, length);
      return true;
    }
    for (std::size_t i = 0; i < length; ++i)
      if (address + i < size_) bytes_[address + i] = in[i];
    return false;
  }

 private:
  // Frees what allocate() reserved: munmap for whole huge pages (mapped), free() otherwise.
  struct Free {
    std::size_t mapped;  // bytes mapped by mmap, 0 for aligned_alloc
    void operator()(std::uint8_t* p) const {
      if (mapped) (void)munmap(p, mapped);
      else std::free(p);
    }
  };
  static constexpr std::size_t kHugePage = std::size_t{2} << 20;
  static std::unique_ptr<std::uint8_t[], Free> allocate(std::uint64_t size) {
    // Memories of at least one huge page are rounded up to whole ones; smaller ones (tests) to a
    // cache line, at least one, so that data() is never null.
    const bool huge = size >= kHugePage;
    const std::size_t align = huge ? kHugePage : 64;
    if (size > SIZE_MAX - 2 * align) throw std::bad_alloc();  // the rounding below must not wrap
    const std::size_t bytes = (static_cast<std::size_t>(size == 0 ? 1 : size) + align - 1) & ~(align - 1);
    if (!huge) {
      auto* p = static_cast<std::uint8_t*>(std::aligned_alloc(align, bytes));
      if (!p) throw std::bad_alloc();
      std::memset(p, 0, bytes);
      return std::unique_ptr<std::uint8_t[], Free>(p, Free{0});
    }
    // One huge page more than needed, then the unaligned ends unmapped: a 2 MiB-aligned range of
    // fresh zero pages. The hint comes before the first touch, which then faults in 2 MiB pages
    // (without it, or refused: 4 KiB pages, same bytes).
    void* m = mmap(nullptr, bytes + kHugePage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (m == MAP_FAILED) throw std::bad_alloc();
    const auto start = reinterpret_cast<std::uintptr_t>(m);
    const std::uintptr_t aligned = (start + kHugePage - 1) & ~std::uintptr_t{kHugePage - 1};
    if (aligned > start) (void)munmap(m, aligned - start);
    if (const std::size_t tail = start + kHugePage - aligned) (void)munmap(reinterpret_cast<void*>(aligned + bytes), tail);
    auto* p = reinterpret_cast<std::uint8_t*>(aligned);
    (void)madvise(p, bytes, MADV_HUGEPAGE);
    std::memset(p, 0, bytes);  // fault every page in now, not in the first frame's draws
    return std::unique_ptr<std::uint8_t[], Free>(p, Free{bytes});
  }
  std::uint64_t size_;
  std::unique_ptr<std::uint8_t[], Free> bytes_;
};

}  // namespace gpubridge::sim
