#include "gpubridge/usb/emu/rtl_pins.hpp"


namespace gpubridge::usb::emu {

void RtlPins::set_cs(bool asserted) {
  if (asserted == cs_) return;
  cs_ = asserted;
  bit_in_frame_ = 0;
  d_->set_cs(asserted);
  if (shadow_) shadow_->set_cs(asserted);
}

bool RtlPins::shift_bit(bool mosi) {
  if (!cs_) {
    d_->shift_bit(mosi);  // SCK toggles; the deselected device ignores it
    return true;          // MISO tri-stated, pulled up
  }
  if (faults_.flip_mosi_bit && *faults_.flip_mosi_bit == mosi_bits_) mosi = !mosi;
  ++mosi_bits_;
  bool miso = d_->shift_bit(mosi);
  if (shadow_) {
    const bool other = shadow_->shift_bit(mosi);
    if (bit_in_frame_ < 8) {
      header_ = static_cast<std::uint8_t>(header_ << 1 | (mosi ? 1 : 0));
    } else {
      gw_data_ = gw_data_ << 1 | (miso ? 1 : 0);
      shadow_data_ = shadow_data_ << 1 | (other ? 1 : 0);
    }
  }
  if (++bit_in_frame_ == 72) {
    bit_in_frame_ = 0;
    ++frames_;
    if (shadow_ && (header_ & 0x80) && on_read_) on_read_(header_ & 0x7F, gw_data_, shadow_data_);
    if (faults_.power_cycle_at_frame && *faults_.power_cycle_at_frame == frames_) d_->power_cycle();
  }
  // max_reliable_hz is not modelled here: the gateware's own MISO timing decides what arrives.
  if (faults_.miso_stuck) miso = (*faults_.miso_stuck & 1u) != 0;
  if (faults_.flip_miso_bit && *faults_.flip_miso_bit == miso_bits_) miso = !miso;
  ++miso_bits_;
  return miso;
}

std::uint8_t RtlPins::shift_byte(std::uint8_t mosi) {
  std::uint8_t out = 0;
  for (int b = 7; b >= 0; --b) out = static_cast<std::uint8_t>((out << 1) | (shift_bit((mosi >> b) & 1u) ? 1 : 0));
  return out;
}

PinsFactory rtl_pins() {
  return [](const BoardProfile& profile) -> Result<std::unique_ptr<SpiPins>> {
    if (!rtl::RtlDevice::available()) return make_error(rtl::RtlDevice::unavailable_reason());
    const auto gp = rtl::parse_gateware_profile(profile.gateware);
    if (!gp)
      return make_error("board profile '" + profile.name + "' names no gateware (add \"gateware\": {\"profile\": \"up5k\"} or " +
                        "\"ecp5\" to " + profile.file.string() + ")");
    rtl::PinTiming t;
    t.sck_hz = profile.spi_clock_hz;
    // FTDI MPSSE samples on the profile's read edge; the other bridges sample on the rising edge
    const bool ftdi = profile.chip == BridgeChip::FT232H || profile.chip == BridgeChip::FT2232H ||
                      profile.chip == BridgeChip::FT4232H;
    t.sample_falling = ftdi && profile.read_edge == ReadEdge::Falling;
    t.miso_delay_ns = profile.miso_delay_ns;
    auto d = rtl::RtlDevice::create(*gp, t);
    if (!d) return d.error();
    return std::unique_ptr<SpiPins>(std::make_unique<RtlPins>(std::move(*d)));
  };
}

RtlPins* rtl_pins_of(EmulatedStack& stack) { return dynamic_cast<RtlPins*>(&stack.pins()); }

}  // namespace gpubridge::usb::emu
