// Hostile input: NaN, Inf and huge values at the host conversion (rejected with an error naming the
// value), and arbitrary register words at the device (a defined result, never undefined
// behaviour: this suite also runs under UBSan + ASan in the sanitizer job of scripts/test.sh).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "sim_harness.hpp"

namespace gpubridge::accuracy {
namespace {

std::array<geometry::ScreenVertex, 3> plain_triangle() {
  std::array<geometry::ScreenVertex, 3> tri{};
  tri[1].x = 10;
  tri[2].y = 10;
  for (auto& v : tri) v.z = 0.5;
  return tri;
}

// Bound: every non-finite or out-of-range host value is an error with a non-empty message.
TEST(Robustness, HostConversionRejectsNanInfHuge) {
  const double bad[] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(),
                        -std::numeric_limits<double>::infinity(), 1e300, -1e300, 4096.0, -2049.0};
  for (double v : bad) {
    for (int field = 0; field < 3; ++field) {
      auto tri = plain_triangle();
      if (field == 0) tri[1].x = v;
      if (field == 1) tri[2].y = v;
      if (field == 2) tri[0].w = v;  // huge w is legal only when finite; NaN/Inf/negative must fail
      const auto r = geometry::convert_triangle(tri, {});
      if (field == 2 && std::isfinite(v) && v > 0) continue;
      ASSERT_FALSE(r.ok()) << "value " << v << " field " << field;
      EXPECT_FALSE(r.error().message.empty());
    }
  }
  for (double c : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    auto tri = plain_triangle();
    tri[1].z = c;
    EXPECT_FALSE(geometry::convert_triangle(tri, {}).ok());
    tri[1].z = 0.5;
    tri[1].uv.x = c;
    EXPECT_FALSE(geometry::convert_triangle(tri, {}).ok());
  }
}

// Bound: after thousands of random register words (all fields, reserved bits, extreme vertices,
// Q = 0, random formats), a RESET followed by a normal setup renders exactly the reference again.
TEST(Robustness, RandomRegisterWords_DefinedResultAndRecovery) {
  SimHarness h;
  std::mt19937_64 rng(99);
  using protocol::Reg;
  const Reg regs[] = {Reg::COLOR, Reg::TEXCOORD, Reg::VERTEX, Reg::VERTEX, Reg::VERTEX, Reg::PRIM, Reg::TRI_MODE,
                      Reg::TEX_BASE, Reg::TEX_FMT, Reg::SCISSOR, Reg::FB_FORMAT, Reg::FB_DRAW, Reg::FB_Z,
                      Reg::CLEAR_COLOR, Reg::CLEAR_DEPTH};
  for (int i = 0; i < 3000; ++i) {
    const Reg r = regs[rng() % std::size(regs)];
    std::uint64_t data = rng();
    if (rng() % 4 == 0) data = ~std::uint64_t{0};
    if (rng() % 4 == 0) data = 0;
    // Keep the work per triangle modest: framebuffers of at most 128 x 128 (reserved bits and
    // formats stay random), addresses anywhere (beyond VRAM is a defined, flagged case).
    if (r == Reg::FB_FORMAT) data &= ~((std::uint64_t{0x780} << 16) | 0x780);
    h.write(r, data);
  }
  h.device().drain();
  h.write(Reg::RESET, protocol::kResetMagic);
  SimHarness fresh;  // the same setup sequence on the recovered device must give the same result
  auto redo = [](SimHarness& s) {
    s.write(Reg::FB_FORMAT, *geometry::fb_format_word(64, 64, protocol::PixelFormat::RGBA8888));
    s.write(Reg::FB_DRAW, 0);
    s.write(Reg::FB_Z, *geometry::address16_word(64 * 64 * 4));
    s.scissor(0, 0, 1024, 1024);
    s.clear();
    s.state({});
    s.draw(geometry::DeviceTriangle{dv(8, 8, 0, 0xFF0000FF), dv(900, 100, 0, 0x00FF00FF), dv(300, 1000, 0, 0x0000FFFF)});
  };
  redo(h);
  redo(fresh);
  EXPECT_TRUE(h.color_bytes() == fresh.color_bytes());
}

}  // namespace
}  // namespace gpubridge::accuracy
