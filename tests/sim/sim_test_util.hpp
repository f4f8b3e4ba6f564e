#pragma once
// Helpers for driving the simulator through register frames, as real clients do.
#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/pixel.hpp"
#include "gpubridge/sim/device.hpp"

namespace gpubridge::sim::test {

using protocol::Reg;

inline std::unique_ptr<Device> make_device(DeviceOptions o = {}) {
  auto d = Device::create(o);
  EXPECT_TRUE(d.ok()) << (d.ok() ? "" : d.error().message);
  return std::move(d.value());
}

// `--accuracy preview` with `threads` threads (preview_test.cpp, preview_small_test.cpp).
inline DeviceOptions preview_options(unsigned threads) {
  DeviceOptions o;
  o.threads = threads;
  o.accuracy.preview = true;
  return o;
}

inline void w(Device& d, Reg r, std::uint64_t data) { d.write(protocol::write_frame(r, data)); }
inline std::uint64_t rd(Device& d, Reg r) { return d.read(protocol::index_of(r)); }
inline std::uint16_t errors_of(Device& d) { return static_cast<std::uint16_t>(rd(d, Reg::STATUS) >> 48); }

// VERTEX data from 1/16-pixel coordinates.
inline std::uint64_t vtx(int x16, int y16, std::uint32_t z = 0) {
  return (std::uint64_t{z & 0xFFFFFF} << 32) | (std::uint64_t{static_cast<std::uint16_t>(y16)} << 16) |
         static_cast<std::uint16_t>(x16);
}
inline std::uint64_t color(std::uint32_t rgba, std::uint32_t q = 0xFFFFFFFFu) {
  return (std::uint64_t{q} << 32) | rgba;
}
inline std::uint64_t fb_format(unsigned w, unsigned h, unsigned fmt = 0) {
  return (std::uint64_t{fmt} << 32) | (std::uint64_t{h} << 16) | w;
}
inline std::uint64_t scissor(unsigned x0, unsigned y0, unsigned x1, unsigned y1) {
  return (std::uint64_t{y1} << 48) | (std::uint64_t{x1} << 32) | (std::uint64_t{y0} << 16) | x0;
}

// A small framebuffer at address 0 (colour) and 0x100000 (depth), cleared to 0.
struct Canvas {
  std::unique_ptr<Device> dev;
  unsigned width, height, fmt;
  static constexpr std::uint32_t kZBase = 0x100000;
  Canvas(unsigned wdt, unsigned hgt, unsigned format = 0, DeviceOptions o = {})
      : dev(make_device(o)), width(wdt), height(hgt), fmt(format) {
    w(*dev, Reg::FB_FORMAT, fb_format(wdt, hgt, format));
    w(*dev, Reg::FB_DRAW, 0);
    w(*dev, Reg::FB_Z, kZBase);
    w(*dev, Reg::CLEAR_COLOR, 0);
    w(*dev, Reg::CLEAR, 0);
    w(*dev, Reg::CLEAR_Z, 0);
  }
  unsigned bpp() const { return protocol::bytes_per_pixel(static_cast<protocol::PixelFormat>(fmt)); }
  const std::uint8_t* px(unsigned x, unsigned y) const { return dev->memory().data() + (y * width + x) * bpp(); }
  std::uint32_t rgba(unsigned x, unsigned y) const {
    const auto* p = px(x, y);
    return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
  }
  std::uint32_t depth(unsigned x, unsigned y) const {
    const auto* p = dev->memory().data() + kZBase + (y * width + x) * 4;
    return ((std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3]);
  }
  std::vector<std::uint8_t> color_bytes() const {
    auto m = dev->memory();
    return {m.begin(), m.begin() + std::size_t{width} * height * bpp()};
  }
  unsigned count_nonzero() const {
    unsigned n = 0;
    for (unsigned y = 0; y < height; ++y)
      for (unsigned x = 0; x < width; ++x) {
        bool any = false;
        for (unsigned b = 0; b < bpp(); ++b) any |= px(x, y)[b] != 0;
        n += any;
      }
    return n;
  }
  // One triangle with per-vertex colour, list primitive.
  void tri(int x0, int y0, int x1, int y1, int x2, int y2, std::uint32_t c0 = 0xFFFFFFFF, std::uint32_t c1 = 0xFFFFFFFF,
           std::uint32_t c2 = 0xFFFFFFFF, std::uint32_t z0 = 0, std::uint32_t z1 = 0, std::uint32_t z2 = 0) {
    w(*dev, Reg::PRIM, 0);
    w(*dev, Reg::COLOR, color(c0));
    w(*dev, Reg::VERTEX, vtx(x0, y0, z0));
    w(*dev, Reg::COLOR, color(c1));
    w(*dev, Reg::VERTEX, vtx(x1, y1, z1));
    w(*dev, Reg::COLOR, color(c2));
    w(*dev, Reg::VERTEX, vtx(x2, y2, z2));
  }
};

// What a scene drew on a clear_target: colour and depth bytes, and the whole DeviceStats (the
// coarse depth bounds' tests compare both with the reference routines').
struct DrawnScene {
  std::vector<std::uint8_t> memory;
  DeviceStats stats;
};
inline DrawnScene finish_scene(Device& d, unsigned width, unsigned height) {
  d.drain();
  const auto m = d.memory();
  DrawnScene s;
  s.memory.assign(m.begin(), m.begin() + Canvas::kZBase + std::size_t{width} * height * 4);
  s.stats = d.stats();
  return s;
}

// A width × height RGBA8888 target in Canvas's layout (colour at 0, depth at Canvas::kZBase) on a
// device of the caller's options: the colour cleared to 0, the depth to `depth`.
inline void clear_target(Device& d, unsigned width, unsigned height, std::uint32_t depth) {
  w(d, Reg::FB_FORMAT, fb_format(width, height));
  w(d, Reg::FB_DRAW, 0);
  w(d, Reg::FB_Z, Canvas::kZBase);
  w(d, Reg::CLEAR_COLOR, 0);
  w(d, Reg::CLEAR, 0);
  w(d, Reg::CLEAR_DEPTH, depth);
  w(d, Reg::CLEAR_Z, 0);
}

}  // namespace gpubridge::sim::test
