#pragma once
// The FPGA's SPI pins as a bridge chip model drives them: the seam between the chip models and
// whatever sits behind the pins. SpiSlave (the C++ model of the gateware's SPI front end, driving
// a SpiTarget) implements it; the rtl backend implements it with the Verilated gateware. A chip
// model only ever talks to the pins through this interface.
#include <cstdint>

namespace gpubridge::usb::emu {

class SpiPins {
 public:
  virtual ~SpiPins() = default;
  // CS: asserted = the line driven low. Raising CS inside a 72-bit frame aborts that frame.
  virtual void set_cs(bool asserted) = 0;
  virtual bool cs_asserted() const = 0;
  // One SCK cycle in SPI mode 0: `mosi` is set up before the rising edge; returns MISO as sampled
  // on that edge. While CS is high MISO reads 1 (pulled up).
  virtual bool shift_bit(bool mosi) = 0;
  // Eight SCK cycles, MSB first; returns the eight MISO bits.
  virtual std::uint8_t shift_byte(std::uint8_t mosi) = 0;
  // The FPGA's BUSY output (command FIFO nearly full), for bridges that wait on it in hardware.
  virtual bool busy_pin() const = 0;
  // Device time passing while the bridge waits with SCK stopped (the FIFO drains, commands run).
  virtual void idle_tick() = 0;
  // The SCK frequency the bridge is set to (models of marginal links use it; it is not a clock).
  virtual void set_clock_hz(std::uint32_t hz) = 0;
};

}  // namespace gpubridge::usb::emu
