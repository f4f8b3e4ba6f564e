#include "gateware_board.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>

#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/rtl/simulator_options.hpp"

namespace gpubridge::test {

using protocol::Reg;
using protocol::index_of;

usb::BoardProfile board_profile(const std::string& name) {
  auto p = usb::find_board_profile(GPUBRIDGE_CONFIG_DIR, name);
  if (!p) throw std::runtime_error(p.error().message);
  return *p;
}

usb::BoardProfile with_gateware(usb::BoardProfile p, const std::string& gateware, std::uint32_t spi_clock_hz) {
  p.gateware = gateware;
  p.spi_clock_hz = spi_clock_hz;
  const auto caps = rtl::caps_of(*rtl::parse_gateware_profile(gateware));
  p.vram_kib = caps.vram_kib;
  p.max_width = caps.max_width;
  p.max_height = caps.max_height;
  p.fifo_depth = caps.fifo_depth;
  return p;
}

namespace {
// GPUBRIDGE_RTL_TRACE=FILE: every frame the simulator receives on the wires, for debugging a seed.
class TracingTarget final : public backends::SpiTarget {
 public:
  TracingTarget(backends::SpiTarget& t, const char* path) : t_(t), f_(std::fopen(path, "w")) {}
  ~TracingTarget() override {
    if (f_) std::fclose(f_);
  }
  std::uint8_t miso_status() override { return t_.miso_status(); }
  std::uint64_t read_register(std::uint8_t i) override {
    const auto v = t_.read_register(i);
    if (f_) std::fprintf(f_, "read  %02X -> %016llX\n", i, static_cast<unsigned long long>(v));
    return v;
  }
  void frame_complete(const protocol::Frame& fr) override {
    if (f_ && !fr.read) std::fprintf(f_, "write %02X %016llX\n", fr.index, static_cast<unsigned long long>(fr.data));
    t_.frame_complete(fr);
  }
  void frame_aborted() override {
    if (f_) std::fprintf(f_, "abort\n");
    t_.frame_aborted();
  }
  bool busy_pin() const override { return t_.busy_pin(); }

 private:
  backends::SpiTarget& t_;
  std::FILE* f_;
};
}  // namespace

Result<std::unique_ptr<GatewareBoard>> GatewareBoard::open(const usb::BoardProfile& profile, usb::BoardOptions opts) {
  std::unique_ptr<GatewareBoard> g(new GatewareBoard);
  const auto gp = rtl::parse_gateware_profile(profile.gateware);
  if (!gp) return make_error("profile " + profile.name + " names no gateware");
  auto s = sim::Device::create(rtl::simulator_options(rtl::caps_of(*gp)));
  if (!s) return s.error();
  g->sim_ = std::move(*s);
  g->sim_->set_scanout_callback([raw = g.get()](std::shared_ptr<const backends::ScanoutFrame> f) { raw->sim_frames_.push_back(*f); });
  backends::SpiTarget* target = g->sim_.get();
  if (const char* path = std::getenv("GPUBRIDGE_RTL_TRACE"); path && *path) {
    g->trace_ = std::make_unique<TracingTarget>(*g->sim_, path);
    target = g->trace_.get();
  }
  g->sim_pins_ = std::make_unique<usb::emu::SpiSlave>(*target, nullptr, nullptr);
  // The stack must exist before the backend attaches (attach already talks to the device), so the
  // shadow is connected through a stack opened first and a backend attached to it afterwards.
  usb::emu::EmulationOptions eo;
  eo.pins = usb::emu::rtl_pins();
  auto stack = usb::emu::EmulatedStack::create(profile, eo);
  if (!stack) return stack.error();
  std::shared_ptr<usb::emu::EmulatedStack> shared = std::move(*stack);
  GatewareBoard* raw = g.get();
  usb::emu::rtl_pins_of(*shared)->set_shadow(g->sim_pins_.get(), [raw](std::uint8_t index, std::uint64_t gw, std::uint64_t other) {
    // registers whose value does not depend on when the read happens
    const bool timed = index == index_of(Reg::STATUS) || index == index_of(Reg::FRAME_CRC) ||
                       index == index_of(Reg::MEM_ADDR) || index == index_of(Reg::MEM_DATA);
    const bool stable = index == index_of(Reg::ID) || index == index_of(Reg::CAPS) || index == index_of(Reg::CAPS2) ||
                        index == index_of(Reg::HOST_TAG) ||
                        index == index_of(Reg::LINK_STATUS) || (raw->compare_all_reads_ && !timed);
    if (!stable) return;
    ++raw->reads_compared_;
    if (gw != other && raw->read_mismatches_.size() < 8)
      raw->read_mismatches_.push_back(fmt::format("read of 0x{:02X}: gateware 0x{:016X}, simulator 0x{:016X}", index, gw, other));
  });
  usb::emu::rtl_pins_of(*shared)->device().set_frame_callback([raw](const rtl::ScanFrame& f) { raw->gw_frames_.push_back(f); });
  auto bridge = usb::open_bridge(profile, shared->transport());
  if (!bridge) return bridge.error();
  auto backend = usb::BoardBackend::attach(profile, shared, std::move(*bridge), opts);
  if (!backend) return backend.error();
  (*backend)->set_scanout_callback([raw](std::shared_ptr<const backends::ScanoutFrame> f) { raw->board_frames_.push_back(f); });
  g->board_ = usb::emu::EmulatedBoard{shared, std::move(*backend)};
  return g;
}

std::string GatewareBoard::compare(bool errors_too) {
  std::string out;
  if (auto r = board_.backend->flush(); !r) out += "flush: " + r.error().message + "\n";
  for (const auto& m : read_mismatches_) out += m + "\n";
  // video memory
  const std::uint64_t n = compare_limit_ ? std::min(compare_limit_, gateware().vram_bytes()) : gateware().vram_bytes();
  std::vector<std::uint8_t> gw(n);
  gateware().read_vram(0, gw.data(), gw.size());
  const auto sm = sim_->memory();
  std::size_t diffs = 0;
  for (std::size_t i = 0; i < gw.size() && i < sm.size(); ++i) {
    if (gw[i] == sm[i]) continue;
    if (diffs++ < 4) out += fmt::format("VRAM byte 0x{:X}: gateware 0x{:02X}, simulator 0x{:02X}\n", i, gw[i], sm[i]);
  }
  if (diffs) out += fmt::format("VRAM: {} bytes differ\n", diffs);
  // frames: the gateware's scanout and the board's reports, swap by swap
  if (gw_frames_.size() != sim_frames_.size())
    out += fmt::format("gateware scanned out {} frames, simulator {}\n", gw_frames_.size(), sim_frames_.size());
  for (std::size_t i = 0; i < gw_frames_.size() && i < sim_frames_.size(); ++i) {
    const auto& a = gw_frames_[i];
    const auto& b = sim_frames_[i];
    if (a.width != b.width || a.height != b.height || a.format != b.format || a.bytes != b.pixels) {
      out += fmt::format("frame {}: gateware {}x{} fmt {} crc {:08X}, simulator {}x{} fmt {} crc {:08X}", i + 1, a.width,
                         a.height, int(a.format), protocol::crc32(a.bytes), b.width, b.height, int(b.format), b.crc);
      std::size_t k = 0;
      while (k < a.bytes.size() && k < b.pixels.size() && a.bytes[k] == b.pixels[k]) ++k;
      if (k < a.bytes.size() && k < b.pixels.size())
        out += fmt::format("; first difference at byte {}: gateware 0x{:02X}, simulator 0x{:02X}", k, a.bytes[k], b.pixels[k]);
      out += "\n";
    }
  }
  for (std::size_t i = 0; i < board_frames_.size() && i < sim_frames_.size(); ++i) {
    const auto& a = *board_frames_[i];
    if (a.crc != sim_frames_[i].crc || (!a.pixels.empty() && a.pixels != sim_frames_[i].pixels))
      out += fmt::format("board frame {}: FRAME_CRC {:08X}, simulator {:08X}\n", i + 1, a.crc, sim_frames_[i].crc);
  }
  if (board_frames_.size() > sim_frames_.size()) out += "the board reported more frames than the simulator swapped\n";
  if (errors_too) {
    // Idle, STATUS holds still: read until two reads in a row agree, since an injected bit error
    // may still be pending and garble one read (into a read of another register, or a write).
    auto st = board_.backend->read_register(index_of(Reg::STATUS));
    for (int i = 0; i < 4 && st; ++i) {
      auto again = board_.backend->read_register(index_of(Reg::STATUS));
      if (!again || *again == *st) {
        st = again;
        break;
      }
      st = again;
    }
    if (!st) out += "STATUS read: " + st.error().message + "\n";
    else if ((*st >> 48) != sim_->errors())
      out += fmt::format("STATUS.ERRORS: gateware {}, simulator {}\n", protocol::describe_errors(std::uint16_t(*st >> 48)),
                         protocol::describe_errors(sim_->errors()));
  }
  const auto c = gateware().counters();
  if (c.sdram_violations) out += fmt::format("{} SDRAM timing violations\n", c.sdram_violations);
  return out;
}

}  // namespace gpubridge::test
