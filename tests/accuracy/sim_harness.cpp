// Register-frame driver of the simulator for the accuracy suite (see sim_harness.hpp).
#include "sim_harness.hpp"

#include <stdexcept>
#include <string>

#include "gpubridge/protocol/frame.hpp"
#if GPUBRIDGE_ACCURACY_GATEWARE
#include <gtest/gtest.h>

#include "gateware_board.hpp"
#else
namespace gpubridge::test {
class GatewareBoard {};  // only the gateware build of the suite has one
}  // namespace gpubridge::test
#endif

namespace gpubridge::accuracy {

using protocol::Reg;

geometry::DeviceVertex dv(int x16, int y16, std::uint32_t z, std::uint32_t rgba, std::uint32_t q, std::int32_t s,
                          std::int32_t t) {
  geometry::DeviceVertex v;
  v.x = static_cast<std::int16_t>(x16);
  v.y = static_cast<std::int16_t>(y16);
  v.z = z;
  v.rgba = rgba;
  v.q = q;
  v.s = s;
  v.t = t;
  return v;
}

geometry::DeviceTriangle to_device(const FixedTriangle& f) {
  geometry::DeviceTriangle t;
  for (int i = 0; i < 3; ++i) {
    const auto& c = f[i].rgba;
    t[i] = dv(f[i].x, f[i].y, f[i].z,
              (std::uint32_t{c[0]} << 24) | (std::uint32_t{c[1]} << 16) | (std::uint32_t{c[2]} << 8) | c[3], f[i].q,
              f[i].s, f[i].t);
  }
  return t;
}

namespace {
template <class T>
T must(Result<T> r, const char* what) {
  if (!r) throw std::runtime_error(std::string(what) + ": " + r.error().message);
  return std::move(r).value();
}
void must(Result<void> r, const char* what) {
  if (!r) throw std::runtime_error(std::string(what) + ": " + r.error().message);
}
std::uint32_t align16(std::uint64_t v) { return static_cast<std::uint32_t>((v + 15) & ~std::uint64_t{15}); }
}  // namespace

SimHarness::SimHarness(const Setup& setup) : setup_(setup) {
#if GPUBRIDGE_ACCURACY_GATEWARE
  // the gateware has the hardware's accuracy; threads only change how the simulator works
  if (!setup.knobs.exact()) throw std::runtime_error("accuracy knobs do not apply to the gateware");
  gateware_ = must(test::GatewareBoard::open(test::board_profile("ulx3s")), "gateware board");
  device_ = &gateware_->sim();
#else
  sim::DeviceOptions opt;
  opt.vram_bytes = 16u << 20;
  opt.threads = setup.threads;
  opt.accuracy = setup.knobs;
  own_device_ = must(sim::Device::create(opt), "sim::Device::create");
  device_ = own_device_.get();
#endif
  const std::uint64_t fb_bytes = std::uint64_t{setup.width} * setup.height * protocol::bytes_per_pixel(setup.format);
  z_base_ = align16(fb_bytes);
  tex_base_ = align16(z_base_ + std::uint64_t{setup.width} * setup.height * 4);
#if GPUBRIDGE_ACCURACY_GATEWARE
  gateware_->limit_compare(tex_base_ + (4u << 20));  // buffers and the largest texture of the suite
#endif
  write(Reg::FB_FORMAT, must(geometry::fb_format_word(setup.width, setup.height, setup.format), "FB_FORMAT"));
  write(Reg::FB_DRAW, must(geometry::address16_word(0), "FB_DRAW"));
  write(Reg::FB_Z, must(geometry::address16_word(z_base_), "FB_Z"));
  scissor(0, 0, 1024, 1024);
  clear();
}

SimHarness::~SimHarness() = default;
SimHarness::SimHarness(SimHarness&&) noexcept = default;

void SimHarness::send(const protocol::Frame& f) {
  if (!gateware_) {
    device_->write(f);
    return;
  }
#if GPUBRIDGE_ACCURACY_GATEWARE
  // The board backend owns RESET (Backend::reset()), HOST_TAG and the link registers, as for every
  // board: a RESET with its magic goes through reset(), on the wires both devices see; the other
  // writes to them (random register words) reach neither device.
  using protocol::index_of;
  if (!f.read && (f.index == index_of(Reg::RESET) || f.index == index_of(Reg::HOST_TAG) ||
                  f.index == index_of(Reg::LINK_CTRL) || f.index == index_of(Reg::LINK_CHECK))) {
    if (f.index == index_of(Reg::RESET) && f.data == protocol::kResetMagic) {
      flush();
      must(gateware_->backend().reset(), "reset");
      dirty_ = true;
    }
    return;
  }
#endif
  pending_.push_back(f);
  dirty_ = true;
  if (pending_.size() >= 4096) flush();
}

void SimHarness::flush() const {
#if GPUBRIDGE_ACCURACY_GATEWARE
  if (pending_.empty()) return;
  std::vector<std::uint8_t> wire;
  for (const auto& p : pending_) protocol::append(wire, p);
  pending_.clear();
  must(gateware_->backend().write_frames(protocol::FrameView{wire}), "write_frames");
#endif
}

void SimHarness::sync() const {
  dirty_ = false;
#if GPUBRIDGE_ACCURACY_GATEWARE
  if (!gateware_) return;
  flush();
  // the part of video memory this harness uses (framebuffer, depth, textures) is compared
  const std::string diff = gateware_->compare(/*errors_too=*/true);
  if (!diff.empty()) ADD_FAILURE() << "gateware and simulator differ:\n" << diff;
#endif
}

std::uint16_t SimHarness::device_errors() const {
  if (dirty_) sync();
  return device_->errors();
}

void SimHarness::write(Reg reg, std::uint64_t data) { send(protocol::write_frame(reg, data)); }

void SimHarness::clear(std::uint32_t rgba, std::uint32_t depth) {
  write(Reg::CLEAR_COLOR, rgba);
  write(Reg::CLEAR, 0);
  write(Reg::CLEAR_DEPTH, depth & 0xFFFFFFu);
  write(Reg::CLEAR_Z, 0);
}

void SimHarness::scissor(unsigned x0, unsigned y0, unsigned x1, unsigned y1) {
  write(Reg::SCISSOR, must(geometry::scissor_word(x0, y0, x1, y1), "SCISSOR"));
}

void SimHarness::state(const geometry::RenderState& s) { write(Reg::TRI_MODE, geometry::tri_mode_word(s)); }

void SimHarness::prim(protocol::PrimType type) { write(Reg::PRIM, static_cast<std::uint64_t>(type)); }

void SimHarness::vertex(const geometry::DeviceVertex& v) {
  write(Reg::COLOR, geometry::color_word(v));
  write(Reg::TEXCOORD, geometry::texcoord_word(v));
  write(Reg::VERTEX, geometry::vertex_word(v));
}

void SimHarness::draw(const geometry::DeviceTriangle& tri) {
  prim(protocol::PrimType::List);
  for (const auto& v : tri) vertex(v);
}

void SimHarness::draw(std::span<const geometry::DeviceTriangle> tris) {
  prim(protocol::PrimType::List);
  // Encoded by the host library exactly as a client sends them.
  std::vector<protocol::Frame> frames;
  for (const auto& t : tris) geometry::encode_triangle(t, true, frames);
  for (const auto& f : frames) send(f);
}

void SimHarness::texture(const std::vector<std::uint8_t>& bytes, const geometry::TextureFormat& fmt) {
  std::vector<protocol::Frame> frames;
  must(geometry::encode_upload(tex_base_, bytes, frames), "texture upload");
  for (const auto& f : frames) send(f);
  write(Reg::TEX_BASE, must(geometry::address16_word(tex_base_), "TEX_BASE"));
  write(Reg::TEX_FMT, must(geometry::tex_fmt_word(fmt), "TEX_FMT"));
}

protocol::Rgba8 SimHarness::color(int x, int y) const {
  if (dirty_) sync();
  device_->drain();
  const auto mem = static_cast<const sim::Device&>(*device_).memory();
  const unsigned bpp = protocol::bytes_per_pixel(setup_.format);
  return protocol::load_pixel(setup_.format, mem.data() + (std::size_t(y) * setup_.width + x) * bpp);
}

std::uint32_t SimHarness::depth(int x, int y) const {
  if (dirty_) sync();
  device_->drain();
  const auto mem = static_cast<const sim::Device&>(*device_).memory();
  const std::uint8_t* p = mem.data() + z_base_ + (std::size_t(y) * setup_.width + x) * 4;
  return ((std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3]) & 0xFFFFFFu;
}

std::vector<std::uint8_t> SimHarness::color_bytes() const {
  if (dirty_) sync();
  device_->drain();
  const auto mem = static_cast<const sim::Device&>(*device_).memory();
  const std::size_t n = std::size_t{setup_.width} * setup_.height * protocol::bytes_per_pixel(setup_.format);
  return {mem.begin(), mem.begin() + n};
}

std::vector<std::uint8_t> SimHarness::depth_bytes() const {
  if (dirty_) sync();
  device_->drain();
  const auto mem = static_cast<const sim::Device&>(*device_).memory();
  const std::size_t n = std::size_t{setup_.width} * setup_.height * 4;
  return {mem.begin() + z_base_, mem.begin() + z_base_ + n};
}

std::vector<int> SimHarness::hit_counts(std::span<const geometry::DeviceTriangle> tris) {
  clear(0x00000000u);
  geometry::RenderState counting;
  counting.gouraud = false;
  counting.blend = protocol::BlendMode::Add;
  state(counting);
  std::vector<geometry::DeviceTriangle> red(tris.begin(), tris.end());
  for (auto& t : red)
    for (auto& v : t) v.rgba = 0x01000000u;
  draw(red);
  std::vector<int> counts(std::size_t{setup_.width} * setup_.height);
  for (unsigned y = 0; y < setup_.height; ++y)
    for (unsigned x = 0; x < setup_.width; ++x) counts[std::size_t{y} * setup_.width + x] = color(int(x), int(y)).r;
  return counts;
}

std::vector<int> reference_hit_counts(std::span<const geometry::DeviceTriangle> tris, const PixelRect& clip,
                                      unsigned width, unsigned height) {
  std::vector<int> counts(std::size_t{width} * height);
  for (const auto& t : tris)
    for (const auto& s : rasterize(to_fixed(t), clip)) counts[std::size_t(s.y) * width + s.x] += 1;
  return counts;
}

}  // namespace gpubridge::accuracy
