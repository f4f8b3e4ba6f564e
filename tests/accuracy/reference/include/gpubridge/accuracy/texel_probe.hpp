#pragma once
// Measuring where the device samples a texture, to 1/256 texel, from the colour it writes.
//
// The probe texture (RGBA8888) encodes the texel index in its channels:
//   R = 255 on even columns, 0 on odd ones      G = column index mod 256
//   B = 255 on even rows,    0 on odd ones      A = row index mod 256
// Drawn with BILINEAR filtering in DECAL mode, R and G depend on the column only, so the vertical
// weights cancel and R = round(255 * (1 - fu/256)) or round(255 * fu/256) depending on the parity of
// the left column i0 (docs/protocol.md 10.4): R gives the bilinear weight fu, G gives i0 roughly, and
// the position the device sampled is i0 + (fu + 0.5)/256 + 0.5 texels (+-1/512 from the truncation
// of the weight to 8 bits). B and A do the same for rows. The reference position picks the candidate
// among the ones consistent with R and G (searched within kProbeWindow texels; G's +-1 tolerance
// rejects the wrong period of R's parity pattern, also across G's 255 -> 0 wrap), so the measurement
// needs no access to simulator internals.
#include <cstdint>
#include <vector>

namespace gpubridge::accuracy {

// The probe texture of 2^log2_w x 2^log2_h texels as device bytes (R, G, B, A per texel).
std::vector<std::uint8_t> make_probe_texture(unsigned log2_w, unsigned log2_h);

// How far from the expected position a reading is searched (texels). Farther errors are reported
// as gross with a position exactly this far off (a lower bound of the error).
inline constexpr long long kProbeWindow = 100;

struct ProbeReading {
  double position = 0;  // texel coordinate the device sampled (texels, same period as `expected`)
  bool gross = false;   // nothing within kProbeWindow texels matches: error > kProbeWindow
};

// Decodes one axis. `fine` and `coarse` are the written R and G (or B and A); `expected` is the
// reference texel coordinate u * W (any real number, wrapping is handled); `size` is W (or H).
ProbeReading read_probe_axis(std::uint8_t fine, std::uint8_t coarse, double expected, unsigned size);

}  // namespace gpubridge::accuracy
