#pragma once
// One interface for every USB-SPI bridge chip (openFPGALoader's cable pattern): the board
// backend describes chip-select windows, the chip driver turns them into its own USB traffic.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "gpubridge/common/result.hpp"

namespace gpubridge::usb {

// One chip-select window: CS falls, `mosi` is shifted out MSB first in SPI mode 0, CS rises.
struct SpiWindow {
  std::span<const std::uint8_t> mosi;
  bool capture_miso = false;           // return the MISO bytes clocked during this window
  std::vector<std::size_t> busy_waits; // byte offsets before which the bridge waits for BUSY low
                                       // (only honoured when hardware_busy_wait() is true)
};

// Counters for benchmarks and tests (never used for decisions).
struct BridgeStats {
  std::uint64_t usb_out_transfers = 0, usb_in_transfers = 0, control_transfers = 0;
  std::uint64_t usb_bytes_out = 0, usb_bytes_in = 0;
  std::uint64_t spi_bits = 0;  // SCK cycles generated
  std::uint64_t busy_waits = 0;
  // Times the host waited for the device before it could go on: every synchronous IN transfer,
  // one per streamed read (FTDI with an asynchronous IN queue). What the USB latency multiplies.
  std::uint64_t round_trips = 0;
  std::uint64_t streamed_reads = 0;  // transfers whose reads went through UsbDevice::bulk_stream
};

class SpiBridge {
 public:
  virtual ~SpiBridge() = default;
  virtual std::string_view chip() const = 0;
  // Requests an SCK frequency; returns the frequency the chip will really use (≤ requested).
  virtual Result<std::uint32_t> set_clock(std::uint32_t hz) = 0;
  virtual std::uint32_t clock_hz() const = 0;
  // True when the bridge can stall on the BUSY pin itself (FTDI wait-on-I/O), so flow control
  // costs no USB round trip.
  virtual bool hardware_busy_wait() const = 0;
  // Largest MOSI byte count the board backend should put into one transfer() call.
  virtual std::size_t preferred_batch_bytes() const = 0;
  // Runs the windows in order. Returns the MISO bytes of every capture_miso window, concatenated.
  // Errors carry BackendError codes (kDeviceGone, kDeviceTimeout, kDeviceProtocol).
  virtual Result<std::vector<std::uint8_t>> transfer(std::span<const SpiWindow> windows) = 0;
  // After a failed transfer: bring the bridge back to a known state (CS high, FIFOs purged).
  virtual Result<void> recover() = 0;
  virtual const BridgeStats& stats() const = 0;
};

}  // namespace gpubridge::usb
