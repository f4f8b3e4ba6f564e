#pragma once
// FTDI FT232H / FT2232H / FT4232H (channels A/B) in MPSSE mode as an SpiBridge.
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>
#include <string>

#include "gpubridge/usb/spi_bridge.hpp"
#include "gpubridge/usb/usb_device.hpp"

namespace gpubridge::usb {

enum class ReadEdge : std::uint8_t { Rising, Falling };

struct FtdiConfig {
  int channel = 0;                 // 0 = A, 1 = B
  std::uint8_t cs_pin = 3;         // ADBUS bit of the chip select (3 = common adapters, 4 = iceprog wiring)
  bool busy_pin = false;           // FPGA BUSY wired to GPIOL1 (ADBUS5): use wait-on-I/O (0x89)
  ReadEdge read_edge = ReadEdge::Rising;  // 0x31 (rising) or 0x35 (falling) full-duplex sampling
  std::uint8_t latency_ms = 1;
  std::uint32_t clock_hz = 30'000'000;
  unsigned timeout_ms = 1000;
  // Reads larger than the RX FIFO go through one asynchronous stream (IN transfers queued while the
  // commands are sent) instead of one round trip per FIFO-full. Off = synchronous rounds only.
  bool stream_reads = true;
};

// FIFO sizes by chip (bcdDevice identifies the chip: 0x0900 FT232H, 0x0700 FT2232H, 0x0800 FT4232H).
std::size_t ftdi_fifo_bytes(std::uint16_t bcd_device);
std::string_view ftdi_chip_name(std::uint16_t bcd_device);

class FtdiMpsseBridge final : public SpiBridge {
 public:
  // Detaches the kernel driver, claims the interface, puts the channel into MPSSE mode, sets the
  // clock and checks command sync (AB → FA AB).
  static Result<std::unique_ptr<FtdiMpsseBridge>> open(UsbDevice& dev, FtdiConfig cfg);
  ~FtdiMpsseBridge() override;

  std::string_view chip() const override { return ftdi_chip_name(dev_.info().bcd_device); }
  Result<std::uint32_t> set_clock(std::uint32_t hz) override;
  std::uint32_t clock_hz() const override { return clock_hz_; }
  bool hardware_busy_wait() const override { return cfg_.busy_pin; }
  std::size_t preferred_batch_bytes() const override { return 32 * 1024; }
  Result<std::vector<std::uint8_t>> transfer(std::span<const SpiWindow> windows) override;
  Result<void> recover() override;
  const BridgeStats& stats() const override { return stats_; }

  // The MPSSE command bytes transfer() would send for these windows (for tests and benchmarks).
  std::vector<std::uint8_t> encode(std::span<const SpiWindow> windows) const;

 private:
  FtdiMpsseBridge(UsbDevice& dev, FtdiConfig cfg);
  Result<void> init();
  Result<void> control(std::uint8_t request, std::uint16_t value, const char* what);
  Result<void> write_all(std::span<const std::uint8_t> bytes);
  Result<void> read_exact(std::span<std::uint8_t> out);
  // Collects the payload of IN transfers into `out`, dropping each packet's two modem-status bytes.
  struct InCollector {
    std::span<std::uint8_t> out;
    std::size_t got = 0;
    unsigned empty_transfers = 0;
    std::chrono::steady_clock::time_point last_data;
  };
  // Ok(true) once `out` is full; errors on surplus bytes or when the chip sends nothing for too long.
  Result<bool> collect_in(InCollector& c, std::span<const std::uint8_t> transfer) const;
  // Sends the whole command stream and reads its `in_bytes` of MISO through UsbDevice::bulk_stream.
  // Ok(nullopt): the device has no asynchronous path (nothing was sent); use rounds instead.
  Result<std::optional<std::vector<std::uint8_t>>> stream_transfer(std::span<const std::uint8_t> cmd, std::size_t in_bytes);
  Result<void> sync_check();
  std::string where() const;

  UsbDevice& dev_;
  FtdiConfig cfg_;
  std::uint8_t ep_in_, ep_out_;
  std::uint16_t windex_;
  std::uint16_t packet_size_ = 512;
  std::size_t fifo_ = 1024;
  std::uint32_t clock_hz_ = 0;
  std::uint8_t idle_value_, direction_;
  bool claimed_ = false;
  bool stream_supported_ = true;  // until the device says NotSupported
  BridgeStats stats_;
};

}  // namespace gpubridge::usb
