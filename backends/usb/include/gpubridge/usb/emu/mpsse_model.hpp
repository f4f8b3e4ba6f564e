#pragma once
// Byte-exact model of an FTDI H-series chip in MPSSE mode behind the UsbDevice seam: the vendor
// control requests, the MPSSE command interpreter (every opcode a driver may send, FA xx for bad
// ones), GPIO and chip select, 2 modem-status bytes per wMaxPacketSize IN packet, status-only
// packets when nothing is pending, wait-on-I/O, chip FIFO sizes and the 65,536-byte limit.
// Anything a real chip would reject or a driver should never do is recorded as a violation.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "gpubridge/usb/emu/chip_model.hpp"

namespace gpubridge::usb::emu {

enum class FtdiChip : std::uint8_t { FT232H, FT2232H, FT4232H };

struct MpsseModelConfig {
  FtdiChip chip = FtdiChip::FT232H;
  bool high_speed = true;         // wMaxPacketSize 512 (else 64: behind a full-speed hub)
  std::string serial = "EMU00001";
  std::string port_path = "1-1";
  std::uint8_t cs_pin = 3;        // ADBUS bit wired to the FPGA's CS
  bool busy_wired = true;         // FPGA BUSY on GPIOL1 (ADBUS5)
  unsigned max_wait_ticks = 100000;  // device time a wait-on-I/O may take before the MPSSE stalls
};

// Two channels, each its own interface with ftdi_sio bound until detached: claim and release are
// this model's own, not UsbChipModel's single-interface ones.
class MpsseModel final : public ChipModel, public UsbDevice {
 public:
  // pins: the SPI device on channel A (channel B has nothing attached).
  MpsseModel(MpsseModelConfig cfg, SpiPins* pins);
  UsbDevice* usb() override { return this; }

  const UsbDeviceInfo& info() const override { return info_; }
  UsbStatus detach_kernel_driver(int interface) override;
  UsbStatus claim_interface(int interface) override;
  UsbStatus release_interface(int interface) override;
  UsbIo control_out(std::uint8_t request_type, std::uint8_t request, std::uint16_t value, std::uint16_t index,
                    std::span<const std::uint8_t> data, unsigned timeout_ms) override;
  UsbIo control_in(std::uint8_t request_type, std::uint8_t request, std::uint16_t value, std::uint16_t index,
                   std::span<std::uint8_t> data, unsigned timeout_ms) override;
  UsbIo bulk_out(std::uint8_t endpoint, std::span<const std::uint8_t> data, unsigned timeout_ms) override;
  UsbIo bulk_in(std::uint8_t endpoint, std::span<std::uint8_t> data, unsigned timeout_ms) override;
  UsbStatus clear_halt(std::uint8_t endpoint) override;
  std::uint16_t max_packet_size(std::uint8_t endpoint) const override;
  BulkStreamResult bulk_stream(const BulkStream& s, const InSink& on_in) override;

  std::uint32_t sck_hz() const;
  std::size_t tx_fifo_bytes() const;
  std::size_t rx_fifo_bytes() const { return tx_fifo_bytes(); }
  // Every OUT payload, for byte-exact stream tests.
  const std::vector<std::vector<std::uint8_t>>& out_log() const { return out_log_; }
  void clear_out_log() { out_log_.clear(); }

 private:
  struct Channel {
    bool claimed = false, kernel_driver = true, mpsse = false;
    std::uint8_t latency = 16;
    std::uint8_t low_value = 0, low_dir = 0, high_value = 0, high_dir = 0;
    std::uint16_t divisor = 0;
    bool div5 = true, loopback = false, three_phase = false, adaptive = false;
    std::vector<std::uint8_t> pending;  // OUT bytes not yet interpreted (partial command or stalled)
    std::deque<std::uint8_t> in;        // bytes waiting for the host
  };
  int channel_of_endpoint(std::uint8_t ep, bool in) const;
  Channel* channel_of_index(std::uint16_t windex);
  // Moves waiting IN bytes into `data` as packets, each led by the two modem-status bytes, up to
  // `limit` bytes and ending at a short packet; nullopt when not even one packet fits (babble).
  std::optional<std::size_t> pack_in(Channel& c, std::span<std::uint8_t> data, std::size_t limit);
  void run(int ch);                          // interprets as much of `pending` as possible
  std::size_t execute(int ch, std::span<const std::uint8_t> cmd, bool& stalled);  // bytes consumed (0 = need more)
  void update_cs(Channel& c);
  std::uint8_t shift(Channel& c, std::uint8_t mosi, bool write, unsigned bits);

  MpsseModelConfig cfg_;
  UsbDeviceInfo info_;
  Channel ch_[2];
  std::vector<std::vector<std::uint8_t>> out_log_;
};

}  // namespace gpubridge::usb::emu
