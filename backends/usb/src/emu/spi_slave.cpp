#include "gpubridge/usb/emu/spi_slave.hpp"

#include <utility>

namespace gpubridge::usb::emu {

SpiSlave::SpiSlave(backends::SpiTarget& target, std::function<void()> power_cycle, std::function<void()> idle_tick)
    : target_(target), power_cycle_(std::move(power_cycle)), idle_tick_(std::move(idle_tick)) {}

void SpiSlave::set_cs(bool asserted) {
  if (cs_ && !asserted && bit_in_frame_ != 0) {
    // CS rose inside a frame: the gateware drops the partial frame.
    target_.frame_aborted();
    ++aborted_;
  }
  cs_ = asserted;
  bit_in_frame_ = 0;
}

bool SpiSlave::shift_bit(bool mosi) {
  if (!cs_) return true;  // MISO is tri-stated and pulled up while CS is high
  if (faults_.flip_mosi_bit && *faults_.flip_mosi_bit == mosi_bits_) mosi = !mosi;
  ++mosi_bits_;

  if (bit_in_frame_ == 0) status_ = target_.miso_status();
  bool miso;
  if (bit_in_frame_ < 8) {
    miso = (status_ >> (7 - bit_in_frame_)) & 1u;
    byte0_ = static_cast<std::uint8_t>((byte0_ << 1) | (mosi ? 1 : 0));
  } else {
    miso = (data_out_ >> (63 - (bit_in_frame_ - 8))) & 1u;
    data_in_ = (data_in_ << 1) | (mosi ? 1 : 0);
  }
  ++bit_in_frame_;
  if (bit_in_frame_ == 8) {
    // Bit 64 has arrived: R/W̄ and the index are known, a read value is captured now.
    data_out_ = (byte0_ & 0x80) ? target_.read_register(byte0_ & 0x7F) : 0;
  } else if (bit_in_frame_ == 72) {
    protocol::Frame f{(byte0_ & 0x80) != 0, static_cast<std::uint8_t>(byte0_ & 0x7F), data_in_};
    target_.frame_complete(f);
    ++frames_;
    bit_in_frame_ = 0;
    data_in_ = 0;
    byte0_ = 0;
    if (faults_.power_cycle_at_frame && *faults_.power_cycle_at_frame == frames_ && power_cycle_) power_cycle_();
  }

  if (faults_.miso_stuck) miso = (*faults_.miso_stuck & 1u) != 0;
  if (faults_.flip_miso_bit && *faults_.flip_miso_bit == miso_bits_) miso = !miso;
  if (faults_.max_reliable_hz && clock_hz_ > faults_.max_reliable_hz && miso_bits_ % 61 == 60) miso = !miso;
  ++miso_bits_;
  return miso;
}

std::uint8_t SpiSlave::shift_byte(std::uint8_t mosi) {
  std::uint8_t out = 0;
  for (int b = 7; b >= 0; --b) out = static_cast<std::uint8_t>((out << 1) | (shift_bit((mosi >> b) & 1u) ? 1 : 0));
  return out;
}

bool SpiSlave::busy_pin() const { return faults_.busy_stuck || target_.busy_pin(); }

void SpiSlave::idle_tick() {
  if (idle_tick_) idle_tick_();
}

}  // namespace gpubridge::usb::emu
