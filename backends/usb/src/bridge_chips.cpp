// The bridge chip table. To add a chip: its driver (an SpiBridge), its model (an emu::ChipModel),
// one row here, configs/cables/<chip>.json and a board profile; CONTRIBUTING.md has the steps and
// tests/usb/chip_table_test.cpp fails until all of them exist.
#include "gpubridge/usb/bridge_chips.hpp"

#include <algorithm>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/ch341a.hpp"
#include "gpubridge/usb/cp2130.hpp"
#include "gpubridge/usb/emu/ch341a_model.hpp"
#include "gpubridge/usb/emu/cp2130_model.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "gpubridge/usb/emu/mcp2210_model.hpp"
#include "gpubridge/usb/emu/mpsse_model.hpp"
#include "gpubridge/usb/ftdi_mpsse.hpp"
#include "gpubridge/usb/mcp2210.hpp"

namespace gpubridge::usb {
namespace {

template <class Bridge>
Result<std::unique_ptr<SpiBridge>> as_bridge(Result<std::unique_ptr<Bridge>> b) {
  if (!b) return b.error();
  return std::unique_ptr<SpiBridge>(std::move(*b));
}

Result<std::unique_ptr<SpiBridge>> open_ftdi(const BoardProfile& p, BridgeTransport t) {
  FtdiConfig c;
  c.channel = p.interface;
  c.cs_pin = p.cs_pin;
  c.busy_pin = p.busy_pin;
  c.read_edge = p.read_edge;
  c.latency_ms = p.latency_ms;
  c.clock_hz = p.spi_clock_hz;
  c.stream_reads = p.stream_reads;
  return as_bridge(FtdiMpsseBridge::open(*t.usb, c));
}
Result<std::unique_ptr<SpiBridge>> open_ch341a(const BoardProfile&, BridgeTransport t) { return as_bridge(Ch341aBridge::open(*t.usb)); }
Result<std::unique_ptr<SpiBridge>> open_cp2130(const BoardProfile& p, BridgeTransport t) {
  return as_bridge(Cp2130Bridge::open(*t.usb, p.cs_pin, p.spi_clock_hz));
}
Result<std::unique_ptr<SpiBridge>> open_mcp2210(const BoardProfile& p, BridgeTransport t) {
  return as_bridge(Mcp2210Bridge::open(*t.hid, p.cs_pin, p.spi_clock_hz));
}

template <emu::FtdiChip kChip>
std::unique_ptr<emu::ChipModel> mpsse_model(const BoardProfile& p, const emu::EmulationOptions& o, emu::SpiPins* pins) {
  emu::MpsseModelConfig c;
  c.chip = kChip;
  c.high_speed = o.high_speed;
  c.serial = o.serial;
  c.cs_pin = p.cs_pin;
  c.busy_wired = p.busy_pin;
  return std::make_unique<emu::MpsseModel>(c, pins);
}
template <class Model>
std::unique_ptr<emu::ChipModel> model(const BoardProfile&, const emu::EmulationOptions& o, emu::SpiPins* pins) {
  return std::make_unique<Model>(pins, o.serial);
}

constexpr std::string_view kFtdiCs = "FTDI chip select must be ADBUS3..7 (and not 5, GPIOL1, when busy_pin is wired)";

// clang-format off
constexpr BridgeChipInfo kChips[] = {
  // chip                name       label      vid     pid     api             max SCK     ch cs     cs rule  BUSY streams  driver        model
  {BridgeChip::FT232H,  "ft232h",  "FT232H",  0x0403, 0x6014, UsbApi::Libusb, 30'000'000, 1, 3, 7,  kFtdiCs, 5,  true,  &open_ftdi,    &mpsse_model<emu::FtdiChip::FT232H>},
  {BridgeChip::FT2232H, "ft2232h", "FT2232H", 0x0403, 0x6010, UsbApi::Libusb, 30'000'000, 2, 3, 7,  kFtdiCs, 5,  true,  &open_ftdi,    &mpsse_model<emu::FtdiChip::FT2232H>},
  {BridgeChip::FT4232H, "ft4232h", "FT4232H", 0x0403, 0x6011, UsbApi::Libusb, 30'000'000, 2, 3, 7,  kFtdiCs, 5,  true,  &open_ftdi,    &mpsse_model<emu::FtdiChip::FT4232H>},
  {BridgeChip::CH341A,  "ch341a",  "CH341A",  0x1a86, 0x5512, UsbApi::Libusb, 1'700'000,  1, 0, 10, {},      -1, false, &open_ch341a,  &model<emu::Ch341aModel>},
  {BridgeChip::MCP2210, "mcp2210", "MCP2210", 0x04d8, 0x00de, UsbApi::Hidapi, 12'000'000, 1, 0, 10, {},      -1, false, &open_mcp2210, &model<emu::Mcp2210Model>},
  {BridgeChip::CP2130,  "cp2130",  "CP2130",  0x10c4, 0x87a0, UsbApi::Libusb, 12'000'000, 1, 0, 10, {},      -1, false, &open_cp2130,  &model<emu::Cp2130Model>},
};
// clang-format on
static_assert([] {
  for (std::size_t i = 0; i < std::size(kChips); ++i)
    if (static_cast<std::size_t>(kChips[i].chip) != i) return false;
  return true;
}(), "kChips lists every BridgeChip once, in enum order");

}  // namespace

std::string_view to_string(UsbApi api) { return api == UsbApi::Hidapi ? "hidapi" : "libusb"; }

std::span<const BridgeChipInfo> bridge_chips() { return kChips; }
const BridgeChipInfo& chip_info(BridgeChip chip) { return kChips[static_cast<std::size_t>(chip)]; }

const BridgeChipInfo* find_chip(std::string_view name) {
  for (const auto& c : kChips)
    if (c.name == name) return &c;
  return nullptr;
}

std::string_view to_string(BridgeChip chip) {
  const auto i = static_cast<std::size_t>(chip);
  return i < std::size(kChips) ? kChips[i].name : "?";
}

std::optional<BridgeChip> parse_bridge_chip(std::string_view name) {
  if (const auto* c = find_chip(name)) return c->chip;
  return std::nullopt;
}

std::string chip_names(std::string_view separator) {
  std::string out;
  for (const auto& c : kChips) out += (out.empty() ? "" : std::string(separator)) + std::string(c.name);
  return out;
}

Result<std::unique_ptr<SpiBridge>> open_bridge(const BoardProfile& profile, BridgeTransport transport) {
  const auto& chip = chip_info(profile.chip);
  const bool hid = chip.api == UsbApi::Hidapi;
  if (hid ? !transport.hid : !transport.usb)
    return make_error(std::string(chip.label) + " driver needs a " + (hid ? "HID" : "USB") + " device", backends::kBadRequest);
  return chip.open_driver(profile, transport);
}

}  // namespace gpubridge::usb
