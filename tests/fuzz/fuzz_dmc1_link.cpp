// Fuzzes the DMC-1 UART link: arbitrary bytes into the standalone SOC's receiver model feeding the
// DMC-1, and the same bytes over the wire model at a baud rate picked by the first byte. Properties:
// no crash/UB; the receiver hands over one word per 8 bytes after the sync byte; the framer's
// output is read back as the commands it was given.
#include <cmath>
#include <memory>

#include "fuzz_check.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "gpubridge/dmc1/uart.hpp"

using namespace gpubridge::dmc1;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // One device for every input, back to its reset state each time (creating one costs more than a run).
  static const auto dev = [] {
    auto d = Device::create({}, *TextureMemory::from_image(std::vector<std::uint8_t>(4096, 7)), Palette{});
    FUZZ_CHECK(d.ok());
    return std::move(d).value();
  }();
  if (size == 0) return 0;
  const std::span<const std::uint8_t> bytes(data + 1, size - 1);
  dev->reset();
  std::size_t words = 0;
  SocReceiver rx([&](std::uint64_t w) { ++words; dev->submit(std::span(&w, 1)); }, [](const ScreenCommand&) {});
  rx.bytes(bytes);
  dev->flush();
  const std::uint64_t synced_bytes = rx.stats().bytes - rx.stats().ignored_before_sync - (rx.synced() ? 1 : 0);
  FUZZ_CHECK(words == synced_bytes / 8);
  FUZZ_CHECK(rx.partial_bytes() == synced_bytes % 8);

  // The wire at a mismatched rate never delivers more bytes than bit times allow: every byte the
  // receiver delivers starts at its own falling edge of the line, and the next one is looked for
  // only after its stop-bit sample, 9.5 receiver bit periods later.
  const double tx_baud = 1200.0 + 4800.0 * data[0];
  LineStats st;
  const auto wire = uart_transfer(bytes, tx_baud, kStandaloneBaud, &st);
  FUZZ_CHECK(st.bytes_received == wire.size());
  std::size_t falls = 0;
  bool high = true;  // idle line
  for (const std::uint8_t b : bytes)
    for (unsigned bit = 0; bit < kUartBitsPerByte; ++bit) {  // start, 8 data bits LSB first, stop
      const bool level = bit == 0 ? false : bit == 9 ? true : ((b >> (bit - 1)) & 1) != 0;
      falls += high && !level;
      high = level;
    }
  FUZZ_CHECK(wire.size() <= falls);
  const double line_ticks = static_cast<double>(bytes.size()) * kUartBitsPerByte * kSocUartClockHz / tx_baud;
  const double byte_ticks = 9.5 * std::round(kSocUartClockHz / kStandaloneBaud);
  FUZZ_CHECK(static_cast<double>(wire.size()) <= (line_ticks + 1) / byte_ticks + 1);

  // The bytes as commands: framed, they come back as the same words (zero words as stand-ins).
  std::vector<std::uint64_t> cmds;
  for (std::size_t i = 0; i + 8 <= bytes.size(); i += 8) {
    std::uint64_t w = 0;
    for (std::size_t b = 0; b < 8; ++b) w = w << 8 | bytes[i + b];
    cmds.push_back(w);
  }
  UartFramer f;
  std::vector<std::uint8_t> framed;
  f.commands(cmds, framed);
  std::vector<std::uint64_t> back;
  SocReceiver check([&](std::uint64_t w) { back.push_back(w); }, [](const ScreenCommand&) { FUZZ_CHECK(false); });
  check.bytes(framed);
  FUZZ_CHECK(back.size() == cmds.size());
  for (std::size_t i = 0; i < cmds.size(); ++i) FUZZ_CHECK(back[i] == cmds[i] || (cmds[i] == 0 && back[i] == UartFramer::kZeroStandIn));
  return 0;
}
