#include "gpubridge/examples/dmc1_level.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "gpubridge/dmc1/command.hpp"

namespace gpubridge::examples::dmc1_level {
namespace {

namespace d = gpubridge::dmc1;

// Textures of the golden pack (tests/dmc1/data): opaque 128 x 128 walls, 64 x 64 flats, the terrain.
constexpr unsigned kStone = 2, kBrick = 7, kPillar = 42, kSill = 39, kLintel = 45;
constexpr unsigned kFloor = 131, kCeiling = 137, kTerrain = 663;
constexpr unsigned kSkyDepth = 0xFFFF;  // the background filler: behind everything
constexpr double kFocal = 256;          // pixels: the DMC-1's plane and terrain arithmetic assume it
constexpr int kHorizon = 120;           // row of the eye's height

struct Hit {
  char cell = 0;
  double z = 0;  // perpendicular distance (world units)
  double u = 0;  // position along the face (world units)
};

// Grid traversal from the camera along dir (forward component 1, so the ray parameter is z).
Hit cast(const Level& lv, const Camera& cam, double dx, double dz) {
  const double px = cam.x / lv.cell, pz = cam.z / lv.cell;
  int mx = static_cast<int>(std::floor(px)), mz = static_cast<int>(std::floor(pz));
  const int sx = dx < 0 ? -1 : 1, sz = dz < 0 ? -1 : 1;
  const double ddx = dx == 0 ? 1e30 : std::abs(1 / dx), ddz = dz == 0 ? 1e30 : std::abs(1 / dz);
  double tx = (dx < 0 ? px - mx : mx + 1 - px) * ddx, tz = (dz < 0 ? pz - mz : mz + 1 - pz) * ddz;
  const int rows = static_cast<int>(lv.map.size()), cols = static_cast<int>(lv.map[0].size());
  for (int guard = 0; guard < 4 * (rows + cols); ++guard) {
    bool x_side = tx < tz;
    double t = x_side ? tx : tz;
    if (x_side) {
      mx += sx;
      tx += ddx;
    } else {
      mz += sz;
      tz += ddz;
    }
    if (mx < 0 || mz < 0 || mx >= cols || mz >= rows) break;
    const char c = lv.map[static_cast<std::size_t>(mz)][static_cast<std::size_t>(mx)];
    if (c == '.') continue;
    const double z = t * lv.cell;
    return Hit{c, z, x_side ? cam.z + z * dz : cam.x + z * dx};
  }
  return Hit{};
}

// The rows a height range covers at depth z (pixel centres inside the projection), unclamped.
int row_above(double y, double eye, double z) { return static_cast<int>(std::ceil(kHorizon + kFocal * (y - eye) / z - 0.5)); }
int row_below(double y, double eye, double z) { return static_cast<int>(std::floor(kHorizon + kFocal * (y - eye) / z - 0.5)); }

// A textured wall from height y0 to y1 at depth z: one texel per unit, v counted up from y = 0.
void wall_span(std::vector<std::uint64_t>& out, const Camera& cam, double z, double y0, double y1, unsigned tid,
               unsigned light, double u) {
  const int lo = std::max(row_above(y0, cam.height, z), 0), hi = std::min(row_below(y1, cam.height, z), 239);
  if (lo > hi) return;
  const double v = cam.height + (lo + 0.5 - kHorizon) * z / kFocal;  // height at the first row's centre
  const auto depth = static_cast<std::uint16_t>(std::clamp(std::lround(8 * z), 1L, 0x3FFFL));  // = the v step
  out.push_back(d::wall({static_cast<unsigned>(lo), static_cast<unsigned>(hi), light, tid}, depth,
                        static_cast<std::uint8_t>(static_cast<int>(std::floor(v)) & 255),
                        static_cast<std::uint8_t>(static_cast<int>(std::floor(u)) & 255)));
}

// A floor (up = true: ceiling) plane span over rows lo..hi: normal +-y, texture axes world x and z
// at 2 units per texel. dr is the ray's height component at the first row.
void plane_span(std::vector<std::uint64_t>& out, int lo, int hi, bool ceiling, double distance, double dx, double dz,
                unsigned tid, unsigned light) {
  lo = std::max(lo, 0);
  hi = std::min(hi, 239);
  if (lo > hi) return;
  const int sign = ceiling ? -1 : 1;
  out.push_back(d::plane_a(256 * sign, 0, 0, static_cast<int>(std::lround(512 * dx)), static_cast<int>(std::lround(512 * dz))));
  out.push_back(d::plane({static_cast<unsigned>(lo), static_cast<unsigned>(hi), light, tid},
                         static_cast<std::int16_t>(std::lround(distance)), static_cast<std::int16_t>(sign * (lo - kHorizon))));
}

}  // namespace

// Legend: '#' stone wall, 'B' brick wall, 'P' pillar, 'W' window (a sill, the terrain beyond, a
// lintel under the ceiling), '.' floor. Row 0 is the south wall (z = 0).
Level hall() {
  Level lv;
  lv.map = {
      "##############", "#............#", "#............#", "#..P......P..#", "#............#",
      "B............B", "B.....BB.....B", "B.....BB.....B", "B............B", "#............#",
      "#..P......P..#", "#............#", "#............#", "##WWWWWWWWWW##",
  };
  return lv;
}

Camera camera_path(const Level& lv, double t) {
  const double a = 2 * std::numbers::pi * t;
  const double cx = 7 * lv.cell, cz = 6.5 * lv.cell;
  Camera c;
  c.x = cx + 3.4 * lv.cell * std::cos(a);
  c.z = cz + 2.6 * lv.cell * std::sin(a);
  c.yaw = a + std::numbers::pi / 2 + 0.5 * std::sin(3 * a);  // along the path, glancing about
  c.height = 64 + 8 * std::sin(2 * a);
  return c;
}

std::vector<std::uint64_t> frame_commands(const Level& lv, const Camera& cam) {
  std::vector<std::uint64_t> out;
  out.reserve(320 * 10);
  // Floor and terrain texture coordinates share the offsets: 512 * position puts the camera at
  // texel x / 2 of a floor and x / 8 of the terrain.
  out.push_back(d::uv_offset(static_cast<std::int32_t>(std::lround(512 * cam.x)), static_cast<std::int32_t>(std::lround(512 * cam.z)), false));
  out.push_back(d::view_z(static_cast<std::int16_t>(std::lround(cam.height + lv.terrain_drop))));
  const double fx = std::cos(cam.yaw), fz = std::sin(cam.yaw), rx = std::sin(cam.yaw), rz = -std::cos(cam.yaw);
  for (unsigned c = 0; c < d::kColumns; ++c) {
    const double x = (static_cast<double>(c) - 160 + 0.5) / kFocal;
    const double dx = fx + rx * x, dz = fz + rz * x;  // forward component 1: ray parameter = depth
    out.push_back(d::wall({0, 239, 15, 0}, kSkyDepth, 0, 0));
    const Hit h = cast(lv, cam, dx, dz);
    if (h.cell) {
      plane_span(out, 0, row_above(0, cam.height, h.z) - 1, false, cam.height, dx, dz, kFloor, 13);
      plane_span(out, row_below(lv.ceiling, cam.height, h.z) + 1, 239, true, lv.ceiling - cam.height, dx, dz, kCeiling, 11);
      if (h.cell == 'W') {
        wall_span(out, cam, h.z, 0, lv.parapet, kSill, 14, h.u);
        wall_span(out, cam, h.z, lv.lintel, lv.ceiling, kLintel, 14, h.u);
        const int lo = std::max(row_below(lv.parapet, cam.height, h.z) + 1, 0);
        const int hi = std::min(row_above(lv.lintel, cam.height, h.z) - 1, 239);
        const long start = std::lround(std::ceil(h.z));
        if (lo <= hi && start < 1024) {
          out.push_back(d::ray_cs(static_cast<int>(std::lround(2048 * dx)), static_cast<int>(std::lround(2048 * dz))));
          out.push_back(d::terrain({static_cast<unsigned>(lo), static_cast<unsigned>(hi), 15, kTerrain},
                                   static_cast<unsigned>(start), 2047, c == 160));
        }
      } else {
        const unsigned tid = h.cell == 'B' ? kBrick : h.cell == 'P' ? kPillar : kStone;
        wall_span(out, cam, h.z, 0, lv.ceiling, tid, 15, h.u);
      }
    }
    out.push_back(d::end_of_column());
  }
  return out;
}

std::vector<std::uint64_t> path_commands(const Level& lv, unsigned frames) {
  std::vector<std::uint64_t> out;
  for (unsigned f = 0; f < frames; ++f) {
    const auto words = lap_frame_commands(lv, f, frames);
    out.insert(out.end(), words.begin(), words.end());
  }
  return out;
}

std::vector<std::uint64_t> lap_frame_commands(const Level& lv, unsigned n, unsigned path_frames) {
  path_frames = std::max(path_frames, 1u);
  return frame_commands(lv, camera_path(lv, static_cast<double>(n % path_frames) / path_frames));
}

std::vector<std::uint64_t> golden_frame_commands(unsigned frame) { return lap_frame_commands(hall(), frame, kPathFrames); }

std::string golden_name(unsigned frame) {
  char name[32];
  std::snprintf(name, sizeof name, "level-%02u.png", frame);
  return name;
}

}  // namespace gpubridge::examples::dmc1_level
