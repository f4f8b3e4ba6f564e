#pragma once
// The figures of docs/examples.md for the donut ASIC's two ideas (issue 23), rendered on the exact
// simulator from the torus example held at one pose (`gpubridge-demo figures`):
//  - the temporal dither: the 8-bit reference (RGBA8888, no dither), one ordered-dither frame, one
//    temporal-dither frame, and the mean of 2, 4, 8 and 16 consecutive temporal frames (an aligned
//    run of phases), with each image's error against the reference;
//  - shift-and-add rotation: the torus with CORDIC vertex stages of several iteration counts.
#include <filesystem>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"

namespace gpubridge::examples {

struct FigureFile {
  std::string file;         // name inside the directory
  std::string what;         // one line
  double mean_error = 0;    // mean |image - reference| over the torus's pixels and R, G, B (8-bit LSB)
  bool has_error = false;   // false for the reference itself and the CORDIC figures
};

inline constexpr unsigned kFigurePose = 12;  // the torus pose of every figure (the golden frame)

// Writes the PNGs into `dir` (created) and describes them.
Result<std::vector<FigureFile>> write_figures(const std::filesystem::path& dir);

}  // namespace gpubridge::examples
