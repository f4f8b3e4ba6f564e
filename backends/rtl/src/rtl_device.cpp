// The pin engine: one SPI timeline (the master's instants) and one core clock (its own period and
// phase). Pins change at SPI instants; every core clock edge up to an instant is simulated before the
// pins change there, so the device sees asynchronous inputs through its synchronisers as on a board.
#include "gpubridge/rtl/rtl_device.hpp"

#include <algorithm>
#include <cmath>

#include "gateware_model.hpp"

namespace gpubridge::rtl {

RtlCounters operator-(const RtlCounters& a, const RtlCounters& b) {
  RtlCounters d;
  d.cycles = a.cycles - b.cycles;
  d.work_cycles = a.work_cycles - b.work_cycles;
  d.commands = a.commands - b.commands;
  d.spi_frames = a.spi_frames - b.spi_frames;
  d.core_mem_stalls = a.core_mem_stalls - b.core_mem_stalls;
  d.triangles = a.triangles - b.triangles;
  d.pixels = a.pixels - b.pixels;
  d.passed = a.passed - b.passed;
  d.textured = a.textured - b.textured;
  d.core_busy_cycles = a.core_busy_cycles - b.core_busy_cycles;
  d.setup_cycles = a.setup_cycles - b.setup_cycles;
  d.raster_cycles = a.raster_cycles - b.raster_cycles;
  d.refreshes = a.refreshes - b.refreshes;
  d.sdram_violations = a.sdram_violations - b.sdram_violations;
  d.sck_edges_too_fast = a.sck_edges_too_fast - b.sck_edges_too_fast;
  return d;
}

#if GPUBRIDGE_HAVE_RTL
bool RtlDevice::available() { return true; }
std::string RtlDevice::unavailable_reason() { return {}; }
#else
bool RtlDevice::available() { return false; }
std::string RtlDevice::unavailable_reason() {
  return "the rtl backend is not part of this build: Verilator was not found when it was configured (install it "
         "with scripts/install-deps.sh, then reconfigure)";
}
#endif

struct RtlDevice::Impl {
  GatewareProfile profile{};
  GatewareCaps caps;
  PinTiming timing;
  std::unique_ptr<detail::GatewareModel> model;
  detail::ModelInputs in;
  // time in picoseconds
  double tc = 0;           // core clock period
  double now = 0;          // SPI timeline
  double next_edge = 0;    // next core clock edge
  double sck_period = 0;
  double miso_delay = 0;
  std::uint64_t cycles = 0;
  std::uint64_t fast_edges = 0;
  // counters: the model's are 32 bits; these accumulate them
  mutable detail::ModelCounters last_raw;
  mutable RtlCounters acc;
  std::uint64_t last_fold_cycles = 0;
  // scanout capture
  std::function<void(const ScanFrame&)> frame_cb;
  ScanFrame frame;
  bool in_frame = false;
  std::uint32_t frames = 0;

  void apply() { model->set_inputs(in); }

  void run_to(double t) {
    while (next_edge <= t) {
      if (model->tick()) on_frame_signals();
      ++cycles;
      next_edge += tc;
    }
    if (cycles - last_fold_cycles > (1u << 30)) fold_counters();
  }

  void on_frame_signals() {
    const detail::ModelFrame f = model->frame();
    if (f.start) {
      frame = ScanFrame{};
      frame.width = f.width;
      frame.height = f.height;
      frame.format = static_cast<protocol::PixelFormat>(f.format);
      frame.bytes.reserve(std::size_t{f.width} * f.height * protocol::bytes_per_pixel(frame.format));
      in_frame = true;
    }
    if (f.valid && in_frame)
      for (unsigned i = 0; i < f.nbytes && i < 4; ++i) frame.bytes.push_back(static_cast<std::uint8_t>(f.word >> (24 - 8 * i)));
    if (f.end && in_frame) {
      in_frame = false;
      frame.number = ++frames;
      if (frame_cb) frame_cb(frame);
    }
  }

  void fold_counters() const {
    const detail::ModelCounters c = model->counters();
    acc.work_cycles += std::uint32_t(c.work_cycles - last_raw.work_cycles);
    acc.commands += std::uint32_t(c.cmds - last_raw.cmds);
    acc.spi_frames += std::uint32_t(c.frames - last_raw.frames);
    acc.core_mem_stalls += std::uint32_t(c.core_stalls - last_raw.core_stalls);
    acc.refreshes += std::uint32_t(c.refreshes - last_raw.refreshes);
    acc.sdram_violations += std::uint32_t(c.sdram_violations - last_raw.sdram_violations);
    acc.triangles += std::uint32_t(c.triangles - last_raw.triangles);
    acc.pixels += std::uint32_t(c.pixels - last_raw.pixels);
    acc.passed += std::uint32_t(c.passed - last_raw.passed);
    acc.textured += std::uint32_t(c.textured - last_raw.textured);
    acc.core_busy_cycles += std::uint32_t(c.core_busy - last_raw.core_busy);
    acc.setup_cycles += std::uint32_t(c.setup - last_raw.setup);
    acc.raster_cycles += std::uint32_t(c.raster - last_raw.raster);
    last_raw = c;
  }

  void set_sck(double hz) {
    sck_period = 1e12 / hz;
    if (sck_period / 2 <= tc) ++fast_edges;  // outside the documented ratio: edges may be missed
  }

  void reset_pulse() {
    in.rst = true;
    apply();
    now += 8 * tc;
    run_to(now);
    in.rst = false;
    apply();
    now += 2 * tc;
    run_to(now);
  }
};

Result<std::unique_ptr<RtlDevice>> RtlDevice::create(GatewareProfile profile, PinTiming timing) {
  if (!available()) return make_error(unavailable_reason());
  auto impl = std::make_unique<Impl>();
  impl->profile = profile;
  impl->caps = caps_of(profile);
  if (timing.core_hz == 0) timing.core_hz = impl->caps.core_hz;
  if (!(timing.sck_hz > 0) || !(timing.miso_delay_ns >= 0) || !(timing.phase >= 0 && timing.phase < 1) ||
      !std::isfinite(timing.sck_hz) || !std::isfinite(timing.miso_delay_ns))
    return make_error("rtl device: SPI clock must be > 0 Hz, MISO delay >= 0 ns and the clock phase in [0, 1)");
  if (timing.core_hz != impl->caps.core_hz)
    return make_error("rtl device: the " + std::string(to_string(profile)) + " model is built for a " +
                      std::to_string(impl->caps.core_hz / 1e6) + " MHz core clock (its SDRAM timing depends on it), not " +
                      std::to_string(timing.core_hz / 1e6) + " MHz");
  impl->timing = timing;
  impl->model = profile == GatewareProfile::Up5k ? detail::make_model_up5k() : detail::make_model_ecp5();
  if (!impl->model) return make_error(unavailable_reason());
  impl->tc = 1e12 / timing.core_hz;
  impl->next_edge = timing.phase * impl->tc;
  impl->miso_delay = timing.miso_delay_ns * 1e3;
  impl->set_sck(timing.sck_hz);
  impl->reset_pulse();
  return std::unique_ptr<RtlDevice>(new RtlDevice(std::move(impl)));
}

RtlDevice::RtlDevice(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RtlDevice::~RtlDevice() = default;

GatewareProfile RtlDevice::profile() const { return impl_->profile; }
const GatewareCaps& RtlDevice::caps() const { return impl_->caps; }
const PinTiming& RtlDevice::timing() const { return impl_->timing; }

void RtlDevice::set_cs(bool asserted) {
  Impl& d = *impl_;
  if (asserted == !d.in.cs_n) return;
  // CS setup / hold: the synchronisers keep CS and SCK in order when they are 2+ clocks apart
  const double guard = std::max(3 * d.tc, d.sck_period / 2);
  d.now += guard;
  d.run_to(d.now);
  d.in.cs_n = !asserted;
  d.apply();
  d.now += guard;
  d.run_to(d.now);
}

bool RtlDevice::cs_asserted() const { return !impl_->in.cs_n; }

bool RtlDevice::shift_bit(bool mosi) {
  Impl& d = *impl_;
  const double half = d.sck_period / 2;
  d.run_to(d.now);
  d.in.mosi = mosi;  // the master drives MOSI on the falling edge that ends the previous bit
  d.apply();
  const double rise = d.now + half, fall = d.now + 2 * half;
  bool miso = true;
  if (!d.timing.sample_falling) {
    d.run_to(rise - d.miso_delay);
    miso = d.model->miso();
  }
  d.run_to(rise);
  d.in.sck = true;
  d.apply();
  if (d.timing.sample_falling) {
    d.run_to(fall - d.miso_delay);
    miso = d.model->miso();
  }
  d.run_to(fall);
  d.in.sck = false;
  d.apply();
  d.now = fall;
  return miso;
}

std::uint8_t RtlDevice::shift_byte(std::uint8_t mosi) {
  std::uint8_t out = 0;
  for (int b = 7; b >= 0; --b) out = static_cast<std::uint8_t>((out << 1) | (shift_bit((mosi >> b) & 1u) ? 1 : 0));
  return out;
}

bool RtlDevice::busy_pin() const { return impl_->model->busy(); }
void RtlDevice::set_sck_hz(double hz) {
  if (hz > 0 && std::isfinite(hz)) impl_->set_sck(hz);
}
void RtlDevice::idle_ns(double ns) {
  if (!(ns > 0) || !std::isfinite(ns)) return;
  impl_->now += ns * 1e3;
  impl_->run_to(impl_->now);
}
void RtlDevice::idle_clocks(std::uint64_t clocks) {
  impl_->now += static_cast<double>(clocks) * impl_->tc;
  impl_->run_to(impl_->now);
}
void RtlDevice::power_cycle() {
  impl_->in_frame = false;
  impl_->reset_pulse();
}

std::uint64_t RtlDevice::vram_bytes() const { return impl_->model->vram_bytes(); }
void RtlDevice::read_vram(std::uint64_t address, std::uint8_t* out, std::size_t length) const {
  impl_->model->read_vram(address, out, length);
}
std::vector<std::uint8_t> RtlDevice::vram() const {
  std::vector<std::uint8_t> v(vram_bytes());
  read_vram(0, v.data(), v.size());
  return v;
}
void RtlDevice::set_frame_callback(std::function<void(const ScanFrame&)> cb) { impl_->frame_cb = std::move(cb); }
RtlCounters RtlDevice::counters() const {
  impl_->fold_counters();
  RtlCounters c = impl_->acc;
  c.cycles = impl_->cycles;
  c.sck_edges_too_fast = impl_->fast_edges;
  return c;
}
double RtlDevice::now_ns() const { return impl_->now / 1e3; }

}  // namespace gpubridge::rtl

#if !GPUBRIDGE_HAVE_RTL
namespace gpubridge::rtl::detail {
std::unique_ptr<GatewareModel> make_model_up5k() { return nullptr; }
std::unique_ptr<GatewareModel> make_model_ecp5() { return nullptr; }
}  // namespace gpubridge::rtl::detail
#endif
