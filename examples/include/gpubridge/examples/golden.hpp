#pragma once
// Golden images of the examples: the frame kGoldenFrame of each, rendered on the exact simulator.
#include <filesystem>
#include <string>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/sim/options.hpp"

namespace gpubridge::examples {

// Renders frames 0..kGoldenFrame on a fresh simulator and returns the last scanned-out frame.
Result<Image> render_golden_frame(Example& ex, const sim::DeviceOptions& device = {});
std::filesystem::path golden_path(const std::filesystem::path& dir, const std::string& name);

struct ImageDiff {
  bool size_mismatch = false;
  std::size_t differing_pixels = 0;
  int max_difference = 0;               // largest per-channel difference
  std::vector<std::pair<unsigned, unsigned>> first_differences;  // up to 10 (x, y)
  bool identical() const { return !size_mismatch && differing_pixels == 0; }
  std::string summary() const;          // "identical" or "312 pixels differ (max 40), first at (3, 4) ..."
};
ImageDiff compare_images(const Image& expected, const Image& actual);

}  // namespace gpubridge::examples
