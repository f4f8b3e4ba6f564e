#pragma once
// Reads a fuzz input as a script of small decisions (a status here, a length there). Once the
// bytes run out every read returns 0 and exhausted() turns true, so a harness can stop or answer
// with a terminal failure instead of looping on an empty script.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>

namespace gpubridge::fuzz {

class FuzzInput {
 public:
  FuzzInput(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  bool exhausted() const { return pos_ >= size_; }
  std::uint8_t byte() { return exhausted() ? 0 : data_[pos_++]; }
  std::uint16_t u16() { return static_cast<std::uint16_t>(byte() | byte() << 8); }
  // Copies up to out.size() bytes of the script into out and zero-fills the rest.
  void fill(std::span<std::uint8_t> out) {
    const std::size_t n = std::min(out.size(), size_ - std::min(pos_, size_));
    std::copy_n(data_ + pos_, n, out.begin());
    std::fill(out.begin() + static_cast<std::ptrdiff_t>(n), out.end(), std::uint8_t{0});
    pos_ += n;
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

}  // namespace gpubridge::fuzz
