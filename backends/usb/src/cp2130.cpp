// CP2130 SPI driver (AN792; bloguetronica/cp2130-conf for request layouts).
#include "gpubridge/usb/cp2130.hpp"

#include <algorithm>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/usb/usb_errors.hpp"

namespace gpubridge::usb {
namespace {

constexpr std::uint8_t kEpOut = 0x01, kEpIn = 0x82;  // high-priority write (default)
constexpr std::uint8_t kSetGpioChipSelect = 0x25, kSetSpiWord = 0x31;
constexpr std::uint8_t kCmdWrite = 0x01, kCmdWriteRead = 0x02;
constexpr unsigned kControlTimeoutMs = 500, kBulkTimeoutMs = 1000;

void header(std::vector<std::uint8_t>& out, std::uint8_t cmd, std::size_t len) {
  out.insert(out.end(), {0x00, 0x00, cmd, 0x00, static_cast<std::uint8_t>(len), static_cast<std::uint8_t>(len >> 8),
                         static_cast<std::uint8_t>(len >> 16), static_cast<std::uint8_t>(len >> 24)});
}

}  // namespace

Result<std::unique_ptr<Cp2130Bridge>> Cp2130Bridge::open(UsbDevice& dev, unsigned cs, std::uint32_t hz) {
  if (cs > 10) return make_error("CP2130 chip select channel must be 0..10", backends::kBadRequest);
  std::unique_ptr<Cp2130Bridge> b(new Cp2130Bridge(dev, cs, hz));
  const UsbStatus d = dev.detach_kernel_driver(0);
  if (d != UsbStatus::Ok && d != UsbStatus::NotFound && d != UsbStatus::NotSupported)
    return usb_error(d, "CP2130: detach kernel driver");
  if (const UsbStatus c = dev.claim_interface(0); c != UsbStatus::Ok) return usb_error(c, "CP2130: claim interface 0");
  b->claimed_ = true;
  if (auto r = b->recover(); !r) return r.error();
  return b;
}

Cp2130Bridge::~Cp2130Bridge() {
  if (claimed_) (void)dev_.release_interface(0);
}

Result<void> Cp2130Bridge::control(std::uint8_t request, std::span<const std::uint8_t> data, const char* what) {
  ++stats_.control_transfers;
  const UsbIo io = dev_.control_out(kRequestTypeVendorOut, request, 0, 0, data, kControlTimeoutMs);
  if (!io.ok()) return usb_error(io.status, std::string("CP2130: ") + what);
  return {};
}

Result<std::uint32_t> Cp2130Bridge::set_clock(std::uint32_t hz) {
  // freq index 0..7 = 12, 6, 3, 1.5, 0.75, 0.375, 0.1875, 0.09375 MHz: the fastest ≤ hz.
  unsigned idx = 0;
  std::uint32_t f = 12'000'000;
  while (idx < 7 && f > hz) {
    ++idx;
    f /= 2;
  }
  // cpha = 0, cpol = 0 (mode 0), push-pull output (bit 3).
  const std::uint8_t word[] = {static_cast<std::uint8_t>(cs_), static_cast<std::uint8_t>(0x08 | idx)};
  if (auto r = control(kSetSpiWord, word, "set SPI word"); !r) return r.error();
  clock_hz_ = f;
  return f;
}

Result<void> Cp2130Bridge::recover() {
  if (auto r = set_clock(clock_hz_); !r) return r.error();
  const std::uint8_t select[] = {static_cast<std::uint8_t>(cs_), 0x02};  // enable only this CS
  return control(kSetGpioChipSelect, select, "set chip select");
}

Result<void> Cp2130Bridge::out(std::span<const std::uint8_t> bytes) {
  const UsbIo io = dev_.bulk_out(kEpOut, bytes, kBulkTimeoutMs);
  ++stats_.usb_out_transfers;
  stats_.usb_bytes_out += io.transferred;
  if (!io.ok()) return usb_error(io.status, "CP2130: bulk OUT (" + std::to_string(io.transferred) + " of " +
                                                std::to_string(bytes.size()) + " bytes)");
  return {};
}

Result<void> Cp2130Bridge::in(std::span<std::uint8_t> bytes) {
  std::size_t got = 0;
  for (unsigned attempt = 0; got < bytes.size(); ++attempt) {
    if (attempt > 16) return make_error("CP2130: read data did not arrive", backends::kDeviceTimeout);
    std::uint8_t packet[64];
    const UsbIo io = dev_.bulk_in(kEpIn, packet, kBulkTimeoutMs);
    ++stats_.usb_in_transfers;
    ++stats_.round_trips;
    stats_.usb_bytes_in += io.transferred;
    if (!io.ok()) return usb_error(io.status, "CP2130: bulk IN");
    if (got + io.transferred > bytes.size())
      return make_error("CP2130: chip returned more bytes than the WriteRead asked for", backends::kDeviceProtocol);
    std::copy_n(packet, io.transferred, bytes.begin() + static_cast<std::ptrdiff_t>(got));
    got += io.transferred;
  }
  return {};
}

Result<std::vector<std::uint8_t>> Cp2130Bridge::transfer(std::span<const SpiWindow> windows) {
  std::vector<std::uint8_t> miso, buf;
  for (const auto& w : windows) {
    stats_.spi_bits += 8 * w.mosi.size();
    if (!w.capture_miso) {
      // A Write command may span many packets: CS stays asserted for the whole command.
      buf.clear();
      header(buf, kCmdWrite, w.mosi.size());
      buf.insert(buf.end(), w.mosi.begin(), w.mosi.end());
      if (auto r = out(buf); !r) return r.error();
      continue;
    }
    for (std::size_t off = 0; off < w.mosi.size(); off += kWriteReadChunk) {
      const std::size_t n = std::min(kWriteReadChunk, w.mosi.size() - off);
      buf.clear();
      header(buf, kCmdWriteRead, n);
      buf.insert(buf.end(), w.mosi.begin() + static_cast<std::ptrdiff_t>(off), w.mosi.begin() + static_cast<std::ptrdiff_t>(off + n));
      if (auto r = out(buf); !r) return r.error();
      const std::size_t at = miso.size();
      miso.resize(at + n);
      if (auto r = in(std::span(miso).subspan(at)); !r) return r.error();
    }
  }
  return miso;
}

}  // namespace gpubridge::usb
