#pragma once
// `gpubridge bench rtl --fill`: the fill rate of the whole device, per gateware profile and scene
// class. The co-simulated board (SPI slave, FIFO, executor, core, memory arbiter, SPRAM or SDRAM
// controller with its chip model, behind the emulated bridge: the rtl:BOARD path) draws one
// rectangle as two triangles; the clocks counted are the device's work clocks between two quiet
// points (setup and clears drained before, the draw drained after), so SPI transfer time, which
// only delays the commands, is not counted. rtl_core_<profile>_bench gives the same classes for the
// core alone with an ideal memory port; the difference is what the memory system costs.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/geometry/encode.hpp"
#include "gpubridge/protocol/command_stream.hpp"
#include "gpubridge/rtl/gateware_profile.hpp"

namespace gpubridge::cli {

struct FillClass {
  std::string name;  // as rtl_core_<profile>_bench names the class (predict.py pairs them)
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  geometry::RenderState state;  // TRI_MODE
  bool bilinear = false;        // textured: the filter
};

struct FillDraw {
  FillClass cls;
  unsigned width = 0, height = 0;  // the rectangle (and the framebuffer)
  protocol::CommandStream setup;   // buffers, depth clear, texture: drained before the count starts
  protocol::CommandStream draw;    // the rectangle as two triangles
};

// The classes the profile has (CAPS.FEATURES), each on the largest of 640 x 480, 320 x 240,
// 320 x 200, 256 x 128, 192 x 80 whose colour buffer (with depth buffer and texture if the class
// uses them) fits the profile's VRAM and maximum size; `quick`: 64 x 48 (a smoke run).
std::vector<FillDraw> fill_draws(const rtl::GatewareCaps& caps, bool quick);

struct FillResult {
  std::string name;
  unsigned width = 0, height = 0, bytes_per_pixel = 4;
  bool depth = false, blend = false, textured = false, bilinear = false;
  std::uint64_t pixels = 0;            // covered pixels (the RTL's perf_pixels)
  std::uint64_t draw_clocks = 0;       // device work clocks of the draw
  std::uint64_t core_busy_clocks = 0;  // clocks the render core was not idle
  std::uint64_t setup_clocks = 0;      // of which in triangle setup
  std::uint64_t mem_stall_clocks = 0;  // clocks a core memory request waited (arbiter, SPRAM / SDRAM)
  std::uint64_t refreshes = 0;         // SDRAM auto refreshes during the draw
  std::uint64_t bytes_compared = 0;    // VRAM compared with the simulator's after the same streams
  std::uint64_t bytes_differing = 0;   // of which differing (0: the draw is the simulator's)
  double px_per_clock = 0, mpixel_per_s = 0;
};

// Plays each draw on a fresh emulated board of the profile (board profile from `config_dir`) and on
// the simulator, and compares the buffers and texture in VRAM afterwards.
Result<std::vector<FillResult>> measure_fill(rtl::GatewareProfile profile, bool quick, const std::filesystem::path& config_dir);

}  // namespace gpubridge::cli
