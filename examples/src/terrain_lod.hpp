#pragma once
// Level of detail for the terrain's height-map grid (terrain.cpp), on its own for its tests.
#include <cstdint>
#include <vector>

namespace gpubridge::examples {

// Triangle indices over a grid of `grid` x `grid` vertices (vertex (i, j) = j * grid + i, cell
// (i, j) between vertices i..i+1, j..j+1) for an eye at (x, z) in cell units. Cells are grouped
// in 2x2 blocks from the corner (0, 0); the last row and column of cells of an even-sized cell
// grid are in no block and stay fine. A block whose centre is farther than `distance` from the
// eye is coarse: two triangles over its corners, or — when a fine block or cell shares one of its
// edges — a fan from its centre vertex over its corners and the midpoints of those edges, so that
// both sides meet at the same vertices (no T-junction, so no crack). Fine cells are the two
// triangles (a, c, b), (b, c, d) with a = (i, j), b = a + 1, c = a + grid, d = c + 1: counter-
// clockwise seen from above (+y with j along +z), the same diagonal b-c in every cell and block.
// The triangles cover the grid's square exactly once, whatever the eye.
std::vector<std::uint32_t> terrain_lod_indices(int grid, double eye_x, double eye_z, double distance);

}  // namespace gpubridge::examples
