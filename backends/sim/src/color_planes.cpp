#include "color_planes.hpp"

#include <cmath>

namespace gpubridge::sim {

// Written as 4-lane loops: the AVX2 clone vectorises them (vroundpd for the floor); the default
// clone computes the same numbers lane by lane. Every operation but the quotient estimate is exact
// integer arithmetic in double, so contraction into FMA cannot change a result either.
__attribute__((target_clones("avx2", "default"))) void setup_color_planes(Plane* out, const Vertex* v, const Edge& b1,
                                                                        const Edge& b2, std::int64_t D) {
  const double den = 2.0 * static_cast<double>(D), inv = 1.0 / den;
  const double dd = static_cast<double>(D);
  const double w[3][2] = {{static_cast<double>(b1.e), static_cast<double>(b2.e)},
                          {static_cast<double>(b1.ex), static_cast<double>(b2.ex)},
                          {static_cast<double>(b1.ey), static_cast<double>(b2.ey)}};
  double d1[4], d2[4];
  for (unsigned ch = 0; ch < 4; ++ch) {
    d1[ch] = static_cast<double>(int{v[1].c[ch]} - int{v[0].c[ch]});
    d2[ch] = static_cast<double>(int{v[2].c[ch]} - int{v[0].c[ch]});
  }
  double q[3][4], r[3][4];
  for (unsigned k = 0; k < 3; ++k) {
    for (unsigned ch = 0; ch < 4; ++ch) {
      // M = 2·(Δ1·b1 + Δ2·b2) (+ D at the origin), then its floor-divmod by 2D.
      const double m = 2.0 * (d1[ch] * w[k][0] + d2[ch] * w[k][1]) + (k == 0 ? dd : 0.0);
      double qq = std::floor(m * inv);
      double rr = m - qq * den;
      const bool below = rr < 0, above = rr >= den;
      qq += below ? -1.0 : above ? 1.0 : 0.0;
      rr += below ? den : above ? -den : 0.0;
      q[k][ch] = qq;
      r[k][ch] = rr;
    }
  }
  for (unsigned ch = 0; ch < 4; ++ch) {
    Plane& p = out[ch];
    p = Plane{};
    p.q = v[0].c[ch];
    if (d1[ch] == 0 && d2[ch] == 0) continue;  // constant: as setup_plane leaves it
    p.constant = false;
    p.q += static_cast<std::int64_t>(q[0][ch]);
    p.r = static_cast<std::int64_t>(r[0][ch]);
    p.qx = static_cast<std::int64_t>(q[1][ch]);
    p.rx = static_cast<std::int64_t>(r[1][ch]);
    p.qy = static_cast<std::int64_t>(q[2][ch]);
    p.ry = static_cast<std::int64_t>(r[2][ch]);
  }
}

}  // namespace gpubridge::sim
