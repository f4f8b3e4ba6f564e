#pragma once
// A second, deliberately slow DMC-1 model written the way the RTL is organised: every span runs
// its row events one by one with the texture fetch pipeline explicit (the texel seen at event k
// was fetched after event k - 2), the register history of dot_ray/dot_u/dot_v kept per event, the
// depth test and column buffers per pixel, and scan-out by the column sender's arithmetic. The
// library computes walls and planes in closed form, splits rows across threads and scans out
// through a table; tests compare the two on streams the goldens do not cover.
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "gpubridge/dmc1/palette.hpp"
#include "gpubridge/dmc1/texture_memory.hpp"

namespace gpubridge::dmc1::test {

class ReferenceModel {
 public:
  ReferenceModel(std::shared_ptr<const TextureMemory> textures, const Palette& palette);
  void run(std::span<const std::uint64_t> words);
  // Every column sent so far, in output order (column 0 rows 0..239, column 1, ...).
  const std::vector<std::uint16_t>& output() const { return out_; }
  std::uint8_t picked_height() const { return picked_height_; }

 private:
  void command(std::uint64_t w);
  void span(std::uint32_t t0, std::uint32_t t1, unsigned tag, unsigned start, unsigned col_end);
  void end_of_column();
  std::uint8_t read_texel(std::uint32_t u, std::uint32_t v) const;

  std::shared_ptr<const TextureMemory> mem_;
  Palette palette_;
  std::int32_t u_off_ = 0, v_off_ = 0, ny_ = 0, uy_ = 0, vy_ = 0, dot_u_ = 0, dot_v_ = 0, dot_ray_ = 0, ded_ = 0;
  std::int32_t view_z_ = 0, cos_ = 0, sin_ = 0;
  bool lightmap_ = false;
  unsigned buffer_ = 0, sampler_id_ = 0;
  TextureBinding binding_;
  std::uint8_t scrh_diff_ = 0, picked_height_ = 0;
  std::array<std::array<std::uint16_t, 256>, 2> colbuf_{};
  std::array<std::uint32_t, 240> depth_{};
  std::vector<std::uint16_t> out_;
};

}  // namespace gpubridge::dmc1::test
