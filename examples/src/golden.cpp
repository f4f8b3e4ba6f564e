#include "gpubridge/examples/golden.hpp"

#include <algorithm>
#include <cstdlib>

#include <fmt/format.h>

#include "gpubridge/draw/sim_sink.hpp"

namespace gpubridge::examples {

Result<std::vector<GoldenFrame>> render_frames(Example& ex, const std::vector<unsigned>& wanted,
                                               const sim::DeviceOptions& device) {
  if (wanted.empty()) return make_error(ex.info().name + ": no frames to render");
  auto sink = draw::SimulatorSink::create(device);
  if (!sink) return sink.error();
  auto ctx = draw::Context::create(**sink, ex.options());
  if (!ctx) return make_error(ex.info().name + ": " + ctx.error().message);
  std::vector<GoldenFrame> out;
  auto keep = [&](unsigned n) -> Result<void> {
    if (std::find(wanted.begin(), wanted.end(), n) == wanted.end()) return {};
    const auto f = (*sink)->latest_frame();
    if (!f) return make_error(ex.info().name + ": no frame was scanned out");
    out.push_back({n, image_from_device(f->format, f->width, f->height, f->pixels)});
    return {};
  };
  if (auto r = run_frames(ex, *ctx, 0, wanted.back() + 1, keep); !r) return r.error();
  if (const auto errors = (*sink)->backend().device().errors())
    return make_error(fmt::format("{}: the device reported errors: {}", ex.info().name, protocol::describe_errors(errors)));
  return out;
}

std::filesystem::path golden_path(const std::filesystem::path& dir, const std::string& name, unsigned frame) {
  return dir / (frame == kGoldenFrame ? name + ".png" : fmt::format("{}-f{}.png", name, frame));
}

const std::vector<GoldenClass>& golden_classes() {
  static const std::vector<GoldenClass> classes = [] {
    DeviceCaps up5k;
    up5k.name = "up5k";
    up5k.vram_bytes = 128 * 1024;
    up5k.max_width = 320;
    up5k.max_height = 240;
    DeviceCaps up5k_min = up5k;
    up5k_min.name = "up5k-min";
    // a memory and feature class, not a gateware: it keeps the depth buffer (its goldens predate CAPS2)
    up5k_min.features = kDither | kStrictLink | kRgba2222 | kTexturing | kDepthBuffer;
    return std::vector<GoldenClass>{
        {"large", "the default simulator: 8 MiB, 1024x1024, every feature", DeviceCaps{}},
        {"up5k", "128 KiB, 320x240, every feature (iCEBreaker and the 128 KiB board profiles)", up5k},
        {"up5k-min", "128 KiB, 320x240, RGBA2222 and the dither only (no RGB565, bilinear or blending)", up5k_min},
    };
  }();
  return classes;
}

const GoldenClass* find_golden_class(std::string_view name) {
  for (const auto& c : golden_classes())
    if (c.name == name) return &c;
  return nullptr;
}

Result<std::vector<GoldenFrame>> render_golden_frames(Example& ex, const GoldenClass& cls, unsigned threads) {
  if (auto f = configure(ex, cls.device); !f) return f.error();
  auto options = cls.device.simulator_options();
  options.threads = threads;
  return render_frames(ex, ex.golden_frames(), options);
}

Result<Image> render_golden_frame(Example& ex, const GoldenClass& cls, unsigned threads) {
  auto frames = render_golden_frames(ex, cls, threads);
  if (!frames) return frames.error();
  for (auto& f : *frames)
    if (f.frame == kGoldenFrame) return std::move(f.image);
  return make_error(ex.info().name + ": frame " + std::to_string(kGoldenFrame) + " is not among its golden frames");
}

std::filesystem::path golden_path(const std::filesystem::path& dir, const GoldenClass& cls, const std::string& name,
                                  unsigned frame) {
  return golden_path(cls.name == "large" ? dir : dir / cls.name, name, frame);
}

ImageDiff compare_images(const Image& expected, const Image& actual) {
  ImageDiff d;
  if (expected.width != actual.width || expected.height != actual.height) {
    d.size_mismatch = true;
    return d;
  }
  for (unsigned y = 0; y < expected.height; ++y)
    for (unsigned x = 0; x < expected.width; ++x) {
      int m = 0;
      for (int c = 0; c < 4; ++c) m = std::max(m, std::abs(int{expected.pixel(x, y)[c]} - int{actual.pixel(x, y)[c]}));
      if (m == 0) continue;
      ++d.differing_pixels;
      d.max_difference = std::max(d.max_difference, m);
      if (d.first_differences.size() < 10) d.first_differences.emplace_back(x, y);
    }
  return d;
}

std::string ImageDiff::summary() const {
  if (size_mismatch) return "the image size differs from the golden";
  if (differing_pixels == 0) return "identical";
  std::string s = fmt::format("{} pixels differ (max channel difference {}), first at", differing_pixels, max_difference);
  for (const auto& [x, y] : first_differences) s += fmt::format(" ({}, {})", x, y);
  return s;
}

}  // namespace gpubridge::examples
