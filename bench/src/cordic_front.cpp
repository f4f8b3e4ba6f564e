// The CORDIC front of `gpubridge bench accuracy` (cordic_front.hpp): host time and image error of
// the torus example's shift-and-add vertex stage against its floating-point path.
#include "gpubridge/bench/cordic_front.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <numeric>
#include <optional>
#include <span>
#include <sstream>

#include <fmt/format.h>

#include "gpubridge/bench/accuracy_bench.hpp"
#include "gpubridge/examples/golden.hpp"
#include "gpubridge/examples/torus.hpp"

namespace gpubridge::bench {
namespace {

using Clock = std::chrono::steady_clock;
constexpr double kVertexGrid = 1.0 / 16;  // s12.4 vertex positions: the knee criterion

std::vector<unsigned> iteration_counts(bool quick) {
  if (quick) return {4, 8, 16};
  std::vector<unsigned> out;
  for (unsigned k = examples::cordic::kMinIterations; k <= examples::cordic::kMaxIterations; ++k) out.push_back(k);
  return out;
}

// Register frames are encoded and dropped: the host's work without a link or a device.
class DiscardSink final : public draw::CommandSink {
 public:
  Result<void> write_frames(protocol::FrameView) override { return {}; }
  Result<void> upload(std::uint32_t, std::span<const std::uint8_t>) override { return {}; }
  Result<std::vector<std::uint8_t>> readback(std::uint32_t, std::uint32_t) override {
    return make_error("the bench's discarding sink has no memory to read");
  }
  Result<void> flush() override { return {}; }
  // The default simulator's memory; CAPS 0 reads as every feature (the example is not fitted).
  backends::DeviceInfo device() const override {
    backends::DeviceInfo info;
    info.backend = "discard";
    info.vram_bytes = 8u << 20;
    return info;
  }
};

// One vertex-stage configuration under timing: its geometry alone (vertex stage), and the whole
// example drawing into a discarding sink (host frame).
struct Timed {
  unsigned iterations = 0;
  std::unique_ptr<examples::TorusGeometry> geometry;
  examples::TorusGeometry::Frame frame;
  std::unique_ptr<examples::Example> example;
  DiscardSink sink;
  std::optional<draw::Context> context;
  double vertex_us = 1e300, frame_us = 1e300;
};

double us_since(Clock::time_point t0) { return std::chrono::duration<double, std::micro>(Clock::now() - t0).count(); }

// Best time per frame over `runs` passes of frames 0..frames-1 for every configuration, the
// configurations interleaved within each pass (so load changes on a shared machine hit them
// alike); pass 0 warms caches and allocators and is not counted.
Result<void> time_configurations(std::vector<Timed>& all, unsigned frames, unsigned runs) {
  for (auto& t : all) {
    t.geometry = std::make_unique<examples::TorusGeometry>(t.iterations);
    t.example = examples::make_torus({.cordic_iterations = t.iterations});
    auto ctx = draw::Context::create(t.sink, t.example->options());
    if (!ctx) return ctx.error();
    t.context.emplace(std::move(ctx).value());
    if (auto r = t.example->setup(*t.context); !r) return r.error();
  }
  for (unsigned run = 0; run <= runs; ++run)
    for (auto& t : all) {
      auto t0 = Clock::now();
      for (unsigned n = 0; n < frames; ++n) t.geometry->frame(n, t.frame);
      const double vertex = us_since(t0) / frames;
      t0 = Clock::now();
      for (unsigned n = 0; n < frames; ++n)
        if (auto r = t.example->frame(*t.context, n); !r) return r.error();
      const double frame = us_since(t0) / frames;
      if (run == 0) continue;
      t.vertex_us = std::min(t.vertex_us, vertex);
      t.frame_us = std::min(t.frame_us, frame);
    }
  return {};
}

// Frames 0..frames-1 of the torus in RGBA8888 without dither, on the exact simulator.
Result<std::vector<std::vector<std::uint8_t>>> render_rgba(unsigned iterations, unsigned frames, unsigned& width,
                                                           unsigned& height) {
  auto ex = examples::make_torus({.cordic_iterations = iterations, .rgba8888 = true});
  std::vector<unsigned> numbers(frames);
  std::iota(numbers.begin(), numbers.end(), 0u);
  auto rendered = examples::render_frames(*ex, numbers);
  if (!rendered) return rendered.error();
  std::vector<std::vector<std::uint8_t>> out;
  for (auto& f : *rendered) {
    width = f.image.width;
    height = f.image.height;
    out.push_back(std::move(f.image.rgba));
  }
  return out;
}

// Screen position (pixels) of a model-space point under projection · view · model.
std::pair<double, double> to_screen(const geometry::Mat4& pvm, geometry::Vec3 p, unsigned w, unsigned h) {
  const auto c = pvm * geometry::Vec4{p.x, p.y, p.z, 1};
  return {(c.x / c.w * 0.5 + 0.5) * w, (0.5 - c.y / c.w * 0.5) * h};
}

// Screen distance of every vertex from its floating-point position, max and mean over all frames.
void measure_shift(const examples::TorusGeometry& geo, const std::vector<examples::TorusGeometry::Frame>& float_frames,
                   const geometry::Mat4& pv, unsigned width, unsigned height, CordicRow& row) {
  examples::TorusGeometry::Frame f;
  double sum = 0;
  std::size_t count = 0;
  for (unsigned n = 0; n < float_frames.size(); ++n) {
    geo.frame(n, f);
    const auto& ref = float_frames[n];
    const geometry::Mat4 ref_pvm = pv * ref.model, pvm = pv * f.model;
    for (std::size_t i = 0; i < f.vertices.size(); ++i) {
      const auto a = to_screen(ref_pvm, ref.vertices[i].position, width, height);
      const auto b = to_screen(pvm, f.vertices[i].position, width, height);
      const double d = std::hypot(a.first - b.first, a.second - b.second);
      row.shift_max_px = std::max(row.shift_max_px, d);
      sum += d;
      ++count;
    }
  }
  row.shift_mean_px = count ? sum / double(count) : 0;
}

// Image error of RGBA8888 frames against the floating-point ones. The background is black and
// every lit torus pixel is not: pixels covered in only one of the two frames are edge pixels
// (coverage moved with the vertices); colour is compared where both frames show the torus.
void measure_image(const std::vector<std::vector<std::uint8_t>>& reference,
                   const std::vector<std::vector<std::uint8_t>>& frames, CordicRow& row) {
  double sum = 0;
  std::uint64_t torus = 0, both = 0, channels = 0, differing = 0;
  for (std::size_t n = 0; n < std::min(reference.size(), frames.size()); ++n) {
    const auto& a = reference[n];
    const auto& b = frames[n];
    for (std::size_t p = 0; p + 3 < std::min(a.size(), b.size()); p += 4) {
      const bool in_a = (a[p] | a[p + 1] | a[p + 2]) != 0, in_b = (b[p] | b[p + 1] | b[p + 2]) != 0;
      if (!in_a && !in_b) continue;
      ++torus;
      if (in_a != in_b) {
        ++row.edge_pixels;
        continue;
      }
      ++both;
      bool differs = false;
      for (std::size_t c = 0; c < 3; ++c) {
        const int d = std::abs(int(a[p + c]) - int(b[p + c]));
        row.color_max = std::max(row.color_max, double(d));
        sum += d;
        ++channels;
        differs |= d != 0;
      }
      differing += differs;
    }
  }
  row.color_mean = channels ? sum / double(channels) : 0;
  row.differing_pct = both ? 100.0 * double(differing) / double(both) : 0;
  row.edge_pct = torus ? 100.0 * double(row.edge_pixels) / double(torus) : 0;
}

}  // namespace

Result<CordicFront> run_cordic_front(const CordicFrontOptions& opt, const std::function<void(const std::string&)>& progress) {
  CordicFront front;
  front.machine = machine_description();
  front.frames = opt.quick ? 4 : std::max(1u, opt.frames);
  front.runs = opt.quick ? 1 : std::max(1u, opt.runs);
  progress("CORDIC front: floating-point torus frames");
  auto reference = render_rgba(0, front.frames, front.width, front.height);
  if (!reference) return reference.error();
  const geometry::Mat4 pv =
      geometry::perspective(examples::TorusGeometry::kFovY, double(front.width) / front.height,
                            examples::TorusGeometry::kNear, examples::TorusGeometry::kFar) *
      examples::TorusGeometry::view();
  const examples::TorusGeometry float_geo(0);
  std::vector<examples::TorusGeometry::Frame> float_frames(front.frames);
  for (unsigned n = 0; n < front.frames; ++n) float_geo.frame(n, float_frames[n]);

  std::vector<unsigned> counts = iteration_counts(opt.quick);
  counts.insert(counts.begin(), 0);
  for (unsigned k : counts) {
    CordicRow row;
    row.iterations = k;
    if (k != 0) {
      progress(fmt::format("CORDIC front: {} iterations, error", k));
      const examples::TorusGeometry geo(k);
      measure_shift(geo, float_frames, pv, front.width, front.height, row);
      unsigned w = 0, h = 0;
      auto frames = render_rgba(k, front.frames, w, h);
      if (!frames) return frames.error();
      measure_image(*reference, *frames, row);
      if (!front.knee && row.shift_max_px < kVertexGrid) front.knee = k;
    }
    front.rows.push_back(row);
  }
  progress("CORDIC front: host time of every configuration, interleaved");
  std::vector<Timed> timed(counts.size());
  for (std::size_t i = 0; i < counts.size(); ++i) timed[i].iterations = counts[i];
  if (auto r = time_configurations(timed, front.frames, front.runs); !r) return r.error();
  for (std::size_t i = 0; i < counts.size(); ++i) {
    front.rows[i].vertex_us = timed[i].vertex_us;
    front.rows[i].frame_us = timed[i].frame_us;
    front.rows[i].vertex_ratio = timed[i].vertex_us / timed[0].vertex_us;
  }
  return front;
}

std::string cordic_front_markdown(const CordicFront& f, const std::string& command) {
  std::ostringstream o;
  o << kCordicBegin << "\n"
    << "## CORDIC front: shift-and-add rotation in the torus example (issue 23)\n\n"
    << "Generated by `" << command << "`. The torus example (`examples/src/torus.cpp`, 800 vertices, 1,600 "
       "triangles, " << f.width << "x" << f.height << ") computes its vertex stage (the model rotation of the "
       "positions and the two lighting dot products per vertex) either in floating point or with CORDIC "
       "rotations of n shift-and-add steps (`examples/include/gpubridge/examples/cordic.hpp`), as the donut "
       "ASIC rotates without multipliers. Frames 0.." << f.frames - 1 << ".\n\n"
    << "- Machine: " << f.machine << "\n"
    << "- Host time: best of " << f.runs << " passes over the frames after a warm-up pass, per frame, every "
       "configuration timed in turn within each pass (so load changes hit them alike; the host frame, mostly the "
       "draw library, still varies by a few tenths between configurations on a loaded machine). *Vertex stage*: rotation and "
       "lighting alone; *host frame*: the example's whole frame (vertex stage, then the draw library's "
       "transform, clipping, snapping and register encoding, recorded, not executed). Ratios against the "
       "floating-point path of the same run.\n"
    << "- Vertex shift: screen distance between each CORDIC vertex and the floating-point one of the same frame "
       "(projected in double precision), max and mean over every vertex of every frame.\n"
    << "- Image: the same frames rendered on the exact simulator in RGBA8888 without dither (an LSB is 1/255). "
       "*Edge pixels*: covered by the torus in only one of the two frames (coverage moved with the vertices), "
       "as a share of the pixels it covers in either. *Colour*: |CORDIC - float| per channel where both "
       "frames show the torus (the lighting error), max / mean, and the share of those pixels with any "
       "channel changed.\n\n"
    << "| Vertex stage | µs / frame | vs float | Host frame µs | Shift max / mean (px) | Edge pixels | "
       "Colour max / mean (LSB) | Pixels changed |\n|---|---|---|---|---|---|---|---|\n";
  for (const auto& r : f.rows) {
    const std::string name = r.iterations == 0 ? "floating point" : fmt::format("CORDIC, {} iterations", r.iterations);
    o << "| " << name << fmt::format(" | {:.1f} | {:.2f}x | {:.1f} | ", r.vertex_us, r.vertex_ratio, r.frame_us);
    if (r.iterations == 0)
      o << "- | - | - | - |\n";
    else
      o << fmt::format("{:.3f} / {:.4f} | {:.2f} % | {:.0f} / {:.3f} | {:.2f} % |\n", r.shift_max_px, r.shift_mean_px,
                       r.edge_pct, r.color_max, r.color_mean, r.differing_pct);
  }
  o << "\n";
  const CordicRow *knee = nullptr, *before = nullptr;
  for (std::size_t i = 1; i < f.rows.size(); ++i)
    if (f.knee && f.rows[i].iterations == *f.knee) {
      knee = &f.rows[i];
      if (i > 1) before = &f.rows[i - 1];
    }
  if (knee) {
    const CordicRow& last = f.rows.back();
    const CordicRow& first = f.rows.size() > 1 ? f.rows[1] : last;
    // Cost per iteration: least-squares slope of the vertex-stage time over the CORDIC rows.
    double sk = 0, st = 0, skk = 0, skt = 0, m = 0;
    for (std::size_t i = 1; i < f.rows.size(); ++i) {
      const double k = f.rows[i].iterations, t = f.rows[i].vertex_us;
      sk += k, st += t, skk += k * k, skt += k * t, m += 1;
    }
    const double per_step = m > 1 && m * skk != sk * sk ? (m * skt - sk * st) / (m * skk - sk * sk) : 0;
    o << fmt::format(
        "**Knee: {} iterations.** The fewest whose vertices all stay within 1/16 pixel of the floating-point "
        "ones (max shift {:.3f} px): the device's s12.4 vertex grid sees at most one subpixel step of "
        "difference, {:.2f} % of the torus's pixels are edge pixels and the colour error is {:.0f} LSB max, "
        "{:.3f} mean.",
        knee->iterations, knee->shift_max_px, knee->edge_pct, knee->color_max, knee->color_mean);
    if (before)
      o << fmt::format(" With {} iterations vertices move up to {:.3f} px ({:.2f} % edge pixels, colour {:.3f} LSB mean).",
                       before->iterations, before->shift_max_px, before->edge_pct, before->color_mean);
    o << fmt::format(" Each iteration costs about {:.1f} µs of vertex stage per frame ({} to {} iterations: {:.2f}x to {:.2f}x "
                     "the floating-point time); past the knee it buys only sub-grid vertex motion.\n\n",
                     per_step, first.iterations, last.iterations, first.vertex_ratio, last.vertex_ratio);
  } else {
    o << "**Knee: not reached** (no iteration count kept every vertex within 1/16 pixel).\n\n";
  }
  o << "![CORDIC front: vertex shift and host time against iterations](cordic-front.svg)\n" << kCordicEnd << "\n";
  return o.str();
}

nlohmann::json cordic_front_json(const CordicFront& f) {
  nlohmann::json j;
  j["machine"] = f.machine;
  j["frames"] = f.frames;
  j["runs"] = f.runs;
  j["width"] = f.width;
  j["height"] = f.height;
  j["knee_iterations"] = f.knee ? nlohmann::json(*f.knee) : nlohmann::json(nullptr);
  j["rows"] = nlohmann::json::array();
  for (const auto& r : f.rows) {
    nlohmann::json jr{{"iterations", r.iterations}, {"path", r.iterations == 0 ? "float" : "cordic"},
                      {"vertex_us", r.vertex_us},   {"vertex_ratio", r.vertex_ratio},
                      {"frame_us", r.frame_us}};
    if (r.iterations != 0) {
      jr["shift_max_px"] = r.shift_max_px;
      jr["shift_mean_px"] = r.shift_mean_px;
      jr["edge_pixels"] = r.edge_pixels;
      jr["edge_pct"] = r.edge_pct;
      jr["colour_max_lsb"] = r.color_max;
      jr["colour_mean_lsb"] = r.color_mean;
      jr["differing_pct"] = r.differing_pct;
    }
    j["rows"].push_back(jr);
  }
  return j;
}

// Two panels against the iteration count: vertex shift (log scale, with the 1/16-pixel line and
// the knee) and the vertex stage's host time relative to floating point.
std::string cordic_front_svg(const CordicFront& f) {
  std::vector<const CordicRow*> rows;
  for (const auto& r : f.rows)
    if (r.iterations != 0) rows.push_back(&r);
  const int pw = 400, ph = 260, margin = 60, gap = 70;
  const int width = 2 * pw + gap + 2 * margin, height = ph + 2 * margin + 10;
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
    << "\" font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    << "<text x=\"" << margin << "\" y=\"20\" font-size=\"14\">Torus vertex stage: CORDIC iterations against error and "
       "host time (floating point = 1)</text>\n";
  if (rows.empty()) return o.str() + "</svg>\n";
  const double k0 = rows.front()->iterations, k1 = rows.back()->iterations;
  auto X = [&](int ox, double k) { return ox + (k1 > k0 ? (k - k0) / (k1 - k0) : 0.5) * pw; };
  auto panel = [&](int ox, const char* title, const char* yname) {
    o << fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#444\"/>\n", ox, margin, pw, ph)
      << fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"12\">{}</text>\n", ox, margin - 8, title)
      << fmt::format("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">iterations</text>\n", ox + pw / 2, margin + ph + 32)
      << fmt::format("<text x=\"{}\" y=\"{}\" transform=\"rotate(-90 {} {})\" text-anchor=\"middle\">{}</text>\n", ox - 42,
                     margin + ph / 2, ox - 42, margin + ph / 2, yname);
    for (const auto* r : rows)
      o << fmt::format("<text x=\"{:.1f}\" y=\"{}\" text-anchor=\"middle\">{}</text>\n", X(ox, r->iterations), margin + ph + 14,
                       r->iterations);
  };
  auto polyline = [&](const std::vector<std::pair<double, double>>& pts, const char* color, const char* label, int ly) {
    o << "<polyline fill=\"none\" stroke=\"" << color << "\" stroke-width=\"1.8\" points=\"";
    for (const auto& [x, y] : pts) o << fmt::format("{:.1f},{:.1f} ", x, y);
    o << "\"/>\n";
    for (const auto& [x, y] : pts) o << fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"2.5\" fill=\"{}\"/>", x, y, color);
    o << fmt::format("\n<text x=\"{}\" y=\"{}\" fill=\"{}\">{}</text>\n", pts.empty() ? 0.0 : pts.back().first - 120, ly, color, label);
  };
  // Left: shift in pixels, log10 from 1e-4 to the largest.
  const int ox0 = margin;
  panel(ox0, "vertex shift against the floating-point path (pixels, log scale)", "pixels");
  double ymax = 1e-3;
  for (const auto* r : rows) ymax = std::max(ymax, r->shift_max_px);
  const double l0 = -4, l1 = std::ceil(std::log10(ymax));
  auto Y = [&](double v) { return margin + ph - (std::log10(std::max(v, 1e-4)) - l0) / (l1 - l0) * ph; };
  for (double e = l0; e <= l1; e += 1) {
    const double v = std::pow(10.0, e);
    o << fmt::format("<line x1=\"{}\" y1=\"{:.1f}\" x2=\"{}\" y2=\"{:.1f}\" stroke=\"#ddd\"/>", ox0, Y(v), ox0 + pw, Y(v))
      << fmt::format("<text x=\"{}\" y=\"{:.1f}\" text-anchor=\"end\">{}</text>\n", ox0 - 4, Y(v) + 4, fmt::format("{:g}", v));
  }
  o << fmt::format("<line x1=\"{}\" y1=\"{:.1f}\" x2=\"{}\" y2=\"{:.1f}\" stroke=\"#c33\" stroke-dasharray=\"4 3\"/>", ox0,
                   Y(kVertexGrid), ox0 + pw, Y(kVertexGrid))
    << fmt::format("<text x=\"{}\" y=\"{:.1f}\" fill=\"#c33\">1/16 px (s12.4 grid)</text>\n", ox0 + 4, Y(kVertexGrid) - 4);
  std::vector<std::pair<double, double>> smax, smean;
  for (const auto* r : rows) {
    smax.emplace_back(X(ox0, r->iterations), Y(r->shift_max_px));
    smean.emplace_back(X(ox0, r->iterations), Y(r->shift_mean_px));
  }
  polyline(smax, "#36c", "max", margin + 16);
  polyline(smean, "#2a7", "mean", margin + 30);
  if (f.knee)
    o << fmt::format("<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" stroke=\"#888\" stroke-dasharray=\"2 2\"/>"
                     "<text x=\"{3:.1f}\" y=\"{4}\" fill=\"#444\">knee: {5}</text>\n",
                     X(ox0, *f.knee), margin, margin + ph, X(ox0, *f.knee) + 4, margin + ph - 8, *f.knee);
  // Right: vertex-stage time relative to floating point (linear from 0).
  const int ox1 = margin + pw + gap;
  panel(ox1, "vertex stage host time / floating point", "ratio");
  double rmax = 1;
  for (const auto* r : rows) rmax = std::max(rmax, r->vertex_ratio);
  rmax = std::ceil(rmax);
  auto R = [&](double v) { return margin + ph - v / rmax * ph; };
  for (double t = 0; t <= rmax; t += rmax > 8 ? 2 : 1)
    o << fmt::format("<line x1=\"{}\" y1=\"{:.1f}\" x2=\"{}\" y2=\"{:.1f}\" stroke=\"#ddd\"/>", ox1, R(t), ox1 + pw, R(t))
      << fmt::format("<text x=\"{}\" y=\"{:.1f}\" text-anchor=\"end\">{:g}</text>\n", ox1 - 4, R(t) + 4, t);
  std::vector<std::pair<double, double>> ratio;
  for (const auto* r : rows) ratio.emplace_back(X(ox1, r->iterations), R(r->vertex_ratio));
  polyline(ratio, "#36c", "CORDIC / float", margin + 16);
  o << "</svg>\n";
  return o.str();
}

Result<std::string> splice_cordic_section(const std::string& report, const std::string& section) {
  const auto b = report.find(kCordicBegin);
  const auto e = report.find(kCordicEnd);
  if (b == std::string::npos && e == std::string::npos) {
    std::string out = report;
    if (!out.empty() && out.back() != '\n') out += '\n';
    return out + "\n" + section;
  }
  if (b == std::string::npos || e == std::string::npos || e < b)
    return make_error("the report's CORDIC section markers are unbalanced (expected one \"" + std::string(kCordicBegin) +
                      "\" followed by one \"" + std::string(kCordicEnd) + "\"); restore them or regenerate the whole report");
  std::size_t end = e + std::string(kCordicEnd).size();
  if (end < report.size() && report[end] == '\n') ++end;
  return report.substr(0, b) + section + report.substr(end);
}

}  // namespace gpubridge::bench
