#include "gpubridge/usb/board_factory.hpp"

#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "gpubridge/usb/hidapi_transport.hpp"
#include "gpubridge/usb/libusb_transport.hpp"

namespace gpubridge::usb {
namespace {

// Everything below the driver, destroyed after it (BoardBackend keeps this alive).
struct RealLower {
  std::shared_ptr<LibusbContext> usb_ctx;
  std::shared_ptr<HidapiContext> hid_ctx;
  std::unique_ptr<UsbDevice> usb;
  std::unique_ptr<HidDevice> hid;
};

}  // namespace

Result<std::unique_ptr<BoardBackend>> open_board(const BoardProfile& profile, const BoardOpenOptions& opts) {
  if (opts.emulate) {
    emu::EmulationOptions eo;
    eo.presence_file = opts.emulated_presence_file;
    eo.pins = opts.emulated_pins;
    auto stack = emu::EmulatedStack::create(profile, eo);
    if (!stack) return stack.error();
    std::shared_ptr<emu::EmulatedStack> s = std::move(*stack);
    if (opts.emulated_max_reliable_hz) s->spi_faults().max_reliable_hz = opts.emulated_max_reliable_hz;
    auto bridge = open_bridge(profile, s->transport());
    if (!bridge) return bridge.error();
    return BoardBackend::attach(profile, s, std::move(*bridge), opts.board);
  }
  auto lower = std::make_shared<RealLower>();
  if (chip_info(profile.chip).api == UsbApi::Hidapi) {
    auto ctx = HidapiContext::create();
    if (!ctx) return ctx.error();
    lower->hid_ctx = *ctx;
    auto dev = lower->hid_ctx->open(profile.vid, profile.pid, profile.serial);
    if (!dev) return dev.error();
    lower->hid = std::move(*dev);
  } else {
    auto ctx = LibusbContext::create();
    if (!ctx) return ctx.error();
    lower->usb_ctx = *ctx;
    auto dev = lower->usb_ctx->open(UsbMatch{profile.vid, profile.pid, profile.serial, profile.port_path});
    if (!dev) return dev.error();
    lower->usb = std::move(*dev);
  }
  auto bridge = open_bridge(profile, {lower->usb.get(), lower->hid.get()});
  if (!bridge) return bridge.error();
  return BoardBackend::attach(profile, lower, std::move(*bridge), opts.board);
}

}  // namespace gpubridge::usb
