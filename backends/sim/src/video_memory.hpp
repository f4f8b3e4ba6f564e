#pragma once
// Video memory (docs/protocol.md section 6): one byte-addressed space. Accesses beyond the end are
// dropped (writes) or read 0 (reads); the caller raises ERR_MEM_RANGE when a check fails.
#include <cstdint>
#include <cstring>
#include <span>
#include <vector>

namespace gpubridge::sim {

class VideoMemory {
 public:
  explicit VideoMemory(std::uint64_t size) : bytes_(size, 0) {}

  std::uint64_t size() const { return bytes_.size(); }
  std::uint8_t* data() { return bytes_.data(); }
  const std::uint8_t* data() const { return bytes_.data(); }
  std::span<std::uint8_t> span() { return bytes_; }
  std::span<const std::uint8_t> span() const { return bytes_; }

  // True when [address, address + length) lies inside memory (64-bit math: never wraps).
  bool contains(std::uint64_t address, std::uint64_t length) const {
    return address <= bytes_.size() && length <= bytes_.size() - address;
  }
  // Copies length bytes at address into out; bytes beyond the end read 0. Returns false when any
  // byte was out of range.
  bool read(std::uint64_t address, std::uint8_t* out, std::size_t length) const {
    if (contains(address, length)) {
      std::memcpy(out, bytes_.data() + address, length);
      return true;
    }
    for (std::size_t i = 0; i < length; ++i)
      out[i] = address + i < bytes_.size() ? bytes_[address + i] : 0;
    return false;
  }
  // Writes the bytes that fall inside memory; returns false when any byte was dropped.
  bool write(std::uint64_t address, const std::uint8_t* in, std::size_t length) {
    if (contains(address, length)) {
      std::memcpy(bytes_.data() + address, in, length);
      return true;
    }
    for (std::size_t i = 0; i < length; ++i)
      if (address + i < bytes_.size()) bytes_[address + i] = in[i];
    return false;
  }

 private:
  std::vector<std::uint8_t> bytes_;
};

}  // namespace gpubridge::sim
