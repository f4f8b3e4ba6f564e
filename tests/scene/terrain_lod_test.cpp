// The terrain's level of detail (examples/src/terrain_lod.hpp): whatever the eye, the triangles
// cover the grid's square exactly once, all with the cells' winding, and every edge inside the
// square is shared by exactly two triangles in opposite directions — a T-junction (a coarse edge
// beside two fine ones) or a gap would leave an edge used once, which is what shows as a crack.
#include <gtest/gtest.h>

#include <map>
#include <utility>

#include "terrain_lod.hpp"

namespace gpubridge::examples {
namespace {

struct Checked {
  std::size_t triangles = 0;
};

Checked check_watertight(int grid, double ex, double ez, double distance) {
  const auto idx = terrain_lod_indices(grid, ex, ez, distance);
  EXPECT_EQ(idx.size() % 3, 0u);
  const int cells = grid - 1;
  auto xz = [&](std::uint32_t v) { return std::pair<int, int>(static_cast<int>(v) % grid, static_cast<int>(v) / grid); };
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
  long long twice_area = 0;
  for (std::size_t t = 0; t < idx.size(); t += 3) {
    for (int k = 0; k < 3; ++k) EXPECT_LT(idx[t + k], static_cast<std::uint32_t>(grid * grid));
    const auto [x0, z0] = xz(idx[t]);
    const auto [x1, z1] = xz(idx[t + 1]);
    const auto [x2, z2] = xz(idx[t + 2]);
    const long long cross = static_cast<long long>(x1 - x0) * (z2 - z0) - static_cast<long long>(z1 - z0) * (x2 - x0);
    EXPECT_LT(cross, 0) << "triangle " << t / 3 << " is degenerate or wound the other way";
    twice_area -= cross;
    for (int k = 0; k < 3; ++k) ++directed[{idx[t + k], idx[t + (k + 1) % 3]}];
  }
  EXPECT_EQ(twice_area, 2LL * cells * cells);
  for (const auto& [edge, count] : directed) {
    EXPECT_EQ(count, 1) << "edge " << edge.first << "-" << edge.second << " repeated";
    const auto [xa, za] = xz(edge.first);
    const auto [xb, zb] = xz(edge.second);
    const bool border = (xa == xb && (xa == 0 || xa == cells)) || (za == zb && (za == 0 || za == cells));
    const bool reversed = directed.count({edge.second, edge.first}) == 1;
    EXPECT_TRUE(border != reversed) << "edge (" << xa << "," << za << ")-(" << xb << "," << zb << ") "
                                    << (border ? "on the border has a neighbour" : "inside has no opposite edge");
  }
  return {idx.size() / 3};
}

TEST(TerrainLod, EveryEyeGivesAWatertightCoverOfTheGrid) {
  for (int grid : {64, 9, 10}) {
    SCOPED_TRACE(grid);
    for (double distance : {0.0, 1.5, 3.0, 14.0, 30.0})
      for (double ex : {-5.0, 0.0, 3.3, 31.5, 60.0, 70.0})
        for (double ez : {-2.0, 0.5, 22.0, 59.0, 80.0}) {
          SCOPED_TRACE(testing::Message() << "eye " << ex << "," << ez << " distance " << distance);
          check_watertight(grid, ex, ez, distance);
          if (HasFailure()) return;
        }
  }
}

TEST(TerrainLod, NearIsFineFarIsCoarse) {
  // Everything within reach: the full grid, two triangles per cell.
  EXPECT_EQ(check_watertight(64, 31, 31, 1e9).triangles, 2u * 63 * 63);
  // Nothing within reach: two per block, fans beside the last row and column of cells (which
  // stay fine), and those cells.
  const auto coarse = check_watertight(64, 31, 31, 0).triangles;
  EXPECT_LT(coarse, 2u * 63 * 63 / 3);
  EXPECT_GT(coarse, 2u * 31 * 31);
  // In between, as the terrain flies: fewer than the full grid, more than all coarse.
  const auto mixed = check_watertight(64, 31.5, 55, 30).triangles;
  EXPECT_LT(mixed, 2u * 63 * 63);
  EXPECT_GT(mixed, coarse);
}

}  // namespace
}  // namespace gpubridge::examples
