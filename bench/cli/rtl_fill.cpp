#include "rtl_fill.hpp"

#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "gpubridge/rtl/rtl_device.hpp"
#include "gpubridge/rtl/simulator_options.hpp"
#include "gpubridge/sim/device.hpp"
#include "gpubridge/sim/options.hpp"
#include "gpubridge/sim/run_stream.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "gpubridge/usb/emu/rtl_pins.hpp"

namespace gpubridge::cli {
namespace {

using protocol::Reg;

constexpr unsigned kTexLog2 = 6;  // 64 x 64 RGBA8888, as the core bench
constexpr std::uint32_t kTexBytes = 4u << (2 * kTexLog2);

geometry::RenderState state(bool gouraud, bool depth, protocol::BlendMode blend = protocol::BlendMode::Off,
                            bool textured = false, bool dither = false) {
  geometry::RenderState s;
  s.gouraud = gouraud;
  s.z_test = s.z_write = depth;  // LESS
  s.blend = blend;
  s.textured = textured;
  s.dither = dither;
  return s;
}

// The core bench's classes (gateware/tests/core/core_bench.cpp), in its order and with its names.
const std::vector<FillClass>& classes() {
  using protocol::BlendMode;
  using protocol::PixelFormat;
  static const std::vector<FillClass> all = {
      {"fill RGBA8888 flat", PixelFormat::RGBA8888, state(false, false)},
      {"fill RGB565 flat", PixelFormat::RGB565, state(false, false)},
      {"fill RGBA2222 flat", PixelFormat::RGBA2222, state(false, false)},
      {"RGBA8888 Gouraud", PixelFormat::RGBA8888, state(true, false)},
      {"RGBA8888 flat, Z test + write", PixelFormat::RGBA8888, state(false, true)},
      {"RGBA8888 Gouraud, Z test + write", PixelFormat::RGBA8888, state(true, true)},
      {"RGBA2222 Gouraud, dithered", PixelFormat::RGBA2222, state(true, false, BlendMode::Off, false, true)},
      {"RGBA8888 alpha blend", PixelFormat::RGBA8888, state(true, false, BlendMode::Alpha)},
      {"RGBA8888 textured nearest (64x64 RGBA8888)", PixelFormat::RGBA8888, state(false, false, BlendMode::Off, true)},
      {"RGBA8888 textured bilinear (64x64 RGBA8888)", PixelFormat::RGBA8888, state(false, false, BlendMode::Off, true),
       true},
      // Into a 2-byte buffer (the ULX3S shows RGB565 at 640 x 480): the colour writes take one bus
      // clock a pixel instead of two, so the texel fetches and the core's own rate bind.
      {"RGB565 textured nearest (64x64 RGBA8888)", PixelFormat::RGB565, state(false, false, BlendMode::Off, true)},
      {"RGB565 textured bilinear (64x64 RGBA8888)", PixelFormat::RGB565, state(false, false, BlendMode::Off, true),
       true},
  };
  return all;
}

unsigned bpp_of(const FillClass& c) { return protocol::bytes_per_pixel(c.format); }
bool has_depth(const FillClass& c) { return c.state.z_test; }
bool has_texture(const FillClass& c) { return c.state.textured; }
bool has_blend(const FillClass& c) { return c.state.blend != protocol::BlendMode::Off; }

bool supported(const FillClass& c, std::uint32_t features) {
  if (c.format == protocol::PixelFormat::RGB565 && !(features & sim::FEATURE_RGB565)) return false;
  if (c.format == protocol::PixelFormat::RGBA2222 && !(features & sim::FEATURE_RGBA2222)) return false;
  if (has_texture(c) && !(features & sim::FEATURE_TEXTURE)) return false;
  if (c.bilinear && !(features & sim::FEATURE_BILINEAR)) return false;
  if (has_blend(c) && !(features & sim::FEATURE_BLEND)) return false;
  return true;
}

// The ecp5's SDRAM controller maps word address bits [9:8] to the bank (sdram_ctrl.v: a row holds
// 1 KiB, consecutive rows rotate through the 4 banks). A depth buffer in the colour buffer's bank
// reopens a row at every depth and colour access (measured at 64 x 48: 0.095 instead of 0.144
// px/clock for RGBA8888 + Z); placed 2 KiB off modulo 4 KiB (and 4 bytes a pixel like the colour)
// it stays two banks away, as a host that knows the memory places it. The texture (read through
// the texel cache) starts a bank further.
std::uint32_t in_bank(std::uint64_t after, unsigned bank) {
  return static_cast<std::uint32_t>(((after + 4095) & ~std::uint64_t{4095}) + bank * 1024u);
}

// Colour at 0, then the depth buffer, then the texture.
struct Layout {
  std::uint32_t depth = 0, texture = 0, end = 0;
};
Layout layout(const FillClass& c, unsigned w, unsigned h) {
  Layout l;
  const std::uint64_t colour = std::uint64_t{w} * h * bpp_of(c);
  l.depth = in_bank(colour, 2);
  const std::uint64_t depth_end = has_depth(c) ? l.depth + std::uint64_t{w} * h * 4 : colour;
  l.texture = in_bank(depth_end, 1);
  l.end = has_texture(c) ? l.texture + kTexBytes : static_cast<std::uint32_t>(depth_end);
  return l;
}

// Every size here (at most 640 x 480, 16-byte aligned addresses) is one the encoders accept.
FillDraw make_draw(const FillClass& c, unsigned w, unsigned h) {
  FillDraw d{c, w, h, {}, {}};
  const Layout l = layout(c, w, h);
  {
    protocol::CommandStreamWriter s(d.setup);
    s.write(Reg::FB_FORMAT, *geometry::fb_format_word(w, h, c.format));
    s.write(Reg::FB_DRAW, *geometry::address16_word(0));
    s.write(Reg::FB_Z, *geometry::address16_word(l.depth));
    s.write(Reg::SCISSOR, *geometry::scissor_word(0, 0, w, h));
    if (has_depth(c)) {  // the depth test LESS passes against the far plane everywhere
      s.write(Reg::CLEAR_DEPTH, 0xFFFFFF);
      s.write(Reg::CLEAR_Z, 0);
    }
    if (has_texture(c)) {
      std::vector<std::uint8_t> texels(kTexBytes);
      for (std::size_t i = 0; i < texels.size(); ++i) texels[i] = static_cast<std::uint8_t>(i * 37 + (i >> 8));
      s.upload(l.texture, std::move(texels));
      s.write(Reg::TEX_BASE, *geometry::address16_word(l.texture));
      geometry::TextureFormat tf;
      tf.width = tf.height = 1u << kTexLog2;
      tf.bilinear = c.bilinear;
      s.write(Reg::TEX_FMT, *geometry::tex_fmt_word(tf));
    }
    s.write(Reg::TRI_MODE, geometry::tri_mode_word(c.state));
    s.write(Reg::PRIM, 0);  // list
    s.flush();
  }
  protocol::CommandStreamWriter s(d.draw);
  // The core bench's rectangle scaled to w x h: the texture repeats at half a texel per pixel
  // (S reaches w / 128, T h / 128 in 8.24), the colours and depths are its.
  const auto X = static_cast<std::int16_t>(w * 16), Y = static_cast<std::int16_t>(h * 16);
  const std::int32_t S = std::int32_t(w) << 17, T = std::int32_t(h) << 17;
  auto vertex = [](std::int16_t x, std::int16_t y, std::uint32_t z, std::uint32_t rgba, std::int32_t st, std::int32_t tt) {
    return geometry::DeviceVertex{x, y, z, rgba, 0xFFFFFFFFu, st, tt};
  };
  const geometry::DeviceVertex a = vertex(0, 0, 100, 0xFF0000FF, 0, 0), b = vertex(X, 0, 200, 0x00FF00FF, S, 0),
                               e = vertex(X, Y, 300, 0x0000FFFF, S, T), f = vertex(0, Y, 400, 0xFFFFFF80, 0, T);
  geometry::encode_triangle({a, b, e}, has_texture(c), s.frames());
  geometry::encode_triangle({a, e, f}, has_texture(c), s.frames());
  s.flush();
  return d;
}

// Sends the stream (the driver's flow control on the BUSY pin and FIFO level included); no flush:
// its STATUS polls are bounded in count, and a large draw outlasts them. drain() waits instead.
Result<void> play(usb::BoardBackend& board, const protocol::CommandStream& stream) {
  for (const auto& tc : stream.commands) {
    if (const auto* f = std::get_if<protocol::FramesCmd>(&tc.command)) {
      if (auto r = board.write_frames(f->view()); !r) return r.error();
    } else if (const auto* u = std::get_if<protocol::UploadCmd>(&tc.command)) {
      if (auto r = board.upload(u->address, u->data); !r) return r.error();
    }
  }
  return {};
}

// Runs the device's clock until it has had no work clock (command, core or MEM_* unit) for 256
// clocks: everything sent so far is done. Bounded: a device that never settles is an error.
Result<void> drain(rtl::RtlDevice& dev) {
  for (int i = 0; i < 1 << 20; ++i) {
    const auto before = dev.counters().work_cycles;
    dev.idle_clocks(256);
    if (dev.counters().work_cycles == before) return {};
  }
  return make_error("the device did not become idle within 2^28 clocks");
}

}  // namespace

std::vector<FillDraw> fill_draws(const rtl::GatewareCaps& caps, bool quick) {
  static constexpr unsigned kSizes[][2] = {{640, 480}, {320, 240}, {320, 200}, {256, 128}, {192, 80}};
  std::vector<FillDraw> out;
  for (const auto& c : classes()) {
    if (!supported(c, caps.features)) continue;
    if (has_depth(c) && !(caps.features2 & sim::FEATURE2_DEPTH)) continue;  // CAPS2 (protocol 1.4)
    if (quick) {
      out.push_back(make_draw(c, 64, 48));
      continue;
    }
    for (const auto& [w, h] : kSizes)
      if (w <= caps.max_width && h <= caps.max_height && layout(c, w, h).end <= std::uint64_t{caps.vram_kib} * 1024) {
        out.push_back(make_draw(c, w, h));
        break;
      }
  }
  return out;
}

Result<std::vector<FillResult>> measure_fill(rtl::GatewareProfile profile, bool quick, const std::filesystem::path& config_dir) {
  const rtl::GatewareCaps caps = rtl::caps_of(profile);
  auto board_profile = usb::find_board_profile(config_dir, profile == rtl::GatewareProfile::Up5k ? "icebreaker" : "ulx3s");
  if (!board_profile) return board_profile.error();
  board_profile->scanout = usb::ScanoutMode::CrcOnly;
  std::vector<FillResult> out;
  for (const FillDraw& d : fill_draws(caps, quick)) {
    usb::emu::EmulationOptions eo;
    eo.pins = usb::emu::rtl_pins();
    auto board = usb::emu::open_emulated_board(*board_profile, eo);
    if (!board) return board.error();
    rtl::RtlDevice& dev = usb::emu::rtl_pins_of(*board->stack)->device();
    auto fail = [&](const Error& e) { return make_error(d.cls.name + ": " + e.message); };
    if (auto r = play(*board->backend, d.setup); !r) return fail(r.error());
    if (auto r = drain(dev); !r) return fail(r.error());
    const rtl::RtlCounters c0 = dev.counters();
    if (auto r = play(*board->backend, d.draw); !r) return fail(r.error());
    if (auto r = drain(dev); !r) return fail(r.error());
    const rtl::RtlCounters c = dev.counters() - c0;
    if (c.sdram_violations) return fail(make_error("the SDRAM model saw timing violations"));
    // The simulator, the judge of every co-simulation, plays the same streams: a class that is
    // fast because it draws wrong (texels, the RGB565 packing) shows as differing bytes.
    auto judge = sim::Device::create(rtl::simulator_options(dev.caps()));
    if (!judge) return fail(judge.error());
    if (auto r = sim::run_stream(**judge, d.setup); !r) return fail(r.error());
    if (auto r = sim::run_stream(**judge, d.draw); !r) return fail(r.error());
    const std::uint32_t used = layout(d.cls, d.width, d.height).end;  // colour, depth, texture
    std::vector<std::uint8_t> vram(used);
    dev.read_vram(0, vram.data(), vram.size());
    const auto expected = (*judge)->memory().first(used);
    std::uint64_t differing = 0;
    for (std::size_t i = 0; i < vram.size(); ++i) differing += vram[i] != expected[i];
    FillResult f;
    f.name = d.cls.name;
    f.width = d.width;
    f.height = d.height;
    f.bytes_per_pixel = bpp_of(d.cls);
    f.depth = has_depth(d.cls);
    f.blend = has_blend(d.cls);
    f.textured = has_texture(d.cls);
    f.bilinear = d.cls.bilinear;
    f.pixels = c.pixels;
    // the drain's quiet tail is not work; the work counter also holds the draw's command decode
    f.draw_clocks = c.work_cycles;
    f.core_busy_clocks = c.core_busy_cycles;
    f.setup_clocks = c.setup_cycles;
    f.mem_stall_clocks = c.core_mem_stalls;
    f.refreshes = c.refreshes;
    f.bytes_compared = used;
    f.bytes_differing = differing;
    if (f.draw_clocks) f.px_per_clock = double(f.pixels) / double(f.draw_clocks);
    f.mpixel_per_s = f.px_per_clock * caps.core_hz / 1e6;
    out.push_back(f);
  }
  return out;
}

}  // namespace gpubridge::cli
