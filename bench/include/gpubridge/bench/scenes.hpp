#pragma once
// The fixed scene set of `gpubridge bench accuracy`. Every scene starts as host floats (what a
// client has), goes through the host conversion of client/geometry (snap to 1/16 px, Z, colour,
// per-triangle Q normalisation) and is then the same register data for the simulator, the
// reference and (converted back to floats) llvmpipe.
#include <cstdint>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/geometry/convert.hpp"
#include "gpubridge/geometry/encode.hpp"

namespace gpubridge::bench {

struct Scene {
  std::string name;
  std::string description;
  unsigned width = 640, height = 480;
  geometry::RenderState state;             // render state of the throughput run
  bool textured = false;                   // samples the probe texture (bilinear, decal)
  std::vector<geometry::DeviceTriangle> triangles;
  std::size_t error_subset = 0;            // leading triangles used for the error measurement
  double nominal_area = 0;                 // px per triangle as generated (0: mixed)
};

inline constexpr unsigned kTextureLog2 = 10;  // 1024 x 1024 probe texture (docs section 15 case)

// Scale divides the triangle counts (1 = the full set of the reference sheet's section 5.3;
// `--quick` uses 50).
Result<std::vector<Scene>> make_scenes(unsigned scale);

}  // namespace gpubridge::bench
