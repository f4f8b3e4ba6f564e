#pragma once
// A minimal SPI master on the gateware's pins (no bridge chip): frames in bursts under one CS,
// register reads that return the MISO data of the same frame, and the link CRC of what it sent.
// Used by the SoC-level tests; the bridge path (chip models and drivers) has its own tests.
#include <cstdint>
#include <span>
#include <vector>

#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "gpubridge/rtl/rtl_device.hpp"

namespace gpubridge::test {

struct PinFrameResult {
  std::uint8_t status = 0;  // MISO bits [71:64]
  std::uint64_t data = 0;   // MISO bits [63:0]
};

class PinHost {
 public:
  explicit PinHost(rtl::RtlDevice& d) : d_(d) {}

  // One burst: every frame under one CS assertion. Returns what MISO carried per frame.
  std::vector<PinFrameResult> burst(std::span<const protocol::Frame> frames) {
    std::vector<PinFrameResult> out;
    d_.set_cs(true);
    for (const auto& f : frames) {
      std::uint8_t bytes[9];
      bytes[0] = static_cast<std::uint8_t>((f.read ? 0x80 : 0) | f.index);
      for (int i = 0; i < 8; ++i) bytes[1 + i] = static_cast<std::uint8_t>(f.data >> (56 - 8 * i));
      PinFrameResult r;
      r.status = d_.shift_byte(bytes[0]);
      for (int i = 0; i < 8; ++i) r.data = (r.data << 8) | d_.shift_byte(bytes[1 + i]);
      if (f.index != 0x13 && f.index != 0x14) crc_ = protocol::crc32_update(crc_, std::span<const std::uint8_t>(bytes, 9));
      out.push_back(r);
    }
    d_.set_cs(false);
    return out;
  }
  void write(std::uint8_t index, std::uint64_t data) {
    const protocol::Frame f{false, index, data};
    burst(std::span(&f, 1));
  }
  std::uint64_t read(std::uint8_t index) {
    const protocol::Frame f{true, index, 0};
    return burst(std::span(&f, 1))[0].data;
  }
  std::uint64_t read(protocol::Reg r) { return read(protocol::index_of(r)); }
  void write(protocol::Reg r, std::uint64_t v) { write(protocol::index_of(r), v); }
  // Sends LINK_CHECK with the CRC of the frames since the last check and restarts the host CRC.
  void link_check(bool corrupt = false) {
    const std::uint32_t crc = crc_ ^ (corrupt ? 1u : 0u);
    crc_ = 0;
    write(protocol::Reg::LINK_CHECK, crc);
  }
  void restart_crc() { crc_ = 0; }
  // The CRC of the frames sent since the last restart (what LINK_CHECK carries); restarts it.
  std::uint32_t take_crc() {
    const std::uint32_t c = crc_;
    crc_ = 0;
    return c;
  }
  // Counts a frame into the host CRC without sending it (the host believes it sent this frame).
  void account(const protocol::Frame& f) {
    std::uint8_t bytes[9];
    bytes[0] = static_cast<std::uint8_t>((f.read ? 0x80 : 0) | f.index);
    for (int i = 0; i < 8; ++i) bytes[1 + i] = static_cast<std::uint8_t>(f.data >> (56 - 8 * i));
    crc_ = protocol::crc32_update(crc_, std::span<const std::uint8_t>(bytes, 9));
  }
  // Polls STATUS until nothing is queued, executing, held, or waiting for a swap. `polls` counts
  // the STATUS reads sent (frames on the link).
  std::uint64_t wait_idle(unsigned& polls, unsigned max_polls = 100000) {
    std::uint64_t s = 0;
    for (polls = 1; polls <= max_polls; ++polls) {
      s = read(protocol::Reg::STATUS);
      if ((s & ((1ull << 16) | (1ull << 19) | (1ull << 20) | 0xFFFF)) == 0) return s;
      d_.idle_ns(2000);
    }
    return s;
  }

 private:
  rtl::RtlDevice& d_;
  std::uint32_t crc_ = 0;
};

}  // namespace gpubridge::test
