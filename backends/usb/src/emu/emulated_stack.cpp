#include "gpubridge/usb/emu/emulated_stack.hpp"

#include <cstdio>
#include <stdexcept>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/sim/device.hpp"
#include "gpubridge/usb/bridge_chips.hpp"
#include "gpubridge/usb/emu/chip_model.hpp"
#include "gpubridge/usb/emu/mcp2210_model.hpp"
#include "gpubridge/usb/emu/reference_target.hpp"

namespace gpubridge::usb::emu {
namespace {

// Forwards to the current device model; a power cycle replaces it with a fresh one.
class SwitchableTarget final : public backends::SpiTarget {
 public:
  std::uint8_t miso_status() override { return t_->miso_status(); }
  std::uint64_t read_register(std::uint8_t i) override { return t_->read_register(i); }
  void frame_complete(const protocol::Frame& f) override { t_->frame_complete(f); }
  void frame_aborted() override { t_->frame_aborted(); }
  bool busy_pin() const override { return t_->busy_pin(); }
  std::unique_ptr<backends::SpiTarget> t_;
};

}  // namespace

struct EmulatedStack::Impl {
  BoardProfile profile;
  EmulationOptions opts;
  // The SPI pins: the C++ SPI slave driving a device model (simulator or reference target), or
  // whatever EmulationOptions::pins built (then `slave` is null).
  SwitchableTarget target;
  bool simulator = false;
  std::unique_ptr<SpiSlave> slave;
  std::unique_ptr<SpiPins> custom_pins;
  std::unique_ptr<ChipModel> chip;

  SpiPins* pins() { return slave ? static_cast<SpiPins*>(slave.get()) : custom_pins.get(); }

  Result<std::unique_ptr<backends::SpiTarget>> make_target() {
    if (opts.use_simulator) {
      sim::DeviceOptions o;
      o.vram_bytes = std::uint64_t{profile.vram_kib} * 1024;
      o.max_width = profile.max_width;
      o.max_height = profile.max_height;
      o.fifo_depth = std::max(64u, profile.fifo_depth);
      o.fifo_drain_per_frame = opts.drain_per_frame;
      auto d = sim::Device::create(o);
      if (!d) return d.error();
      simulator = true;
      return std::unique_ptr<backends::SpiTarget>(std::move(*d));
    }
    ReferenceTargetConfig c;
    c.vram_kib = profile.vram_kib;
    c.fifo_depth = profile.fifo_depth;
    c.max_width = profile.max_width;
    c.max_height = profile.max_height;
    c.drain_per_frame = opts.drain_per_frame;
    simulator = false;
    return std::unique_ptr<backends::SpiTarget>(std::make_unique<ReferenceTarget>(c));
  }
  void tick() {
    if (simulator) static_cast<sim::Device*>(target.t_.get())->step(1);
    else static_cast<ReferenceTarget*>(target.t_.get())->tick();
  }
  void power_cycle() {
    auto t = make_target();
    if (t) target.t_ = std::move(*t);  // same options as before, so creation cannot newly fail
  }
  SpiSlave& builtin_slave() {
    if (!slave) throw std::logic_error("emulated board '" + profile.name + "': no C++ SPI slave (EmulationOptions::pins replaced it)");
    return *slave;
  }
};

EmulatedStack::EmulatedStack(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
EmulatedStack::~EmulatedStack() = default;

Result<std::unique_ptr<EmulatedStack>> EmulatedStack::create(const BoardProfile& profile, EmulationOptions opts) {
  FaultPlan presence;
  presence.presence_file = opts.presence_file;
  if (!presence.present()) {
    // The wording and code of LibusbContext::open when nothing matches: the same "device gone" case.
    char id[16];
    std::snprintf(id, sizeof id, "%04x:%04x", profile.vid, profile.pid);
    return make_error(std::string("no USB device ") + id + " with serial " + opts.serial +
                          " is attached (emulated: presence file " + opts.presence_file +
                          " is absent); create the file to plug the emulated adapter in",
                      backends::kDeviceGone);
  }
  auto impl = std::make_unique<Impl>();
  impl->profile = profile;
  impl->opts = opts;
  if (opts.pins) {
    auto pins = opts.pins(profile);
    if (!pins) return make_error("emulated board '" + profile.name + "': " + pins.error().message, pins.error().code);
    impl->custom_pins = std::move(*pins);
  } else {
    auto t = impl->make_target();
    if (!t) return make_error("emulated board '" + profile.name + "': " + t.error().message, backends::kBadRequest);
    impl->target.t_ = std::move(*t);
    Impl* raw = impl.get();
    impl->slave = std::make_unique<SpiSlave>(impl->target, [raw] { raw->power_cycle(); }, [raw] { raw->tick(); });
  }
  impl->chip = chip_info(profile.chip).make_model(profile, opts, impl->pins());
  std::unique_ptr<EmulatedStack> stack(new EmulatedStack(std::move(impl)));
  stack->usb_faults().presence_file = opts.presence_file;
  return stack;
}

UsbDevice* EmulatedStack::usb() { return impl_->chip->usb(); }
HidDevice* EmulatedStack::hid() { return impl_->chip->hid(); }
BridgeTransport EmulatedStack::transport() { return {usb(), hid()}; }
ChipModel& EmulatedStack::chip() { return *impl_->chip; }
Mcp2210Model* EmulatedStack::mcp2210() { return dynamic_cast<Mcp2210Model*>(impl_->chip.get()); }
FaultPlan& EmulatedStack::usb_faults() { return impl_->chip->faults(); }
std::vector<std::string> EmulatedStack::violations() const { return impl_->chip->violations(); }
SpiPins& EmulatedStack::pins() { return *impl_->pins(); }
SpiFaults& EmulatedStack::spi_faults() { return impl_->builtin_slave().faults(); }
SpiSlave& EmulatedStack::slave() { return impl_->builtin_slave(); }
backends::SpiTarget& EmulatedStack::target() {
  impl_->builtin_slave();
  return *impl_->target.t_;
}
bool EmulatedStack::target_is_simulator() const { return impl_->slave && impl_->simulator; }
void EmulatedStack::power_cycle() {
  impl_->builtin_slave();
  impl_->power_cycle();
}

Result<EmulatedBoard> open_emulated_board(const BoardProfile& profile, EmulationOptions opts, BoardOptions board) {
  auto stack = EmulatedStack::create(profile, opts);
  if (!stack) return stack.error();
  std::shared_ptr<EmulatedStack> shared = std::move(*stack);
  auto bridge = open_bridge(profile, shared->transport());
  if (!bridge) return bridge.error();
  auto backend = BoardBackend::attach(profile, shared, std::move(*bridge), board);
  if (!backend) return backend.error();
  return EmulatedBoard{shared, std::move(*backend)};
}

}  // namespace gpubridge::usb::emu
