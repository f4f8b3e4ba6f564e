// Fuzzes board profiles: parse_board_profile and parse_uart_board_profile on the input as the text
// of a profile file. A UART board (a DMC-1 on a USB-UART) has a device kind other than spigpu, a
// baud rate in range and an interface A..D; no text is accepted by both parsers.
// Properties: a refusal is an error naming the file, with the BackendError code for a bad request;
// an accepted profile holds only what its chip can do (clock within the chip's maximum, a chip
// select the chip has, channel B only on dual-channel FTDI parts, device sizes in range).
#include <string_view>

#include "fuzz_check.hpp"
#include "gpubridge/backends/backend.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "gpubridge/usb/board_profile.hpp"

using namespace gpubridge;
using usb::BridgeChip;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  auto u = usb::parse_uart_board_profile(text, "fuzz.json");
  if (!u) {
    FUZZ_CHECK(u.error().message.rfind("fuzz.json: ", 0) == 0);
    FUZZ_CHECK(u.error().code == backends::kBadRequest);
  } else {
    FUZZ_CHECK(u->device_kind != protocol::DeviceKind::Spigpu);
    FUZZ_CHECK(u->baud >= 300 && u->baud <= 4'000'000);
    FUZZ_CHECK(u->interface >= 0 && u->interface <= 3);
    FUZZ_CHECK(!u->name.empty());
  }
  auto p = usb::parse_board_profile(text, "fuzz.json");
  FUZZ_CHECK(!(p && u));
  if (!p) {
    FUZZ_CHECK(p.error().message.rfind("fuzz.json: ", 0) == 0);
    FUZZ_CHECK(p.error().code == backends::kBadRequest);
    return 0;
  }
  const bool ftdi = p->chip == BridgeChip::FT232H || p->chip == BridgeChip::FT2232H || p->chip == BridgeChip::FT4232H;
  FUZZ_CHECK(!p->name.empty());
  FUZZ_CHECK(p->name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789-_") == std::string::npos);
  FUZZ_CHECK(usb::parse_bridge_chip(usb::to_string(p->chip)) == p->chip);
  FUZZ_CHECK(p->spi_clock_hz >= 1000 && p->spi_clock_hz <= (ftdi ? 30'000'000u : p->chip == BridgeChip::CH341A ? 1'700'000u : 12'000'000u));
  FUZZ_CHECK(p->interface == 0 || (p->interface == 1 && (p->chip == BridgeChip::FT2232H || p->chip == BridgeChip::FT4232H)));
  FUZZ_CHECK(p->cs_pin <= 10);
  if (ftdi) FUZZ_CHECK(p->cs_pin >= 3 && p->cs_pin <= 7 && !(p->busy_pin && p->cs_pin == 5));
  FUZZ_CHECK(!p->busy_pin || ftdi);
  FUZZ_CHECK(p->latency_ms >= 1);
  FUZZ_CHECK(p->vram_kib >= 1 && p->vram_kib <= 0xFFFFFF);
  FUZZ_CHECK(p->max_width >= 1 && p->max_width <= protocol::kMaxFramebufferDim);
  FUZZ_CHECK(p->max_height >= 1 && p->max_height <= protocol::kMaxFramebufferDim);
  FUZZ_CHECK(p->fifo_depth >= 33 && p->fifo_depth <= 1023);
  return 0;
}
