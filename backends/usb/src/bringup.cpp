#include "gpubridge/usb/bringup.hpp"

#include <chrono>
#include <random>

#include <fmt/format.h>

#include "gpubridge/common/image.hpp"
#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/sim/device.hpp"

namespace gpubridge::usb {
namespace {

using protocol::Frame;
using protocol::Reg;

class Timer {
 public:
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count(); }

 private:
  std::chrono::steady_clock::time_point t0_ = std::chrono::steady_clock::now();
};

std::vector<std::uint8_t> frames_bytes(std::initializer_list<Frame> frames) {
  std::vector<std::uint8_t> out;
  for (const auto& f : frames) protocol::append(out, f);
  return out;
}

BringupStep id_check(BoardBackend& b) {
  BringupStep s{"id", false, false, "", 0};
  const auto i = b.info();
  s.ok = (i.id >> 32) == protocol::kIdMagic && protocol::protocol_major(i.id) == protocol::kVersionMajor;
  s.detail = fmt::format("ID 0x{:016X} (spigpu v{}.{}, variant 0x{:04X}); CAPS: {} KiB VRAM, FIFO {}, max {}x{}, {}", i.id,
                         protocol::protocol_major(i.id), protocol::protocol_minor(i.id), protocol::id_variant(i.id), i.caps & 0xFFFFFF, (i.caps >> 46) & 0x3FF,
                         i.max_width, i.max_height,
                         protocol::has_depth_buffer(i.id, i.caps2) ? "depth buffer" : "no depth buffer (CAPS2)");
  return s;
}

// FENCE is a queued read-write register: written values read back once executed.
BringupStep register_echo(BoardBackend& b) {
  BringupStep s{"register-echo", true, false, "", 0};
  Timer t;
  std::vector<std::uint64_t> patterns = {0, ~0ull, 0x5555555555555555ull, 0xAAAAAAAAAAAAAAAAull};
  for (int bit = 0; bit < 64; ++bit) patterns.push_back(1ull << bit);
  for (auto p : patterns) {
    const auto bytes = frames_bytes({protocol::write_frame(Reg::FENCE, p)});
    if (auto r = b.write_frames(protocol::FrameView{bytes}); !r) {
      s.ok = false;
      s.detail = r.error().message;
      return s;
    }
    if (auto r = b.flush(); !r) {
      s.ok = false;
      s.detail = r.error().message;
      return s;
    }
    auto v = b.read_register(protocol::index_of(Reg::FENCE));
    if (!v || *v != p) {
      s.ok = false;
      s.detail = v ? fmt::format("FENCE wrote 0x{:016X}, read 0x{:016X}", p, *v) : v.error().message;
      return s;
    }
  }
  s.detail = fmt::format("{} patterns through FENCE (walking ones, 0, ~0, 0x55.., 0xAA..)", patterns.size());
  s.seconds = t.seconds();
  return s;
}

BringupStep memory_test(BoardBackend& b, const BringupOptions& o) {
  BringupStep s{"memory", true, false, "", 0};
  Timer t;
  const std::uint64_t vram = b.info().vram_bytes;
  const std::uint32_t base = o.mem_base & ~7u;
  if (base >= vram) {
    s.ok = false;
    s.detail = fmt::format("range starts at 0x{:X}, beyond video memory ({} bytes)", base, vram);
    return s;
  }
  const std::uint32_t len = static_cast<std::uint32_t>(std::min<std::uint64_t>(o.mem_bytes & ~7u, vram - base));
  auto fail = [&](std::string d) {
    s.ok = false;
    s.detail = std::move(d);
    return s;
  };
  // Data lines: walking ones across a 64-bit word.
  std::vector<std::uint8_t> walk(64 * 8);
  for (int bit = 0; bit < 64 && bit * 8 + 8 <= static_cast<int>(len); ++bit)
    for (int k = 0; k < 8; ++k) walk[static_cast<std::size_t>(bit * 8 + k)] = static_cast<std::uint8_t>((1ull << bit) >> (56 - 8 * k));
  walk.resize(std::min<std::size_t>(walk.size(), len));
  if (auto r = b.upload(base, walk); !r) return fail(r.error().message);
  auto back = b.readback(base, static_cast<std::uint32_t>(walk.size()));
  if (!back) return fail(back.error().message);
  if (*back != walk) return fail("data-line walking ones mismatch at 0x" + fmt::format("{:X}", base));
  if (o.progress) o.progress("memory", 10);
  // Address lines: a distinct marker at base + 2^k for every k, then all read back (aliasing).
  std::vector<std::uint32_t> offsets = {0};
  for (std::uint32_t off = 8; off < len; off <<= 1) offsets.push_back(off);
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    std::vector<std::uint8_t> marker(8, static_cast<std::uint8_t>(0xA0 + i));
    marker[0] = static_cast<std::uint8_t>(i);
    if (auto r = b.upload(base + offsets[i], marker); !r) return fail(r.error().message);
  }
  for (std::size_t i = 0; i < offsets.size(); ++i) {
    auto m = b.readback(base + offsets[i], 8);
    if (!m) return fail(m.error().message);
    if ((*m)[0] != static_cast<std::uint8_t>(i))
      return fail(fmt::format("address line fault: 0x{:X} reads the marker of offset index {}", base + offsets[i], (*m)[0]));
  }
  if (o.progress) o.progress("memory", 20);
  // Whole range, pseudo-random, in chunks with progress.
  std::mt19937 rng(0x6b1d);
  const std::uint32_t chunk = 16 * 1024;
  for (std::uint32_t off = 0; off < len; off += chunk) {
    const std::uint32_t n = std::min(chunk, len - off);
    std::vector<std::uint8_t> data(n);
    for (auto& x : data) x = static_cast<std::uint8_t>(rng());
    if (auto r = b.upload(base + off, data); !r) return fail(r.error().message);
    auto got = b.readback(base + off, n);
    if (!got) return fail(got.error().message);
    if (*got != data) {
      std::size_t k = 0;
      while ((*got)[k] == data[k]) ++k;
      return fail(fmt::format("pattern mismatch at 0x{:X}: wrote 0x{:02X}, read 0x{:02X}", base + off + k, data[k], (*got)[k]));
    }
    if (o.progress) o.progress("memory", 20 + static_cast<unsigned>(80ull * (off + n) / len));
  }
  s.detail = fmt::format("{} bytes at 0x{:X}: data lines, {} address lines, pattern", len, base, offsets.size() - 1);
  s.seconds = t.seconds();
  return s;
}

// Highest SCK at which N iterations of ID reads and a verified memory round trip all pass.
BringupStep clock_sweep(BoardBackend& b, const BringupOptions& o, std::uint32_t& best) {
  BringupStep s{"spi-clock", false, false, "", 0};
  Timer t;
  std::vector<std::uint32_t> clocks = o.clocks;
  if (clocks.empty())
    for (std::uint32_t c : {30'000'000u, 20'000'000u, 15'000'000u, 12'000'000u, 10'000'000u, 7'500'000u, 6'000'000u,
                            3'000'000u, 1'500'000u, 1'000'000u})
      if (c <= (o.max_clock_hz ? o.max_clock_hz : b.profile().spi_clock_hz)) clocks.push_back(c);
  const std::uint64_t id = b.info().id;
  std::string tried;
  best = 0;
  for (auto want : clocks) {
    auto actual = b.bridge().set_clock(want);
    if (!actual) continue;
    bool pass = true;
    for (unsigned i = 0; i < o.clock_iterations && pass; ++i) {
      auto v = b.read_register(protocol::index_of(Reg::ID));
      pass = v && *v == id;
      std::vector<std::uint8_t> data(256);
      for (std::size_t k = 0; k < data.size(); ++k) data[k] = static_cast<std::uint8_t>(k * 7 + i);
      pass = pass && b.upload(o.mem_base & ~7u, data);
      auto got = pass ? b.readback(o.mem_base & ~7u, 256) : Result<std::vector<std::uint8_t>>(Error{});
      pass = pass && got && *got == data;
    }
    tried += fmt::format("{}{:.3g} MHz {}", tried.empty() ? "" : ", ", *actual / 1e6, pass ? "ok" : "FAIL");
    if (pass) {
      best = *actual;
      break;
    }
  }
  if (best) (void)b.bridge().set_clock(best);
  s.ok = best != 0;
  s.detail = (best ? fmt::format("highest passing SCK {:.3g} MHz", best / 1e6) : std::string("no clock passed")) + " (" + tried + ")";
  s.seconds = t.seconds();
  return s;
}

struct Scene {
  const char* name;
  std::vector<std::uint8_t> frames;
};

// Scenes built from CLEAR and SCISSOR only: every design implements them, so they check the
// command path, scanout and FRAME_CRC without depending on rasteriser details.
std::vector<Scene> test_scenes(unsigned w, unsigned h, std::uint32_t fb) {
  auto scissor = [](unsigned x0, unsigned y0, unsigned x1, unsigned y1) {
    return std::uint64_t{y1} << 48 | std::uint64_t{x1} << 32 | std::uint64_t{y0} << 16 | x0;
  };
  const std::uint64_t format = (std::uint64_t{h} << 16) | w;
  std::vector<Scene> scenes;
  scenes.push_back({"solid", frames_bytes({protocol::write_frame(Reg::FB_FORMAT, format), protocol::write_frame(Reg::FB_DRAW, fb),
                                           protocol::write_frame(Reg::SCISSOR, scissor(0, 0, w, h)),
                                           protocol::write_frame(Reg::CLEAR_COLOR, 0x2060A0FF), protocol::write_frame(Reg::CLEAR, 0),
                                           protocol::write_frame(Reg::FB_DISPLAY, fb)})});
  std::vector<Frame> bars = {protocol::write_frame(Reg::FB_FORMAT, format), protocol::write_frame(Reg::FB_DRAW, fb)};
  const std::uint32_t colors[] = {0xFFFFFFFF, 0xFFFF00FF, 0x00FFFFFF, 0x00FF00FF, 0xFF00FFFF, 0xFF0000FF, 0x0000FFFF, 0x000000FF};
  for (unsigned i = 0; i < 8; ++i) {
    bars.push_back(protocol::write_frame(Reg::SCISSOR, scissor(w * i / 8, 0, w * (i + 1) / 8, h)));
    bars.push_back(protocol::write_frame(Reg::CLEAR_COLOR, colors[i]));
    bars.push_back(protocol::write_frame(Reg::CLEAR, 0));
  }
  bars.push_back(protocol::write_frame(Reg::FB_DISPLAY, fb));
  std::vector<std::uint8_t> bb;
  for (const auto& f : bars) protocol::append(bb, f);
  scenes.push_back({"colour-bars", std::move(bb)});
  return scenes;
}

BringupStep scenes_step(BoardBackend& b, const BringupOptions& o) {
  BringupStep s{"scenes", true, false, "", 0};
  Timer t;
  const auto info = b.info();
  const unsigned w = std::min(64u, info.max_width), h = std::min(48u, info.max_height);
  const std::uint32_t fb = 0;
  sim::DeviceOptions so;
  so.vram_bytes = std::max<std::uint64_t>(64 * 1024, (std::uint64_t{w} * h * 4 + 1023) / 1024 * 1024);
  std::string detail;
  for (const auto& scene : test_scenes(w, h, fb)) {
    auto ref = sim::Device::create(so);
    if (!ref) {
      s.ok = false;
      s.detail = ref.error().message;
      return s;
    }
    std::shared_ptr<const backends::ScanoutFrame> want, got;
    (*ref)->set_scanout_callback([&](auto f) { want = std::move(f); });
    (*ref)->write(protocol::FrameView{scene.frames});
    (*ref)->drain();
    b.set_scanout_callback([&](auto f) { got = std::move(f); });
    auto r = b.write_frames(protocol::FrameView{scene.frames});
    b.set_scanout_callback(nullptr);
    if (!r || !got || !want) {
      s.ok = false;
      s.detail = std::string(scene.name) + ": " + (!r ? r.error().message : "no scanout frame");
      return s;
    }
    bool match = got->crc == want->crc;
    if (o.readback && !got->pixels.empty()) {
      const bool pixels_match = got->pixels == want->pixels;
      if (!pixels_match && !o.diff_dir.empty()) {
        Image a = image_from_device(got->format, got->width, got->height, got->pixels);
        const Image e = image_from_device(want->format, want->width, want->height, want->pixels);
        for (std::size_t k = 0; k + 3 < a.rgba.size() && k + 3 < e.rgba.size(); k += 4) {
          const bool same = std::equal(a.rgba.begin() + static_cast<std::ptrdiff_t>(k), a.rgba.begin() + static_cast<std::ptrdiff_t>(k + 4),
                                       e.rgba.begin() + static_cast<std::ptrdiff_t>(k));
          a.rgba[k] = same ? 0 : 255;
          a.rgba[k + 1] = a.rgba[k + 2] = 0;
          a.rgba[k + 3] = 255;
        }
        (void)save_png(std::filesystem::path(o.diff_dir) / (std::string(scene.name) + "-diff.png"), a);
      }
      match = match && pixels_match;
    }
    detail += fmt::format("{}{}: board 0x{:08X} sim 0x{:08X} {}", detail.empty() ? "" : "; ", scene.name, got->crc, want->crc,
                          match ? "match" : "MISMATCH");
    s.ok = s.ok && match;
  }
  s.detail = detail;
  s.seconds = t.seconds();
  return s;
}

}  // namespace

BringupReport run_bringup(BoardBackend& board, const BringupOptions& opts) {
  BringupReport rep;
  rep.steps.push_back(id_check(board));
  if (!rep.steps.back().ok) return rep;
  rep.steps.push_back(register_echo(board));
  rep.steps.push_back(memory_test(board, opts));
  rep.steps.push_back(clock_sweep(board, opts, rep.best_clock_hz));
  rep.steps.push_back(scenes_step(board, opts));
  return rep;
}

}  // namespace gpubridge::usb
