#include "gpubridge/dmc1/uart.hpp"

#include <cmath>

namespace gpubridge::dmc1 {

std::uint64_t screen_word(const ScreenCommand& c) {
  if (c.reset_control) return (1ull << 32) | (std::uint64_t{c.reset_level} << 33);
  return c.data & 0x1FFFF;
}

ScreenCommand screen_reset(bool level) { return ScreenCommand{true, level, 0}; }

ScreenCommand screen_byte(bool is_data, std::uint8_t byte) {
  return ScreenCommand{false, false, (is_data ? 0x100u : 0u) | byte};
}

void UartFramer::start(std::vector<std::uint8_t>& out) {
  out.push_back(0x00);
  out.push_back(kSyncByte);
  started_ = true;
  armed_ = false;  // the sync byte is not zero: it clears the tracker
}

void UartFramer::word(std::uint64_t w, std::vector<std::uint8_t>& out) {
  if (!started_) start(out);
  for (int b = 7; b >= 0; --b) out.push_back(static_cast<std::uint8_t>(w >> (8 * b)));
  armed_ = !(armed_ && w == 0);  // an escape disarms the tracker for one word
}

void UartFramer::command(std::uint64_t w, std::vector<std::uint8_t>& out) {
  if (!started_) start(out);
  word(w == 0 && armed_ ? kZeroStandIn : w, out);
}

void UartFramer::commands(std::span<const std::uint64_t> words, std::vector<std::uint8_t>& out) {
  out.reserve(out.size() + words.size() * 8);
  for (const std::uint64_t w : words) command(w, out);
}

void UartFramer::screen(const ScreenCommand& c, std::vector<std::uint8_t>& out) {
  if (!started_) start(out);
  if (!armed_) word(kNoOpWord, out);
  word(0, out);
  word(screen_word(c), out);
}

void SocReceiver::reset() {
  synced_ = false;
  position_ = 0;
  all_zeros_ = true;
  next_for_screen_ = false;
  received_ = 0;
}

void SocReceiver::byte(std::uint8_t b) {
  ++stats_.bytes;
  received_ = received_ << 8 | b;
  all_zeros_ = all_zeros_ && b == 0;
  if (!synced_) {
    if (b == kSyncByte) synced_ = true;
    else ++stats_.ignored_before_sync;
    return;
  }
  if (++position_ < 8) return;
  position_ = 0;
  if (next_for_screen_) {
    ++stats_.screen_commands;
    ScreenCommand c;
    c.reset_control = (received_ >> 32) & 1;
    c.reset_level = (received_ >> 33) & 1;
    c.data = c.reset_control ? 0 : static_cast<std::uint32_t>(received_ & 0x1FFFF);
    if (screen_) screen_(c);
  }
  ++stats_.words;
  if (gpu_) gpu_(received_);  // every word, escapes and screen words too
  next_for_screen_ = all_zeros_;
  if (all_zeros_) ++stats_.escapes;
  all_zeros_ = !all_zeros_;
}

std::vector<std::uint8_t> uart_transfer(std::span<const std::uint8_t> bytes, double tx_baud, double rx_baud,
                                        LineStats* stats, double rx_clock_hz) {
  LineStats local;
  LineStats& st = stats ? *stats : local;
  std::vector<std::uint8_t> out;
  if (bytes.empty() || !(tx_baud > 0) || !(rx_baud > 0) || !(rx_clock_hz > 0)) return out;
  // Time is counted in receiver clock ticks; the sender's bits are tx_bit ticks long.
  const double tx_bit = rx_clock_hz / tx_baud;
  const std::uint64_t total_bits = std::uint64_t{bytes.size()} * kUartBitsPerByte;
  // The level of sender bit `bit`: back-to-back 8N1 frames, idle (high) after the last one.
  auto bit_level = [&](std::uint64_t bit) -> bool {
    if (bit >= total_bits) return true;
    const unsigned in_frame = static_cast<unsigned>(bit % kUartBitsPerByte);
    if (in_frame == 0) return false;  // start
    if (in_frame == 9) return true;   // stop
    return (bytes[bit / kUartBitsPerByte] >> (in_frame - 1)) & 1;
  };
  auto bit_at = [&](double tick) { return static_cast<std::uint64_t>(tick / tx_bit); };
  auto level = [&](double tick) { return bit_level(bit_at(tick)); };
  const double period = std::round(rx_clock_hz / rx_baud);  // the receiver counts whole clock cycles
  std::uint64_t bit = 0;  // first sender bit the idle receiver has not looked at
  for (;;) {
    // Idle: the next high-to-low transition (bit 0 follows the idle line).
    while (bit < total_bits && (bit_level(bit) || (bit > 0 && !bit_level(bit - 1)))) ++bit;
    if (bit >= total_bits) break;
    const double seen = std::ceil(static_cast<double>(bit) * tx_bit);  // seen at the next clock edge
    if (level(seen + period / 2)) {  // high again mid start bit: a glitch, not a start
      ++st.false_starts;
      bit = bit_at(seen + period / 2) + 1;
      continue;
    }
    std::uint8_t v = 0;
    for (unsigned i = 0; i < 8; ++i)
      if (level(seen + (i + 1.5) * period)) v = static_cast<std::uint8_t>(v | (1u << i));
    out.push_back(v);
    ++st.bytes_received;
    const double stop = seen + 9.5 * period;
    if (!level(stop)) ++st.framing_errors;
    bit = bit_at(stop);  // from the stop sample on, wait for high, then for the next fall
    while (bit < total_bits && !bit_level(bit)) ++bit;
  }
  return out;
}

}  // namespace gpubridge::dmc1
