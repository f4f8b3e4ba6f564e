// Texel-position probe (see texel_probe.hpp).
#include "gpubridge/accuracy/texel_probe.hpp"

#include <cmath>
#include <array>
#include <cstdlib>
#include <vector>

namespace gpubridge::accuracy {
namespace {

// A channel value blended between the columns i0 and i0 + 1 with weight fu: the vertical weights
// of section 10.4 sum to 256 and factor out.
int blend(int left, int right, int fu) { return (left * (256 - fu) * 256 + right * fu * 256 + 32768) >> 16; }

int fine_of(long long i) { return (i & 1) == 0 ? 255 : 0; }
int coarse_of(long long i, unsigned size) { return static_cast<int>(static_cast<unsigned long long>(i) & (size - 1) & 255); }

}  // namespace

std::vector<std::uint8_t> make_probe_texture(unsigned log2_w, unsigned log2_h) {
  const unsigned w = 1u << log2_w, h = 1u << log2_h;
  std::vector<std::uint8_t> bytes(std::size_t{w} * h * 4);
  for (unsigned j = 0; j < h; ++j)
    for (unsigned i = 0; i < w; ++i) {
      std::uint8_t* p = &bytes[(std::size_t{j} * w + i) * 4];
      p[0] = static_cast<std::uint8_t>(fine_of(i));
      p[1] = static_cast<std::uint8_t>(i & 255);
      p[2] = static_cast<std::uint8_t>(fine_of(j));
      p[3] = static_cast<std::uint8_t>(j & 255);
    }
  return bytes;
}

ProbeReading read_probe_axis(std::uint8_t fine, std::uint8_t coarse, double expected, unsigned size) {
  // For each parity of the left column, the weights fu that produce each fine value (one or two).
  struct Inverse {
    std::array<std::array<std::vector<int>, 256>, 2> fu;
    Inverse() {
      for (int parity = 0; parity < 2; ++parity)
        for (int w = 0; w < 256; ++w) fu[parity][blend(fine_of(parity), fine_of(parity + 1), w)].push_back(w);
    }
  };
  static const Inverse inverse;
  ProbeReading best{0, true};
  double best_dist = INFINITY;
  // Candidates up to kProbeWindow texels away; the coarse channel (+-1) rejects the wrong ones.
  const long long centre = static_cast<long long>(std::floor(expected - 0.5));
  for (long long i0 = centre - kProbeWindow; i0 <= centre + kProbeWindow; ++i0) {
    for (int fu : inverse.fu[i0 & 1][fine]) {
      const int coarse_expected = blend(coarse_of(i0, size), coarse_of(i0 + 1, size), fu);
      if (std::abs(coarse_expected - coarse) > 1) continue;
      const double pos = double(i0) + (fu + 0.5) / 256.0 + 0.5;
      const double dist = std::fabs(pos - expected);
      if (dist < best_dist) {
        best_dist = dist;
        best = ProbeReading{pos, false};
      }
    }
  }
  if (best.gross) best.position = expected + kProbeWindow;  // at least this far off
  return best;
}

}  // namespace gpubridge::accuracy
