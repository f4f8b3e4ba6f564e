#pragma once
// An independent, deliberately plain transcription of docs/protocol.md sections 8-9 used by the
// tests to derive expected values: coverage by direct edge evaluation with the top-left rule and
// attribute values as floor((2N + D) / (2D)) in 128-bit arithmetic. It shares no code with the
// simulator.
#include <array>
#include <cstdint>

namespace gpubridge::sim::test::ref {

struct P {
  std::int64_t x, y;  // 1/16 pixel
};

struct Bary {
  bool covered = false;
  std::int64_t D = 0;
  std::array<std::int64_t, 3> b{};  // weights of the (possibly exchanged) vertices
  bool swapped = false;             // P1 and P2 were exchanged
};

inline std::int64_t edge(P a, P b, std::int64_t sx, std::int64_t sy) {
  return (b.x - a.x) * (sy - a.y) - (b.y - a.y) * (sx - a.x);
}
inline std::int64_t bias(P a, P b) {
  const bool top = a.y == b.y && b.x > a.x;
  const bool left = b.y < a.y;
  return (top || left) ? 0 : -1;
}

inline Bary sample(P p0, P p1, P p2, int x, int y) {
  Bary r;
  std::int64_t D = (p1.x - p0.x) * (p2.y - p0.y) - (p2.x - p0.x) * (p1.y - p0.y);
  if (D == 0) return r;
  if (D < 0) {
    std::swap(p1, p2);
    D = -D;
    r.swapped = true;
  }
  const std::int64_t sx = 16 * x + 8, sy = 16 * y + 8;
  r.b = {edge(p1, p2, sx, sy), edge(p2, p0, sx, sy), edge(p0, p1, sx, sy)};
  r.covered = r.b[0] + bias(p1, p2) >= 0 && r.b[1] + bias(p2, p0) >= 0 && r.b[2] + bias(p0, p1) >= 0;
  r.D = D;
  return r;
}

// Attribute value at a sample with vertex values a (in the original vertex order).
inline std::int64_t interpolate(const Bary& s, std::array<std::int64_t, 3> a) {
  if (s.swapped) std::swap(a[1], a[2]);
  const __int128 N = __int128{a[0]} * s.b[0] + __int128{a[1]} * s.b[1] + __int128{a[2]} * s.b[2];
  const __int128 num = 2 * N + s.D, den = 2 * __int128{s.D};
  __int128 q = num / den;
  if ((num % den != 0) && ((num < 0) != (den < 0))) --q;  // floor
  return static_cast<std::int64_t>(q);
}

}  // namespace gpubridge::sim::test::ref
