#pragma once
// The device side of the SPI link: what an FPGA running spigpu does with the frames it receives.
// The simulator's device model implements it; the SPI-slave model behind the emulated USB
// bridges assembles 72-bit frames per chip-select window and calls it, exactly as the gateware's
// SPI front end would (docs/protocol.md, "SPI link").
#include <cstdint>

#include "gpubridge/protocol/frame.hpp"

namespace gpubridge::backends {

class SpiTarget {
 public:
  virtual ~SpiTarget() = default;
  // The status byte shifted out on MISO during bits [71:64] of the frame that is starting.
  virtual std::uint8_t miso_status() = 0;
  // Called when bit 64 of a read frame has been received (R/W̄ = 1 and the index are known);
  // returns the 64 bits shifted out during bits [63:0] of the same frame.
  virtual std::uint64_t read_register(std::uint8_t index) = 0;
  // Every complete frame, read or write, in arrival order: executes (or queues) writes and feeds
  // the link CRC.
  virtual void frame_complete(const protocol::Frame& frame) = 0;
  // Chip select rose after 1..71 bits: the partial frame is discarded (ERR_FRAMING).
  virtual void frame_aborted() = 0;
  // Level of the optional BUSY output pin (1 = FIFO nearly full).
  virtual bool busy_pin() const = 0;
};

}  // namespace gpubridge::backends
