#include "gpubridge/usb/emu/mcp2210_model.hpp"

#include <algorithm>

namespace gpubridge::usb::emu {

Mcp2210Model::Mcp2210Model(SpiPins* pins, std::string serial) : ChipModel(pins) {
  info_.vid = 0x04d8;
  info_.pid = 0x00de;
  info_.path = "/dev/hidraw-model";
  info_.serial = std::move(serial);
  info_.product = "MCP2210 (model)";
  spi_settings_[4] = 0x00;  // power-up default: 1 Mbit/s, 4 bytes per transaction (datasheet)
  spi_settings_[5] = 0x42;
  spi_settings_[6] = 0x0F;
  spi_settings_[18] = 4;
}

int Mcp2210Model::write(std::span<const std::uint8_t> data) {
  const UsbFault f = faults_.next();
  if (f == UsbFault::NoDevice || f == UsbFault::Stall) {
    last_error_ = f == UsbFault::NoDevice ? "No such device" : "Broken pipe";
    return -1;
  }
  if (data.size() != 65 || data[0] != 0x00) {
    violation("HID write of " + std::to_string(data.size()) + " bytes (must be report id 0x00 + 64 bytes)");
    last_error_ = "bad report";
    return -1;
  }
  if (f == UsbFault::TimeoutPartial) return 65;  // the report is lost: no response will come
  responses_.push_back(handle(data.subspan<1, 64>()));
  return 65;
}

int Mcp2210Model::read(std::span<std::uint8_t> data, int) {
  const UsbFault f = faults_.next();
  if (f == UsbFault::NoDevice || f == UsbFault::Stall) {
    last_error_ = "No such device";
    return -1;
  }
  if (responses_.empty() || f == UsbFault::TimeoutPartial) return 0;
  const auto r = responses_.front();
  responses_.pop_front();
  const std::size_t n = std::min<std::size_t>(data.size(), 64);
  std::copy_n(r.begin(), n, data.begin());
  return static_cast<int>(n);
}

std::array<std::uint8_t, 64> Mcp2210Model::handle(std::span<const std::uint8_t, 64> r) {
  std::array<std::uint8_t, 64> out{};
  out[0] = r[0];
  switch (r[0]) {
    case 0x10:
      out[3] = in_transaction_ ? 1 : 0;
      break;
    case 0x11:  // cancel the current SPI transfer
      in_transaction_ = false;
      rx_.clear();
      remaining_ = 0;
      if (pins_ && pins_->cs_asserted()) pins_->set_cs(false);
      break;
    case 0x20:
      std::copy(chip_settings_.begin() + 4, chip_settings_.end(), out.begin() + 4);
      break;
    case 0x21:
      if (in_transaction_) { out[1] = 0xF8; break; }
      std::copy(r.begin(), r.end(), chip_settings_.begin());
      break;
    case 0x40:
      if (in_transaction_) { out[1] = 0xF8; break; }
      if (r[20] > 3) violation("SPI mode " + std::to_string(r[20]) + " (valid 0..3)");
      std::copy(r.begin(), r.end(), spi_settings_.begin());
      break;
    case 0x41:
      std::copy(spi_settings_.begin() + 4, spi_settings_.end(), out.begin() + 4);
      break;
    case 0x42: {
      if (external_master) { out[1] = 0xF7; break; }
      if (inject_busy) { --inject_busy; out[1] = 0xF8; break; }
      const std::size_t n = r[1];
      if (n > 60) {
        violation("transfer of " + std::to_string(n) + " bytes in one report (max 60)");
        out[1] = 0xF8;
        break;
      }
      const bool first = !in_transaction_;
      if (first) {
        remaining_ = std::size_t{spi_settings_[18]} | std::size_t{spi_settings_[19]} << 8;
        if (spi_settings_[20] != 0) violation("SPI mode is not 0");
        const std::uint16_t active = static_cast<std::uint16_t>(spi_settings_[10] | spi_settings_[11] << 8);
        unsigned cs = 9;
        for (unsigned p = 0; p < 9; ++p)
          if (chip_settings_[4 + p] == 1 && !(active & (1u << p))) cs = p;
        if (cs == 9) violation("transfer without a GP pin designated as chip select and driven low");
        if (n == 0 || remaining_ == 0) {
          violation("transfer started with no data or zero transaction length");
          out[1] = 0x00;
          out[3] = 0x10;
          break;
        }
        in_transaction_ = true;
        if (pins_) pins_->set_cs(true);
      }
      if (n > remaining_) violation("more bytes than the configured transaction length");
      for (std::size_t i = 0; i < n && remaining_ > 0; ++i, --remaining_) rx_.push_back(pins_ ? pins_->shift_byte(r[4 + i]) : 0xFF);
      if (remaining_ == 0 && pins_ && pins_->cs_asserted()) pins_->set_cs(false);
      if (first) {
        out[3] = 0x20;  // started, data not yet available
        break;
      }
      const std::size_t k = std::min<std::size_t>(60, rx_.size());
      out[2] = static_cast<std::uint8_t>(k);
      for (std::size_t i = 0; i < k; ++i) {
        out[4 + i] = rx_.front();
        rx_.pop_front();
      }
      if (remaining_ == 0 && rx_.empty()) {
        out[3] = 0x10;
        in_transaction_ = false;
      } else {
        out[3] = 0x30;
      }
      break;
    }
    default:
      violation("unknown MCP2210 command");
      out[1] = 0xF9;
  }
  return out;
}

}  // namespace gpubridge::usb::emu
