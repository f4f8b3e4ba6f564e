// CH341A SPI driver (flashrom programmers/ch341a_spi.c is the reference for the stream format).
#include "gpubridge/usb/ch341a.hpp"

#include <algorithm>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/usb/usb_errors.hpp"

namespace gpubridge::usb {
namespace {

constexpr std::uint8_t kEpOut = 0x02, kEpIn = 0x82;
constexpr std::uint8_t kSpiStream = 0xA8, kI2cStream = 0xAA, kUioStream = 0xAB;
constexpr std::uint8_t kUioOut = 0x80, kUioDir = 0x40, kUioEnd = 0x20;
constexpr std::uint8_t kI2cSet = 0x60, kI2cEnd = 0x00;
constexpr std::uint8_t kPinsIdle = 0x37;   // CS (D0) high, SCK (D3) low, DOUT (D5) high
constexpr std::uint8_t kPinsSelect = 0x36; // CS low
constexpr std::size_t kPacketsPerRound = 8;  // echoed bytes read back after at most 8 data packets

}  // namespace

std::uint8_t reverse_bits(std::uint8_t b) {
  b = static_cast<std::uint8_t>((b & 0xF0) >> 4 | (b & 0x0F) << 4);
  b = static_cast<std::uint8_t>((b & 0xCC) >> 2 | (b & 0x33) << 2);
  return static_cast<std::uint8_t>((b & 0xAA) >> 1 | (b & 0x55) << 1);
}

Result<std::unique_ptr<Ch341aBridge>> Ch341aBridge::open(UsbDevice& dev, unsigned timeout_ms) {
  std::unique_ptr<Ch341aBridge> b(new Ch341aBridge(dev, timeout_ms));
  const UsbStatus d = dev.detach_kernel_driver(0);
  if (d != UsbStatus::Ok && d != UsbStatus::NotFound && d != UsbStatus::NotSupported)
    return usb_error(d, "CH341A: detach kernel driver");
  if (const UsbStatus c = dev.claim_interface(0); c != UsbStatus::Ok) return usb_error(c, "CH341A: claim interface 0");
  b->claimed_ = true;
  if (auto r = b->recover(); !r) return r.error();
  return b;
}

Ch341aBridge::~Ch341aBridge() {
  if (claimed_) (void)dev_.release_interface(0);
}

Result<void> Ch341aBridge::recover() {
  // SPI speed setting lives in the I2C stream config (bit 2 = "double" SPI), then pins on.
  const std::uint8_t cfg[] = {kI2cStream, static_cast<std::uint8_t>(kI2cSet | 0x01), kI2cEnd};
  if (auto r = out(cfg); !r) return r;
  const std::uint8_t pins[] = {kUioStream, static_cast<std::uint8_t>(kUioOut | kPinsIdle),
                               static_cast<std::uint8_t>(kUioDir | 0x3F), kUioEnd};
  return out(pins);
}

Result<void> Ch341aBridge::out(std::span<const std::uint8_t> bytes) {
  const UsbIo io = dev_.bulk_out(kEpOut, bytes, timeout_ms_);
  ++stats_.usb_out_transfers;
  stats_.usb_bytes_out += io.transferred;
  if (!io.ok()) return usb_error(io.status, "CH341A: bulk OUT (" + std::to_string(io.transferred) + " of " +
                                                std::to_string(bytes.size()) + " bytes)");
  return {};
}

Result<void> Ch341aBridge::in(std::span<std::uint8_t> bytes) {
  std::size_t got = 0;
  for (unsigned attempt = 0; got < bytes.size(); ++attempt) {
    if (attempt > 64)
      return make_error("CH341A: echoed SPI bytes did not arrive (" + std::to_string(got) + " of " +
                            std::to_string(bytes.size()) + ")",
                        backends::kDeviceTimeout);
    const UsbIo io = dev_.bulk_in(kEpIn, bytes.subspan(got), timeout_ms_);
    ++stats_.usb_in_transfers;
    ++stats_.round_trips;
    stats_.usb_bytes_in += io.transferred;
    if (io.transferred > bytes.size() - got)  // never trust a count beyond the buffer (found by fuzz_usb_bridges)
      return make_error("CH341A: bulk IN reported " + std::to_string(io.transferred) + " bytes for " +
                            std::to_string(bytes.size() - got) + " requested (USB transport fault)",
                        backends::kDeviceProtocol);
    got += io.transferred;
    if (!io.ok()) return usb_error(io.status, "CH341A: bulk IN (" + std::to_string(got) + " of " + std::to_string(bytes.size()) + " bytes)");
  }
  return {};
}

Result<std::vector<std::uint8_t>> Ch341aBridge::transfer(std::span<const SpiWindow> windows) {
  // An A8 command takes the rest of its 32-byte USB packet as SPI data, so only the last data
  // packet of a transfer may be short. Each window starts with a UIO packet that deasserts CS
  // (ending the previous window) and asserts it again; one standalone release ends the call.
  std::vector<std::uint8_t> miso, buf, echo;
  for (const auto& w : windows) {
    stats_.spi_bits += 8 * w.mosi.size();
    buf.assign(kCh341Packet, 0);
    const std::uint8_t cs[] = {kUioStream, kUioOut | kPinsIdle, kUioOut | kPinsIdle, kUioOut | kPinsSelect, kUioEnd};
    std::copy(std::begin(cs), std::end(cs), buf.begin());
    std::size_t off = 0;
    while (off < w.mosi.size() || !buf.empty()) {
      std::size_t payload = 0;
      for (std::size_t p = 0; p < kPacketsPerRound && off + payload < w.mosi.size(); ++p) {
        const std::size_t n = std::min<std::size_t>(kCh341Packet - 1, w.mosi.size() - off - payload);
        buf.push_back(kSpiStream);
        for (std::size_t i = 0; i < n; ++i) buf.push_back(reverse_bits(w.mosi[off + payload + i]));
        payload += n;
        if (n < kCh341Packet - 1) break;  // a short packet must end the transfer
      }
      if (auto r = out(buf); !r) return r.error();
      buf.clear();
      if (payload == 0) break;
      echo.resize(payload);
      if (auto r = in(echo); !r) return r.error();
      if (w.capture_miso)
        for (auto b : echo) miso.push_back(reverse_bits(b));
      off += payload;
    }
  }
  const std::uint8_t release[] = {kUioStream, kUioOut | kPinsIdle, kUioEnd};
  if (auto r = out(release); !r) return r.error();
  return miso;
}

}  // namespace gpubridge::usb
