#include "gpubridge/usb/emu/emulated_stack.hpp"

#include <cstdio>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/usb/ch341a.hpp"
#include "gpubridge/usb/cp2130.hpp"
#include "gpubridge/usb/emu/ch341a_model.hpp"
#include "gpubridge/usb/emu/cp2130_model.hpp"
#include "gpubridge/usb/emu/mcp2210_model.hpp"
#include "gpubridge/usb/emu/mpsse_model.hpp"
#include "gpubridge/usb/mcp2210.hpp"
#include "gpubridge/usb/emu/reference_target.hpp"
#include "gpubridge/usb/ftdi_mpsse.hpp"
#if GPUBRIDGE_HAVE_SIM
#include "gpubridge/sim/device.hpp"
#endif

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
  SwitchableTarget target;
  bool simulator = false;
  std::unique_ptr<SpiSlave> slave;
  std::unique_ptr<MpsseModel> mpsse;
  std::unique_ptr<Ch341aModel> ch341a;
  std::unique_ptr<Mcp2210Model> mcp2210;
  std::unique_ptr<Cp2130Model> cp2130;
  FaultPlan no_faults;

  Result<std::unique_ptr<backends::SpiTarget>> make_target() {
#if GPUBRIDGE_HAVE_SIM
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
#endif
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
#if GPUBRIDGE_HAVE_SIM
    if (simulator) {
      static_cast<sim::Device*>(target.t_.get())->step(1);
      return;
    }
#endif
    static_cast<ReferenceTarget*>(target.t_.get())->tick();
  }
  void power_cycle() {
    auto t = make_target();
    if (t) target.t_ = std::move(*t);  // same options as before, so creation cannot newly fail
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
  auto t = impl->make_target();
  if (!t) return make_error("emulated board '" + profile.name + "': " + t.error().message, backends::kBadRequest);
  impl->target.t_ = std::move(*t);
  Impl* raw = impl.get();
  impl->slave = std::make_unique<SpiSlave>(impl->target, [raw] { raw->power_cycle(); }, [raw] { raw->tick(); });
  switch (profile.chip) {
    case BridgeChip::FT232H:
    case BridgeChip::FT2232H:
    case BridgeChip::FT4232H: {
      MpsseModelConfig c;
      c.chip = profile.chip == BridgeChip::FT232H    ? FtdiChip::FT232H
               : profile.chip == BridgeChip::FT2232H ? FtdiChip::FT2232H
                                                     : FtdiChip::FT4232H;
      c.high_speed = opts.high_speed;
      c.serial = opts.serial;
      c.cs_pin = profile.cs_pin;
      c.busy_wired = profile.busy_pin;
      impl->mpsse = std::make_unique<MpsseModel>(c, impl->slave.get());
      break;
    }
    case BridgeChip::CH341A: impl->ch341a = std::make_unique<Ch341aModel>(impl->slave.get(), opts.serial); break;
    case BridgeChip::MCP2210: impl->mcp2210 = std::make_unique<Mcp2210Model>(impl->slave.get(), opts.serial); break;
    case BridgeChip::CP2130: impl->cp2130 = std::make_unique<Cp2130Model>(impl->slave.get(), opts.serial); break;
  }
  std::unique_ptr<EmulatedStack> stack(new EmulatedStack(std::move(impl)));
  stack->usb_faults().presence_file = opts.presence_file;
  return stack;
}

UsbDevice* EmulatedStack::usb() {
  if (impl_->mpsse) return impl_->mpsse.get();
  if (impl_->ch341a) return impl_->ch341a.get();
  if (impl_->cp2130) return impl_->cp2130.get();
  return nullptr;
}
HidDevice* EmulatedStack::hid() { return impl_->mcp2210.get(); }
Mcp2210Model* EmulatedStack::mcp2210() { return impl_->mcp2210.get(); }
FaultPlan& EmulatedStack::usb_faults() {
  if (impl_->mpsse) return impl_->mpsse->faults();
  if (impl_->ch341a) return impl_->ch341a->faults();
  if (impl_->cp2130) return impl_->cp2130->faults();
  if (impl_->mcp2210) return impl_->mcp2210->faults();
  return impl_->no_faults;
}
SpiFaults& EmulatedStack::spi_faults() { return impl_->slave->faults(); }
SpiSlave& EmulatedStack::slave() { return *impl_->slave; }
backends::SpiTarget& EmulatedStack::target() { return *impl_->target.t_; }
bool EmulatedStack::target_is_simulator() const { return impl_->simulator; }
void EmulatedStack::power_cycle() { impl_->power_cycle(); }
std::vector<std::string> EmulatedStack::violations() const {
  if (impl_->mpsse) return impl_->mpsse->violations();
  if (impl_->ch341a) return impl_->ch341a->violations();
  if (impl_->cp2130) return impl_->cp2130->violations();
  if (impl_->mcp2210) return impl_->mcp2210->violations();
  return {};
}

Result<std::unique_ptr<SpiBridge>> open_bridge(const BoardProfile& p, UsbDevice* usb, HidDevice* hid) {
  switch (p.chip) {
    case BridgeChip::FT232H:
    case BridgeChip::FT2232H:
    case BridgeChip::FT4232H: {
      if (!usb) return make_error("FTDI driver needs a USB device", backends::kBadRequest);
      FtdiConfig c;
      c.channel = p.interface;
      c.cs_pin = p.cs_pin;
      c.busy_pin = p.busy_pin;
      c.read_edge = p.read_edge;
      c.latency_ms = p.latency_ms;
      c.clock_hz = p.spi_clock_hz;
      c.stream_reads = p.stream_reads;
      auto b = FtdiMpsseBridge::open(*usb, c);
      if (!b) return b.error();
      return std::unique_ptr<SpiBridge>(std::move(*b));
    }
    case BridgeChip::CH341A: {
      if (!usb) return make_error("CH341A driver needs a USB device", backends::kBadRequest);
      auto b = Ch341aBridge::open(*usb);
      if (!b) return b.error();
      return std::unique_ptr<SpiBridge>(std::move(*b));
    }
    case BridgeChip::CP2130: {
      if (!usb) return make_error("CP2130 driver needs a USB device", backends::kBadRequest);
      auto b = Cp2130Bridge::open(*usb, p.cs_pin, p.spi_clock_hz);
      if (!b) return b.error();
      return std::unique_ptr<SpiBridge>(std::move(*b));
    }
    case BridgeChip::MCP2210: {
      if (!hid) return make_error("MCP2210 driver needs a HID device", backends::kBadRequest);
      auto b = Mcp2210Bridge::open(*hid, p.cs_pin, p.spi_clock_hz);
      if (!b) return b.error();
      return std::unique_ptr<SpiBridge>(std::move(*b));
    }
  }
  return make_error("no driver for bridge chip " + std::string(to_string(p.chip)), backends::kBadRequest);
}

Result<EmulatedBoard> open_emulated_board(const BoardProfile& profile, EmulationOptions opts, BoardOptions board) {
  auto stack = EmulatedStack::create(profile, opts);
  if (!stack) return stack.error();
  std::shared_ptr<EmulatedStack> shared = std::move(*stack);
  auto bridge = open_bridge(profile, shared->usb(), shared->hid());
  if (!bridge) return bridge.error();
  auto backend = BoardBackend::attach(profile, shared, std::move(*bridge), board);
  if (!backend) return backend.error();
  return EmulatedBoard{shared, std::move(*backend)};
}

}  // namespace gpubridge::usb::emu
