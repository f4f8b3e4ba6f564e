#include "gpubridge/examples/figures.hpp"

#include <cmath>
#include <cstdlib>
#include <numeric>

#include <fmt/format.h>

#include "gpubridge/common/image.hpp"
#include "gpubridge/examples/golden.hpp"
#include "gpubridge/examples/torus.hpp"

namespace gpubridge::examples {
namespace {

// Frames 0..count-1 of the torus held at kFigurePose (the temporal phase still follows the frame).
Result<std::vector<Image>> render(const TorusOptions& options, unsigned count) {
  auto ex = make_torus(options);
  std::vector<unsigned> numbers(count);
  std::iota(numbers.begin(), numbers.end(), 0u);
  auto frames = render_frames(*ex, numbers);
  if (!frames) return frames.error();
  std::vector<Image> out;
  for (auto& f : *frames) out.push_back(std::move(f.image));
  return out;
}

// Per-channel mean of the images, rounded.
Image mean_of(const std::vector<Image>& frames, std::size_t first, std::size_t count) {
  Image m = frames[first];
  for (std::size_t i = 0; i < m.rgba.size(); ++i) {
    unsigned sum = 0;
    for (std::size_t f = first; f < first + count; ++f) sum += frames[f].rgba[i];
    m.rgba[i] = static_cast<std::uint8_t>((sum + count / 2) / count);
  }
  return m;
}

// Mean |image - reference| over R, G, B of the pixels the reference torus covers (not black).
double mean_error(const Image& img, const Image& ref) {
  double sum = 0;
  std::size_t n = 0;
  for (std::size_t p = 0; p + 3 < ref.rgba.size(); p += 4) {
    if ((ref.rgba[p] | ref.rgba[p + 1] | ref.rgba[p + 2]) == 0) continue;
    for (std::size_t c = 0; c < 3; ++c) sum += std::abs(int(img.rgba[p + c]) - int(ref.rgba[p + c]));
    n += 3;
  }
  return n ? sum / double(n) : 0;
}

}  // namespace

Result<std::vector<FigureFile>> write_figures(const std::filesystem::path& dir) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return make_error(dir.string() + ": cannot create the directory: " + ec.message());
  std::vector<FigureFile> out;
  auto save = [&](const Image& img, FigureFile f) -> Result<void> {
    if (auto s = save_png(dir / f.file, img); !s) return s;
    out.push_back(std::move(f));
    return {};
  };
  auto reference = render({.rgba8888 = true, .pose = kFigurePose}, 1);
  auto ordered = render({.pose = kFigurePose}, 1);
  auto temporal = render({.temporal = true, .pose = kFigurePose}, 16);
  if (!reference) return reference.error();
  if (!ordered) return ordered.error();
  if (!temporal) return temporal.error();
  const Image& ref = reference->front();
  if (auto r = save(ref, {"dither-reference.png", "RGBA8888, no dither: the 8-bit colours the dithers approximate", 0, false}); !r)
    return r.error();
  if (auto r = save(ordered->front(), {"dither-ordered.png", "RGBA2222, ordered dither (every frame alike)",
                                       mean_error(ordered->front(), ref), true});
      !r)
    return r.error();
  if (auto r = save(temporal->front(), {"dither-temporal.png", "RGBA2222, temporal dither, one frame (phase 0)",
                                        mean_error(temporal->front(), ref), true});
      !r)
    return r.error();
  for (std::size_t n : {2u, 4u, 8u, 16u}) {
    const Image m = mean_of(*temporal, 0, n);
    if (auto r = save(m, {fmt::format("dither-temporal-mean{}.png", n),
                          fmt::format("RGBA2222, temporal dither, mean of {} frames (phases 0..{})", n, n - 1),
                          mean_error(m, ref), true});
        !r)
      return r.error();
  }
  for (unsigned k : {4u, 6u, 8u, 12u}) {
    auto c = render({.cordic_iterations = k, .pose = kFigurePose}, 1);
    if (!c) return c.error();
    if (auto r = save(c->front(), {fmt::format("cordic-{}.png", k),
                                   fmt::format("RGBA2222, ordered dither, vertex stage with {}-step CORDIC rotations", k), 0,
                                   false});
        !r)
      return r.error();
  }
  return out;
}

}  // namespace gpubridge::examples
