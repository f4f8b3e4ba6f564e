#pragma once
// Golden images of the examples: the frame kGoldenFrame of each, rendered on the exact simulator,
// for each class of device the examples fit themselves to (fit.hpp).
#include <filesystem>
#include <string>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/sim/options.hpp"

namespace gpubridge::examples {

// Renders frames 0..frames.back() of the example as configured, on a fresh simulator, and
// returns the scanned-out images of `frames` (ascending), in that order; any device error flag is
// an error.
struct GoldenFrame {
  unsigned frame = 0;
  Image image;
};
Result<std::vector<GoldenFrame>> render_frames(Example& ex, const std::vector<unsigned>& frames,
                                               const sim::DeviceOptions& device = {});
// DIR/NAME.png for kGoldenFrame, DIR/NAME-fN.png for a later golden frame N.
std::filesystem::path golden_path(const std::filesystem::path& dir, const std::string& name, unsigned frame = kGoldenFrame);

// A class of device with golden images of every example.
struct GoldenClass {
  std::string name;         // "large", "up5k", "up5k-min"
  std::string description;  // one line
  DeviceCaps device;
};
// large: the default simulator (what every example wants); up5k: 128 KiB and 320x240 at most,
// every feature (iCEBreaker and the other 128 KiB board profiles); up5k-min: the same with only
// RGBA2222 and the dither (no RGB565, bilinear filtering or blending: the least a UP5K design offers).
const std::vector<GoldenClass>& golden_classes();
const GoldenClass* find_golden_class(std::string_view name);
// Configures the example for the class, then renders its golden frames there (threads: the
// simulator's rasteriser threads; the output does not depend on them).
Result<std::vector<GoldenFrame>> render_golden_frames(Example& ex, const GoldenClass& cls, unsigned threads = 1);
// The same, frame kGoldenFrame only.
Result<Image> render_golden_frame(Example& ex, const GoldenClass& cls, unsigned threads = 1);
// golden_path(DIR, NAME, FRAME) for the large class, the same in DIR/CLASS for the others.
std::filesystem::path golden_path(const std::filesystem::path& dir, const GoldenClass& cls, const std::string& name,
                                  unsigned frame = kGoldenFrame);

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
