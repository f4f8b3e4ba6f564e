#pragma once
// A small reference implementation of the device side of the SPI link (docs/protocol.md "SPI
// link"): register file, command FIFO with a configurable drain rate, strict link mode, HOST_TAG,
// RESET, MEM_ADDR/MEM_DATA over VRAM, FB_DISPLAY → FRAME_CRC, CLEAR. It does not rasterize: it
// exists so the bridge models and the board backend can be tested (and boards emulated) with a
// device whose link behaviour is simple to read. Emulated boards use the simulator when built.
#include <cstdint>
#include <deque>
#include <vector>

#include "gpubridge/backends/spi_target.hpp"

namespace gpubridge::usb::emu {

struct ReferenceTargetConfig {
  std::uint32_t vram_kib = 256;
  unsigned fifo_depth = 128;
  unsigned max_width = 640, max_height = 480;
  std::uint16_t variant = 0x00F0;  // ID.VARIANT of the reference target
  unsigned drain_per_frame = 0;    // queued commands executed per received frame (0 = all at once)
};

class ReferenceTarget final : public backends::SpiTarget {
 public:
  explicit ReferenceTarget(ReferenceTargetConfig cfg);

  std::uint8_t miso_status() override;
  std::uint64_t read_register(std::uint8_t index) override;
  void frame_complete(const protocol::Frame& frame) override;
  void frame_aborted() override;
  bool busy_pin() const override;

  void power_cycle();  // everything to power-on state, VRAM cleared
  void tick();         // device time passes: executes one queued command
  void set_drain_per_frame(unsigned n) { cfg_.drain_per_frame = n; }

  // Inspection for tests.
  std::uint64_t reg(std::uint8_t index) const { return regs_[index]; }
  std::uint16_t errors() const { return errors_; }
  const std::vector<std::uint8_t>& vram() const { return vram_; }
  std::uint64_t executed() const { return executed_; }

 private:
  struct Queued {
    std::uint8_t index;
    std::uint64_t data;
  };
  void soft_reset();
  void write_immediate(std::uint8_t index, std::uint64_t data);
  void enqueue(std::uint8_t index, std::uint64_t data);
  void execute(const Queued& q);
  void drain(unsigned n);
  void latch_display();
  void clear_rect(std::uint32_t base, std::uint64_t value, unsigned bytes);
  std::size_t free_entries() const;
  std::uint64_t status_value() const;

  ReferenceTargetConfig cfg_;
  std::vector<std::uint8_t> vram_;
  std::uint64_t regs_[128] = {};
  std::deque<Queued> fifo_, held_;
  std::uint16_t errors_ = 0;
  bool strict_ = false, discarding_ = false, group_tainted_ = false;
  std::uint32_t link_crc_ = 0, link_frames_ = 0;
  std::uint16_t groups_ok_ = 0, groups_bad_ = 0;
  std::uint32_t mem_addr_ = 0;
  bool mem_ready_ = false;
  std::uint16_t frame_count_ = 0;
  std::uint64_t host_tag_ = 0, frame_crc_ = 0, executed_ = 0;
};

}  // namespace gpubridge::usb::emu
