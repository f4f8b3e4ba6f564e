#pragma once
// What the vector routines need of the texture stage (docs/protocol.md section 10): the texture
// unit of the draw, the reciprocal unit, and the per-triangle facts the scalar routine also uses.
#include "reciprocal.hpp"

namespace gpubridge::sim {

class TextureUnit;

struct TextureLanes {
  const TextureUnit* tex = nullptr;  // nullptr: untextured
  const ReciprocalUnit* recip = nullptr;
  bool q_const = false;  // Q constant over the triangle: const_rc is every pixel's reciprocal
  Reciprocal const_rc;
  unsigned wl = 3, hl = 3;  // log2 texture width / height
  bool decal = false;
};

}  // namespace gpubridge::sim
