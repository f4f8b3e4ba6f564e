#pragma once
// SpiPins on the Verilated gateware (backends/rtl): every SCK period the bridge model clocks goes
// to the device's pins on its time axis; the wire faults of SpiFaults apply on the way, as they do
// for the frame-level SpiSlave. rtl_pins() is the PinsFactory for EmulationOptions::pins that puts
// the gateware the board profile names behind an emulated board (backend rtl:BOARD).
#include <cstdint>
#include <functional>
#include <memory>

#include "gpubridge/rtl/rtl_device.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "gpubridge/usb/emu/spi_pins.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"

namespace gpubridge::usb::emu {

class RtlPins final : public SpiPins {
 public:
  explicit RtlPins(std::unique_ptr<rtl::RtlDevice> device) : d_(std::move(device)) {}

  void set_cs(bool asserted) override;
  bool cs_asserted() const override { return cs_; }
  bool shift_bit(bool mosi) override;
  std::uint8_t shift_byte(std::uint8_t mosi) override;
  bool busy_pin() const override { return faults_.busy_stuck || d_->busy_pin(); }
  void idle_tick() override { d_->idle_ns(kTickNs); }
  void set_clock_hz(std::uint32_t hz) override { d_->set_sck_hz(hz); }
  SpiFaults& faults() { return faults_; }
  std::uint64_t frames_completed() const { return frames_; }

  rtl::RtlDevice& device() { return *d_; }
  // Another device on the same wires (e.g. the simulator behind the frame-level SpiSlave): it sees
  // every CS edge and MOSI bit the gateware sees, faults included. on_read(index, gateware value,
  // other value) is called for every complete read frame.
  using ReadCompare = std::function<void(std::uint8_t index, std::uint64_t gateware, std::uint64_t other)>;
  void set_shadow(SpiPins* shadow, ReadCompare on_read) {
    shadow_ = shadow;
    on_read_ = std::move(on_read);
  }
  // Device time per idle tick (a bridge waiting for the BUSY pin polls this often).
  static constexpr double kTickNs = 1000;

 private:
  std::unique_ptr<rtl::RtlDevice> d_;
  SpiFaults faults_;
  bool cs_ = false;
  unsigned bit_in_frame_ = 0;
  std::uint64_t mosi_bits_ = 0, miso_bits_ = 0, frames_ = 0;
  SpiPins* shadow_ = nullptr;
  ReadCompare on_read_;
  std::uint8_t header_ = 0;
  std::uint64_t gw_data_ = 0, shadow_data_ = 0;
};

// The gateware the profile's "gateware" section names, its SPI clock and MISO sampling edge taken
// from the profile's bridge wiring. Fails without Verilator in the build (RtlDevice::available()).
PinsFactory rtl_pins();
// The gateware pins behind a stack; nullptr unless it was built with rtl_pins().
RtlPins* rtl_pins_of(EmulatedStack& stack);

}  // namespace gpubridge::usb::emu
