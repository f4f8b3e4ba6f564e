#pragma once
// SPI-slave model: the FPGA's SPI front end behind the SPI pins the bridge chip models drive
// (SpiPins). It assembles
// 72-bit frames per chip-select window (SPI mode 0, MSB first), shifts the status byte and read
// values out on MISO exactly as docs/protocol.md "SPI link" defines, and drives a SpiTarget.
// Wire-level faults (stuck MISO, bit flips, power cycle, marginal clock) are injected here.
#include <cstdint>
#include <functional>
#include <optional>

#include "gpubridge/backends/spi_target.hpp"
#include "gpubridge/usb/emu/spi_pins.hpp"

namespace gpubridge::usb::emu {

struct SpiFaults {
  std::optional<std::uint8_t> miso_stuck;      // MISO reads this byte value for every bit
  std::optional<std::uint64_t> flip_mosi_bit;  // global MOSI bit index (counted over all windows)
  std::optional<std::uint64_t> flip_miso_bit;  // global MISO bit index
  std::optional<std::uint64_t> power_cycle_at_frame;  // target reset when this many frames completed
  bool busy_stuck = false;                     // the BUSY pin never clears (flow control stuck)
  std::uint32_t max_reliable_hz = 0;           // above this SCK, every 61st MISO bit is wrong (0 = no limit)
};

class SpiSlave final : public SpiPins {
 public:
  // power_cycle: resets the target to its power-on state (called for the power-cycle fault).
  // idle_tick: lets device time pass while the bridge waits (executes queued commands).
  SpiSlave(backends::SpiTarget& target, std::function<void()> power_cycle, std::function<void()> idle_tick);

  void set_cs(bool asserted) override;
  bool cs_asserted() const override { return cs_; }
  bool shift_bit(bool mosi) override;
  std::uint8_t shift_byte(std::uint8_t mosi) override;
  bool busy_pin() const override;
  void idle_tick() override;
  void set_clock_hz(std::uint32_t hz) override { clock_hz_ = hz; }

  SpiFaults& faults() { return faults_; }
  std::uint64_t frames_completed() const { return frames_; }
  std::uint64_t frames_aborted() const { return aborted_; }

 private:
  backends::SpiTarget& target_;
  std::function<void()> power_cycle_, idle_tick_;
  SpiFaults faults_;
  bool cs_ = false;
  unsigned bit_in_frame_ = 0;  // 0..71
  std::uint8_t status_ = 0;
  std::uint8_t byte0_ = 0;
  std::uint64_t data_in_ = 0, data_out_ = 0;
  std::uint64_t mosi_bits_ = 0, miso_bits_ = 0, frames_ = 0, aborted_ = 0;
  std::uint32_t clock_hz_ = 0;
};

}  // namespace gpubridge::usb::emu
