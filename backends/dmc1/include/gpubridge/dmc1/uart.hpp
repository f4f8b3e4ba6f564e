#pragma once
// The standalone SOC's UART link (tinygpus soc-ice40-dmc-1-standalone; docs/dmc1.md, "UART link"):
// 115,200 baud 8N1 into the iCE40, no flow control and no way back. Bytes before the first 0xAA are
// ignored; after it, every 8 bytes are one command word, most significant byte first. An all-zero
// word marks the next word as a screen command (reset line or a byte/pixel for the ST7789); the
// tracker toggles so two zero words in a row are not both escapes, and 0xAA clears it, so the
// first word after the sync byte is never an escape. Every word, escapes and screen words
// included, also goes to the GPU's command FIFO.
//
//   UartFramer   host side: commands and screen commands to bytes, avoiding accidental escapes
//   SocReceiver  the SOC's byte receiver: words to the GPU, screen commands to the panel
//   UartLine     the wire, bit by bit: what the SOC's receiver samples when the host's baud rate
//                differs from its own (framing errors, garbled bytes)
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace gpubridge::dmc1 {

inline constexpr unsigned kStandaloneBaud = 115200;
inline constexpr std::uint8_t kSyncByte = 0xAA;
inline constexpr double kSocUartClockHz = 25e6;  // the receiver runs on the 1x clock
inline constexpr unsigned kUartBitsPerByte = 10;  // start, 8 data, stop

// A word the SOC hands to the screen controller.
struct ScreenCommand {
  bool reset_control = false;  // word bit 32: drive the panel's reset line...
  bool reset_level = false;    // ...to word bit 33
  std::uint32_t data = 0;      // otherwise word bits 16:0: bit 16 pixel mode, bit 8 data/command, 7:0 byte
  friend bool operator==(const ScreenCommand&, const ScreenCommand&) = default;
};
std::uint64_t screen_word(const ScreenCommand& c);
ScreenCommand screen_reset(bool level);
ScreenCommand screen_byte(bool is_data, std::uint8_t byte);  // ST7789 command (is_data false) or parameter

// Host side. Tracks the receiver's escape tracker so that what it sends is read as meant.
class UartFramer {
 public:
  // monitor_send.py's opening: 0x00, then the sync byte. Starts a new receiver session.
  void start(std::vector<std::uint8_t>& out);
  // A GPU command. An all-zero word the receiver would take as an escape is sent as the same
  // one-pixel background wall with light 1 (texture 0 forces light 15: it draws identically).
  void command(std::uint64_t word, std::vector<std::uint8_t>& out);
  void commands(std::span<const std::uint64_t> words, std::vector<std::uint8_t>& out);
  // Escape + screen word. Right after start() the tracker is not armed: a dropped span (rows 1..0,
  // no effect on the GPU) is sent first. The escape and screen words reach the GPU too (the SOC
  // pushes every word): the escape draws a background pixel at row 0.
  void screen(const ScreenCommand& c, std::vector<std::uint8_t>& out);
  bool started() const { return started_; }

  static constexpr std::uint64_t kNoOpWord = 0x400;  // a wall with start 1 > end 0: dropped by the GPU
  static constexpr std::uint64_t kZeroStandIn = 0x04000000;  // the zero word with light 1

 private:
  void word(std::uint64_t w, std::vector<std::uint8_t>& out);
  bool started_ = false;
  bool armed_ = false;  // the receiver's all_zeros tracker at the start of the next word
};

struct ReceiverStats {
  std::uint64_t bytes = 0;
  std::uint64_t ignored_before_sync = 0;
  std::uint64_t words = 0;            // pushed to the GPU FIFO (escapes and screen words included)
  std::uint64_t escapes = 0;
  std::uint64_t screen_commands = 0;
};

// The SOC's receive logic, byte by byte.
class SocReceiver {
 public:
  using WordSink = std::function<void(std::uint64_t)>;
  using ScreenSink = std::function<void(const ScreenCommand&)>;
  SocReceiver(WordSink gpu, ScreenSink screen) : gpu_(std::move(gpu)), screen_(std::move(screen)) {}

  void byte(std::uint8_t b);
  void bytes(std::span<const std::uint8_t> b) {
    for (const std::uint8_t x : b) byte(x);
  }
  // Back to power-on: waits for a sync byte again (the board's reset button).
  void reset();

  bool synced() const { return synced_; }
  // Bytes of the word being received (0..7): a stream cut mid-command leaves them waiting, and the
  // next bytes complete that word, misaligned.
  unsigned partial_bytes() const { return synced_ ? position_ : 0; }
  const ReceiverStats& stats() const { return stats_; }

 private:
  WordSink gpu_;
  ScreenSink screen_;
  bool synced_ = false;
  unsigned position_ = 0;       // bytes of the current word received
  bool all_zeros_ = true;       // the escape tracker (cleared by non-zero bytes, toggled per word)
  bool next_for_screen_ = false;
  std::uint64_t received_ = 0;  // shift register, MSB first
  ReceiverStats stats_;
};

// The wire: bytes sent 8N1 back to back at tx_baud, sampled by the SOC's receiver at rx_baud (it
// detects the start bit's falling edge on its clock, samples each bit in its middle, delivers the
// byte whatever the stop bit and then waits for the line to go high again).
struct LineStats {
  std::uint64_t bytes_received = 0;
  std::uint64_t framing_errors = 0;  // stop bit sampled low
  std::uint64_t false_starts = 0;    // start bit high again at its middle
};
std::vector<std::uint8_t> uart_transfer(std::span<const std::uint8_t> bytes, double tx_baud, double rx_baud,
                                        LineStats* stats = nullptr, double rx_clock_hz = kSocUartClockHz);

// Frames per second a link allows for frames of `words_per_frame` commands (8 bytes each, 10 bits
// per byte on the wire).
inline double uart_frames_per_second(double words_per_frame, double baud) {
  return words_per_frame > 0 ? baud / (kUartBitsPerByte * 8.0 * words_per_frame) : 0;
}

}  // namespace gpubridge::dmc1
