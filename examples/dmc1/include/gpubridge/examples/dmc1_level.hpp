#pragma once
// A DMC-1 client the way tinygpus' demos drive the chip from their RISC-V, on the host instead: a
// small hall (textured walls, floor and ceiling planes, pillars) with a window in its north wall
// opening onto a Comanche-style terrain, seen from a camera moving round the hall. Every frame is
// ray-cast column by column into DMC-1 spans (docs/dmc1.md, "Example client").
//
// Units: world units are wall texels (the wall command's depth doubles as its v step, which makes
// walls one texel per unit at depth 8 * z); floors and ceilings are 2 units per texel, terrain 8
// units per texel; every depth the chip sees is 8 * z.
#include <cstdint>
#include <string>
#include <vector>

namespace gpubridge::examples::dmc1_level {

struct Camera {
  double x = 0, z = 0;  // position on the floor plan (world units)
  double yaw = 0;       // radians; 0 looks along +x
  double height = 64;   // eye height above the floor
};

struct Level {
  std::vector<std::string> map;  // rows along +z, columns along +x; see level.cpp for the legend
  double cell = 64;              // world units per map cell
  double ceiling = 160;          // hall height
  double parapet = 40;           // window sill height
  double lintel = 120;           // window top
  double terrain_drop = 40;      // terrain heights (0..250) sit this far below the floor
};

Level hall();
// Position t in [0, 1) of a closed camera path round the hall.
Camera camera_path(const Level& level, double t);
// One frame: 320 columns of DMC-1 commands, each column ending with an end of column. The first
// column also sets the frame's parameters (UV offsets, view height).
std::vector<std::uint64_t> frame_commands(const Level& level, const Camera& camera);
// `frames` frames evenly spaced along the camera path.
std::vector<std::uint64_t> path_commands(const Level& level, unsigned frames);
// Frame n of a lap of `path_frames` frames (n taken modulo the lap): what the client sends for its
// n-th frame, written to a file (`gpubridge-dmc1-demo write`) or streamed to a daemon (`stream`).
std::vector<std::uint64_t> lap_frame_commands(const Level& level, unsigned n, unsigned path_frames);

// The golden frames (examples/dmc1/golden/): positions on a lap of kPathFrames frames, chosen to show
// the window and terrain, a pillar close up and the brick walls.
inline constexpr unsigned kPathFrames = 64;
inline constexpr unsigned kGoldenFrames[] = {0, 12, 40};
std::vector<std::uint64_t> golden_frame_commands(unsigned frame);
std::string golden_name(unsigned frame);  // "level-NN.png"

}  // namespace gpubridge::examples::dmc1_level
