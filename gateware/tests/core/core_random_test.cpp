// Seeded random differential test of the render core: random render state (formats, buffers
// anywhere including overlapping and beyond VRAM, scissors, every TRI_MODE field), random
// triangles (small, large, slivers, far outside the screen) and clears, drawn by the Verilated
// core and by the simulator; video memory must be byte-identical after every batch and
// ERR_MEM_RANGE must agree. The seed is printed; GPUBRIDGE_RTL_SEED=<n> reproduces a run,
// GPUBRIDGE_RTL_BATCHES=<n> makes it longer.
#include <gtest/gtest.h>

#include <cstdlib>
#include <random>

#include "cosim.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "rtl_config.hpp"

namespace gpubridge::rtl {
namespace {

using protocol::Reg;

std::uint32_t env_u32(const char* name, std::uint32_t fallback) {
  const char* v = std::getenv(name);
  return v ? static_cast<std::uint32_t>(std::strtoul(v, nullptr, 0)) : fallback;
}

class RandomStream {
 public:
  RandomStream(std::uint32_t seed, std::uint64_t vram, std::uint8_t features)
      : rng_(seed), vram_(vram), features_(features) {}

  unsigned pick(unsigned n) { return std::uniform_int_distribution<unsigned>(0, n - 1)(rng_); }
  bool chance(double p) { return std::uniform_real_distribution<double>(0, 1)(rng_) < p; }
  std::uint32_t u32() { return static_cast<std::uint32_t>(rng_()); }

  // A 16-aligned buffer address: mostly inside VRAM, sometimes near its end or far beyond.
  std::uint32_t address(std::uint64_t length) {
    if (chance(0.03)) return 0xFFFFFFF0u - 16 * pick(64);
    if (chance(0.05)) return static_cast<std::uint32_t>((vram_ - 16 * pick(64)) & ~15ull);
    const std::uint64_t room = length < vram_ ? vram_ - length : 16;
    return static_cast<std::uint32_t>((u32() % room) & ~15ull);
  }

  void state(Cosim& cs) {
    width_ = 1 + pick(chance(0.2) ? 130 : 64);
    height_ = 1 + pick(chance(0.2) ? 90 : 48);
    unsigned fmt = pick(3);
    if (fmt == 1 && !(features_ & sim::FEATURE_RGB565)) fmt = 0;
    if (fmt == 2 && !(features_ & sim::FEATURE_RGBA2222)) fmt = 0;
    const unsigned bpp = fmt == 0 ? 4 : fmt == 1 ? 2 : 1;
    cs.write(Reg::FB_FORMAT, (std::uint64_t{fmt} << 32) | (std::uint64_t{height_} << 16) | width_);
    const std::uint64_t pixels = std::uint64_t{width_} * height_;
    const std::uint32_t draw = address(pixels * bpp);
    std::uint32_t z = address(pixels * 4);
    if (chance(0.1)) z = draw + 16 * pick(32);  // overlapping colour and depth: serial mode
    cs.write(Reg::FB_DRAW, draw);
    cs.write(Reg::FB_Z, z);
    std::uint64_t sc = 0;
    if (chance(0.7)) {
      sc = (std::uint64_t{height_ + pick(8)} << 48) | (std::uint64_t{width_ + pick(8)} << 32);
    } else {
      const unsigned x0 = pick(width_ + 4), y0 = pick(height_ + 4);
      sc = std::uint64_t{x0} | (std::uint64_t{y0} << 16) | (std::uint64_t{x0 + pick(width_ + 4)} << 32) |
           (std::uint64_t{y0 + pick(height_ + 4)} << 48);
    }
    cs.write(Reg::SCISSOR, sc);
    std::uint64_t mode = 0;
    mode |= pick(2);                     // GOURAUD
    mode |= std::uint64_t{pick(2)} << 2;  // Z_TEST
    mode |= std::uint64_t{chance(0.9) ? 1 + pick(7) : 0} << 3;  // Z_FUNC
    mode |= std::uint64_t{pick(2)} << 6;  // Z_WRITE
    if (features_ & sim::FEATURE_BLEND) mode |= std::uint64_t{chance(0.5) ? 0 : pick(4)} << 7;
    if (features_ & sim::FEATURE_DITHER) mode |= std::uint64_t{pick(2)} << 9;
    if ((features_ & sim::FEATURE_TEMPORAL_DITHER) && chance(0.5))
      mode |= (std::uint64_t{1} << 15) | (std::uint64_t{pick(16)} << 16);  // TEMPORAL, DITHER_PHASE
    if (chance(0.25)) mode |= std::uint64_t{pick(16)} << 10;  // write masks
    mode |= std::uint64_t{pick(2)} << 14;  // TEX_DECAL
    if (chance(0.5)) {
      mode |= 2;  // TEXTURED (refused, as by the soc, where the profile has no texture unit)
      const unsigned wl = 3 + pick(8), hl = 3 + pick(8);
      unsigned tfmt = pick(3);
      if (tfmt == 1 && !(features_ & sim::FEATURE_RGB565)) tfmt = 0;
      if (tfmt == 2 && !(features_ & sim::FEATURE_RGBA2222)) tfmt = 0;
      std::uint64_t tex_fmt = wl | (hl << 4) | (std::uint64_t{pick(3)} << 8) | (std::uint64_t{pick(3)} << 10) |
                              (std::uint64_t{tfmt} << 16);
      if ((features_ & sim::FEATURE_BILINEAR) && chance(0.5)) tex_fmt |= 1u << 12;
      const unsigned tbpp = tfmt == 0 ? 4 : tfmt == 1 ? 2 : 1;
      std::uint32_t tex = address((std::uint64_t{1} << (wl + hl)) * tbpp);
      if (chance(0.05)) tex = draw;  // sampling the buffer being drawn: serial mode
      cs.write(Reg::TEX_BASE, tex);
      cs.write(Reg::TEX_FMT, tex_fmt);
    }
    cs.write(Reg::TRI_MODE, mode);
  }

  std::int16_t coord(unsigned extent) {
    if (chance(0.04)) return static_cast<std::int16_t>(u32());  // anywhere in s12.4
    const int lo = -16 * 24, hi = 16 * int(extent + 24);
    int c = lo + int(pick(unsigned(hi - lo)));
    if (chance(0.4)) c &= ~7;  // on pixel centres and corners: exact edge cases
    return static_cast<std::int16_t>(c);
  }

  void triangle(Cosim& cs) {
    const bool sliver = chance(0.15);
    std::int16_t px[3], py[3];
    for (int i = 0; i < 3; ++i) {
      px[i] = coord(width_);
      py[i] = coord(height_);
      if (i > 0 && sliver) {
        px[i] = static_cast<std::int16_t>(px[0] + int(pick(9)) - 4 + (i == 2 ? int(pick(200)) : 0));
        py[i] = static_cast<std::int16_t>(py[0] + int(pick(9)) - 4 + (i == 1 ? int(pick(600)) : 0));
      } else if (i > 0 && chance(0.5)) {  // small triangles
        px[i] = static_cast<std::int16_t>(px[0] + int(pick(160)) - 80);
        py[i] = static_cast<std::int16_t>(py[0] + int(pick(160)) - 80);
      }
      // axis-aligned edges (top and bottom, left and right edges of the fill rule)
      if (i > 0 && chance(0.2)) py[i] = py[pick(i)];
      if (i > 0 && chance(0.2)) px[i] = px[pick(i)];
    }
    for (int i = 0; i < 3; ++i) {
      std::uint32_t rgba = u32();
      if (chance(0.2)) rgba |= 0xFF;  // opaque
      cs.write(Reg::COLOR, (std::uint64_t{u32()} << 32) | rgba);
      cs.write(Reg::TEXCOORD, (std::uint64_t{u32()} << 32) | u32());
      const std::uint32_t z = chance(0.3) ? 0x800000u + pick(16) : u32() & 0xFFFFFF;
      cs.write(Reg::VERTEX, (std::uint64_t{z} << 32) | (std::uint64_t{std::uint16_t(py[i])} << 16) | std::uint16_t(px[i]));
    }
  }

  void clear(Cosim& cs) {
    cs.write(Reg::CLEAR_COLOR, u32());
    cs.write(Reg::CLEAR_DEPTH, u32() & 0xFFFFFF);
    cs.write(chance(0.5) ? Reg::CLEAR : Reg::CLEAR_Z, 0);
  }

 private:
  std::mt19937 rng_;
  std::uint64_t vram_;
  std::uint8_t features_;
  unsigned width_ = 16, height_ = 16;
};

TEST(CoreRandom, DrawsAndClearsMatchSimulator) {
  const std::uint32_t seed = env_u32("GPUBRIDGE_RTL_SEED", std::random_device{}());
  const unsigned batches = env_u32("GPUBRIDGE_RTL_BATCHES", 60);
  std::printf("GPUBRIDGE_RTL_SEED=%u GPUBRIDGE_RTL_BATCHES=%u\n", seed, batches);
  sim::DeviceOptions o;
  o.vram_bytes = 64 * 1024;
  o.features = kCoreFeatures;
  Cosim cs(o, seed);
  RandomStream r(seed, o.vram_bytes, o.features);
  // memory starts random (texels, stale buffers)
  {
    std::mt19937 fill(seed ^ 0x5EEDu);
    std::vector<std::uint8_t> bytes(o.vram_bytes);
    for (auto& b : bytes) b = static_cast<std::uint8_t>(fill());
    cs.upload(0, bytes.data(), bytes.size());
  }
  for (unsigned b = 0; b < batches; ++b) {
    r.state(cs);
    cs.write(Reg::PRIM, 0);
    const unsigned n = 1 + r.pick(12);
    for (unsigned i = 0; i < n; ++i) {
      if (r.chance(0.1)) r.clear(cs);
      r.triangle(cs);
    }
    const std::string diff = cs.compare();
    ASSERT_TRUE(diff.empty()) << "seed " << seed << ", batch " << b << ":\n" << diff;
    ASSERT_EQ(cs.range_error_core(), cs.range_error_sim()) << "seed " << seed << ", batch " << b << ": ERR_MEM_RANGE";
  }
  const auto p = cs.core().perf();
  std::printf("%llu commands, %u triangles set up, %u pixels, %llu cycles\n",
              static_cast<unsigned long long>(cs.commands()), p.triangles, p.pixels,
              static_cast<unsigned long long>(cs.core().cycles()));
}

}  // namespace
}  // namespace gpubridge::rtl
