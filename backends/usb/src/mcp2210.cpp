// MCP2210 SPI driver (datasheet DS22288A, commands 0x21, 0x40, 0x42).
#include "gpubridge/usb/mcp2210.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/usb/usb_errors.hpp"

namespace gpubridge::usb {
namespace {

std::string hex(unsigned v) { return fmt::format("0x{:02X}", v); }

constexpr std::uint8_t kCancelTransfer = 0x11, kSetChipSettings = 0x21, kSetSpiSettings = 0x40, kTransfer = 0x42;
constexpr std::uint8_t kOk = 0x00, kBusy = 0xF8, kExternalOwner = 0xF7;
constexpr std::uint8_t kEngineStarted = 0x20, kEngineMore = 0x30, kEngineDone = 0x10;
constexpr std::size_t kMaxChunk = 60;
constexpr std::size_t kMaxTransaction = 65535;
constexpr int kReadTimeoutMs = 1000;

}  // namespace

Result<std::unique_ptr<Mcp2210Bridge>> Mcp2210Bridge::open(HidDevice& dev, unsigned cs_pin, std::uint32_t clock_hz) {
  if (cs_pin > 8) return make_error("MCP2210 chip select must be GP0..GP8", backends::kBadRequest);
  std::unique_ptr<Mcp2210Bridge> b(new Mcp2210Bridge(dev, cs_pin, std::min<std::uint32_t>(clock_hz, 12'000'000)));
  if (auto r = b->recover(); !r) return r.error();
  return b;
}

Result<std::array<std::uint8_t, 64>> Mcp2210Bridge::command(std::span<const std::uint8_t> report) {
  std::array<std::uint8_t, 65> out{};  // report id 0 + 64-byte report
  std::copy(report.begin(), report.end(), out.begin() + 1);
  const int w = dev_.write(out);
  ++stats_.usb_out_transfers;
  if (w < 0)
    return make_error("MCP2210: HID write failed (" + dev_.last_error() + "); the adapter was unplugged?", backends::kDeviceGone);
  std::array<std::uint8_t, 64> in{};
  for (int attempt = 0;; ++attempt) {
    const int r = dev_.read(in, kReadTimeoutMs);
    ++stats_.usb_in_transfers;
    ++stats_.round_trips;
    if (r < 0) return make_error("MCP2210: HID read failed (" + dev_.last_error() + ")", backends::kDeviceGone);
    if (r > static_cast<int>(in.size()))  // never trust a count beyond the buffer (found by fuzz_usb_bridges)
      return make_error("MCP2210: HID read reported " + std::to_string(r) + " bytes for a 64-byte report (HID transport fault)",
                        backends::kDeviceProtocol);
    if (r > 0) break;
    if (attempt >= 2) return make_error("MCP2210: no response report within " + std::to_string(3 * kReadTimeoutMs) + " ms",
                                        backends::kDeviceTimeout);
  }
  if (in[0] != report[0])
    return make_error("MCP2210: response echoes command " + hex(in[0]) + " instead of " + hex(report[0]) +
                          " (report stream out of step)",
                      backends::kDeviceProtocol);
  return in;
}

Result<void> Mcp2210Bridge::recover() {
  std::array<std::uint8_t, 64> r{};
  r[0] = kCancelTransfer;  // ends a transaction a failed transfer left open
  if (auto s = command(std::span(r).first(1)); !s) return s.error();
  // Chip settings: our GP pin as chip select (designation 1), everything else GPIO input.
  r.fill(0);
  r[0] = kSetChipSettings;
  r[4 + cs_pin_] = 1;
  r[13] = 0xFF;  // GPIO default outputs high (CS idle high)
  r[14] = 0x01;
  r[15] = 0xFF;  // directions: inputs
  r[16] = 0x01;
  auto s = command(r);
  if (!s) return s.error();
  if ((*s)[1] != kOk) return make_error("MCP2210: chip settings rejected (status " + hex((*s)[1]) + ")", backends::kDeviceProtocol);
  configured_length_ = 0;
  return {};
}

Result<std::uint32_t> Mcp2210Bridge::set_clock(std::uint32_t hz) {
  clock_hz_ = std::clamp<std::uint32_t>(hz, 1500, 12'000'000);
  configured_length_ = 0;  // re-sent with the next transaction
  return clock_hz_;
}

Result<void> Mcp2210Bridge::set_transfer_settings(std::size_t length) {
  if (length == configured_length_) return {};
  std::array<std::uint8_t, 64> r{};
  r[0] = kSetSpiSettings;
  for (int i = 0; i < 4; ++i) r[4 + static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(clock_hz_ >> (8 * i));
  const std::uint16_t idle = 0x01FF, active = static_cast<std::uint16_t>(idle & ~(1u << cs_pin_));
  r[8] = idle & 0xFF;
  r[9] = idle >> 8;
  r[10] = active & 0xFF;
  r[11] = static_cast<std::uint8_t>(active >> 8);
  // Delays [12..17] stay 0; bytes per transaction; SPI mode 0.
  r[18] = static_cast<std::uint8_t>(length & 0xFF);
  r[19] = static_cast<std::uint8_t>(length >> 8);
  r[20] = 0;
  for (unsigned attempt = 0;; ++attempt) {
    auto s = command(r);
    if (!s) return s.error();
    if ((*s)[1] == kOk) break;
    if ((*s)[1] != kBusy || attempt >= kBusyRetries)
      return make_error("MCP2210: SPI transfer settings rejected (status " + hex((*s)[1]) + ")", backends::kDeviceProtocol);
  }
  configured_length_ = length;
  return {};
}

Result<void> Mcp2210Bridge::window(std::span<const std::uint8_t> mosi, std::vector<std::uint8_t>* miso) {
  if (auto r = set_transfer_settings(mosi.size()); !r) return r;
  std::size_t sent = 0, received = 0;
  unsigned busy = 0, rounds = 0;
  std::array<std::uint8_t, 64> rep{};
  while (true) {
    if (++rounds > 4 * (mosi.size() / kMaxChunk + 2) + kBusyRetries)
      return make_error("MCP2210: transfer did not finish (engine never reported done)", backends::kDeviceTimeout);
    const std::size_t n = std::min(kMaxChunk, mosi.size() - sent);
    rep.fill(0);
    rep[0] = kTransfer;
    rep[1] = static_cast<std::uint8_t>(n);
    std::copy_n(mosi.begin() + static_cast<std::ptrdiff_t>(sent), n, rep.begin() + 4);
    auto s = command(rep);
    if (!s) return s.error();
    const auto& a = *s;
    if (a[1] == kBusy) {
      if (++busy > kBusyRetries)
        return make_error("MCP2210: still busy (0xF8) after " + std::to_string(kBusyRetries) + " retries", backends::kDeviceTimeout);
      continue;  // the chunk was not accepted: send it again
    }
    if (a[1] == kExternalOwner)
      return make_error("MCP2210: SPI bus owned by an external master (0xF7); release the bus on the board", backends::kDeviceProtocol);
    if (a[1] != kOk) return make_error("MCP2210: transfer rejected with status " + hex(a[1]), backends::kDeviceProtocol);
    sent += n;
    const std::size_t count = a[2];
    if (count > kMaxChunk || received + count > mosi.size())
      return make_error("MCP2210: response claims " + std::to_string(count) + " bytes, more than were clocked", backends::kDeviceProtocol);
    if (miso) miso->insert(miso->end(), a.begin() + 4, a.begin() + 4 + static_cast<std::ptrdiff_t>(count));
    received += count;
    if (a[3] == kEngineDone) break;
    if (a[3] != kEngineStarted && a[3] != kEngineMore)
      return make_error("MCP2210: unknown engine status " + hex(a[3]), backends::kDeviceProtocol);
  }
  if (received != mosi.size())
    return make_error("MCP2210: transaction finished with " + std::to_string(received) + " of " + std::to_string(mosi.size()) +
                          " bytes",
                      backends::kDeviceProtocol);
  return {};
}

Result<std::vector<std::uint8_t>> Mcp2210Bridge::transfer(std::span<const SpiWindow> windows) {
  std::vector<std::uint8_t> miso;
  for (const auto& w : windows) {
    if (w.mosi.empty()) continue;
    if (w.mosi.size() > kMaxTransaction)
      return make_error("MCP2210: a chip-select window of " + std::to_string(w.mosi.size()) + " bytes exceeds 65535",
                        backends::kBadRequest);
    stats_.spi_bits += 8 * w.mosi.size();
    if (auto r = window(w.mosi, w.capture_miso ? &miso : nullptr); !r) return r.error();
  }
  return miso;
}

}  // namespace gpubridge::usb
