#include "terrain_lod.hpp"

#include <initializer_list>

namespace gpubridge::examples {

std::vector<std::uint32_t> terrain_lod_indices(int grid, double eye_x, double eye_z, double distance) {
  const int cells = grid - 1, blocks = cells / 2;
  auto vertex = [&](int i, int j) { return static_cast<std::uint32_t>(j * grid + i); };
  auto coarse = [&](int bi, int bj) {
    const double dx = 2 * bi + 1 - eye_x, dz = 2 * bj + 1 - eye_z;
    return dx * dx + dz * dz > distance * distance;
  };
  // A neighbour that is on the grid and drawn fine: a fine block, or a cell in no block.
  auto fine = [&](int bi, int bj) {
    if (bi < 0 || bj < 0 || 2 * bi >= cells || 2 * bj >= cells) return false;
    if (bi >= blocks || bj >= blocks) return true;
    return !coarse(bi, bj);
  };
  std::vector<std::uint32_t> out;
  auto cell = [&](int i, int j) {
    const std::uint32_t a = vertex(i, j), b = a + 1, c = vertex(i, j + 1), d = c + 1;
    for (std::uint32_t k : {a, c, b, b, c, d}) out.push_back(k);
  };
  for (int bj = 0; bj < blocks; ++bj)
    for (int bi = 0; bi < blocks; ++bi) {
      const int i = 2 * bi, j = 2 * bj;
      if (!coarse(bi, bj)) {
        for (int r : {0, 1})
          for (int c : {0, 1}) cell(i + c, j + r);
        continue;
      }
      // The outline in the cells' winding (a -> c -> b): corners and, towards fine neighbours,
      // the midpoints of the shared edges.
      std::uint32_t ring[8];
      std::size_t n = 0;
      ring[n++] = vertex(i, j);
      if (fine(bi - 1, bj)) ring[n++] = vertex(i, j + 1);
      ring[n++] = vertex(i, j + 2);
      if (fine(bi, bj + 1)) ring[n++] = vertex(i + 1, j + 2);
      ring[n++] = vertex(i + 2, j + 2);
      if (fine(bi + 1, bj)) ring[n++] = vertex(i + 2, j + 1);
      ring[n++] = vertex(i + 2, j);
      if (fine(bi, bj - 1)) ring[n++] = vertex(i + 1, j);
      if (n == 4) {  // corners a, c, d, b: the cells' two triangles, twice the size
        for (std::uint32_t k : {ring[0], ring[1], ring[3], ring[3], ring[1], ring[2]}) out.push_back(k);
        continue;
      }
      const std::uint32_t centre = vertex(i + 1, j + 1);
      for (std::size_t k = 0; k < n; ++k)
        for (std::uint32_t v : {centre, ring[k], ring[(k + 1) % n]}) out.push_back(v);
    }
  for (int j = 0; j < cells; ++j)  // the cells in no block
    for (int i = 0; i < cells; ++i)
      if (i >= 2 * blocks || j >= 2 * blocks) cell(i, j);
  return out;
}

}  // namespace gpubridge::examples
