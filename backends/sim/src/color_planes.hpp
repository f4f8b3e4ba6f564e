#pragma once
// Setup of the four colour planes at once (the bulk of a small Gouraud triangle's setup). Same
// result as setup_plane (setup.cpp) per channel, computed in double lanes: with colour deltas below
// 2^8 and edge values below 2^34 (12.4 coordinates), every numerator is an integer below 2^44,
// exact in double; the quotient estimate is within 1/128 of the true quotient, so one correction
// each way gives the exact floor-divmod (docs/simulator.md, "Exact arithmetic, cheaply").
#include <cstdint>

#include "setup.hpp"

namespace gpubridge::sim {

// out[0..3] = planes R, G, B, A of vertices v[0..2] with barycentric edges b1 (vertex 1) and b2
// (vertex 2) and area D > 0.
void setup_color_planes(Plane* out, const Vertex* v, const Edge& b1, const Edge& b2, std::int64_t D);

}  // namespace gpubridge::sim
