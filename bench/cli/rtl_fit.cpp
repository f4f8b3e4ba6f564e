#include "rtl_fit.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

namespace gpubridge::cli {
namespace {

using sim::BoardTiming;
using sim::DeviceStats;

// One term of the model: the counter it multiplies and the parameter it fits.
struct Term {
  std::string key;  // apply_timing_setting key
  std::function<double(const FitSample&)> count;
  std::function<double&(BoardTiming&)> param;
};

enum Stage { kSetup, kRaster, kRest };

// The terms that can cost in each stage (docs/protocol.md section 19, docs/gateware.md).
// sdram: the board has an SDRAM (its preset refreshes), so its row opens and misses can cost.
std::vector<Term> stage_terms(Stage stage, double& clear_byte_cycles, bool sdram) {
  std::vector<Term> t;
  auto clears = [&] {
    // up5k draws a clear as a rectangle (setup + rasteriser); ecp5 fills it beside them
    t.push_back({"cycles_per_clear", [](const FitSample& s) { return double(s.work.clears); },
                 [](BoardTiming& b) -> double& { return b.cycles_per_clear; }});
    t.push_back({"cycles_per_clear_row", [](const FitSample& s) { return double(s.work.clear_rows); },
                 [](BoardTiming& b) -> double& { return b.cycles_per_clear_row; }});
    t.push_back({"cycles_per_clear_pixel", [](const FitSample& s) { return double(s.work.clear_pixels); },
                 [](BoardTiming& b) -> double& { return b.cycles_per_clear_pixel; }});
  };
  for (unsigned m = 0; m < DeviceStats::kModeClasses; ++m) {
    const std::string c = sim::mode_class_name(m);
    if (stage == kSetup)
      t.push_back({"setup_cycles_" + c, [m](const FitSample& s) { return double(s.work.by_mode[m].triangles); },
                   [m](BoardTiming& b) -> double& { return b.setup_cycles[m]; }});
    if (stage != kRaster) continue;
    t.push_back({"row_cycles_" + c, [m](const FitSample& s) { return double(s.work.by_mode[m].rows); },
                 [m](BoardTiming& b) -> double& { return b.row_cycles[m]; }});
    t.push_back({"column_cycles_" + c, [m](const FitSample& s) { return double(s.work.by_mode[m].columns); },
                 [m](BoardTiming& b) -> double& { return b.column_cycles[m]; }});
    t.push_back({"pixel_cycles_" + c, [m](const FitSample& s) { return double(s.work.by_mode[m].pixels); },
                 [m](BoardTiming& b) -> double& { return b.pixel_cycles[m]; }});
  }
  switch (stage) {
    case kSetup:
      t.push_back({"cycles_per_rejected_triangle", [](const FitSample& s) { return double(s.work.triangles_rejected); },
                   [](BoardTiming& b) -> double& { return b.cycles_per_rejected_triangle; }});
      clears();
      break;
    case kRaster:
      t.push_back({"cycles_per_blended_pixel", [](const FitSample& s) { return double(s.work.pixels_blended); },
                   [](BoardTiming& b) -> double& { return b.cycles_per_blended_pixel; }});
      t.push_back({"cycles_per_texel_byte", [](const FitSample& s) { return double(s.work.texel_bytes); },
                   [](BoardTiming& b) -> double& { return b.cycles_per_texel_byte; }});
      t.push_back({"cycles_per_color_byte", [](const FitSample& s) { return double(s.work.pixels_depth_passed) * s.bpp; },
                   [](BoardTiming& b) -> double& { return b.cycles_per_color_byte; }});
      if (sdram) {
        t.push_back({"cycles_per_texel_footprint_byte", [](const FitSample& s) { return double(s.work.texel_footprint_bytes); },
                     [](BoardTiming& b) -> double& { return b.cycles_per_texel_footprint_byte; }});
        t.push_back({"cycles_per_texel_fetch", [](const FitSample& s) { return double(s.work.texel_fetches); },
                     [](BoardTiming& b) -> double& { return b.cycles_per_texel_fetch; }});
        t.push_back({"cycles_per_sdram_access", [](const FitSample& s) { return double(s.work.sdram_accesses); },
                     [](BoardTiming& b) -> double& { return b.cycles_per_sdram_access; }});
        t.push_back({"cycles_per_row_open", [](const FitSample& s) { return double(s.work.row_opens); },
                     [](BoardTiming& b) -> double& { return b.cycles_per_row_open; }});
        t.push_back({"cycles_per_textured_row_miss", [](const FitSample& s) { return double(s.work.textured_row_misses); },
                     [](BoardTiming& b) -> double& { return b.cycles_per_textured_row_miss; }});
        // a credit: the column is negative, so its non-negative parameter subtracts
        t.push_back({"drained_cycles_per_tail_pixel", [](const FitSample& s) { return -double(s.work.depth_tail_pixels); },
                     [](BoardTiming& b) -> double& { return b.drained_cycles_per_tail_pixel; }});
        t.push_back({"cycles_per_depth_write", [](const FitSample& s) { return double(sim::depth_writes(s.work)); },
                     [](BoardTiming& b) -> double& { return b.cycles_per_depth_write; }});
        t.push_back({"cycles_per_row_miss", [](const FitSample& s) { return double(s.work.row_misses - std::min(s.work.row_misses, s.work.textured_row_misses)); },
                     [](BoardTiming& b) -> double& { return b.cycles_per_row_miss; }});
      }
      clears();
      break;
    case kRest:
      t.push_back({"cycles_per_command", [](const FitSample& s) { return double(s.work.queued_executed); },
                   [](BoardTiming& b) -> double& { return b.cycles_per_command; }});
      t.push_back({"cycles_per_triangle", [](const FitSample& s) { return double(s.work.triangles_rasterised); },
                   [](BoardTiming& b) -> double& { return b.cycles_per_triangle; }});
      t.push_back({"cycles_per_mem_write", [](const FitSample& s) { return double(s.work.mem_data_writes); },
                   [](BoardTiming& b) -> double& { return b.cycles_per_mem_write; }});
      clears();
      t.push_back({"clear_bytes_per_cycle", [](const FitSample& s) { return double(s.work.clear_bytes); },
                   [&clear_byte_cycles](BoardTiming&) -> double& { return clear_byte_cycles; }});
      break;
  }
  return t;
}

double stage_target(Stage stage, const rtl::RtlCounters& r) {
  switch (stage) {
    case kSetup: return double(r.setup_cycles);
    case kRaster: return double(r.raster_cycles);
    case kRest: break;
  }
  return double(r.work_cycles) - double(r.setup_cycles) - double(r.raster_cycles);
}

}  // namespace

std::vector<double> nnls(const std::vector<std::vector<double>>& x, const std::vector<double>& y,
                         const std::vector<double>& weight) {
  const std::size_t rows = x.size(), n = rows ? x.front().size() : 0;
  std::vector<double> norm(n, 0.0);
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t j = 0; j < n; ++j) norm[j] += x[r][j] * x[r][j] * weight[r] * weight[r];
  for (auto& v : norm) v = std::sqrt(v);
  // normal equations of the weighted, column-scaled problem
  std::vector<std::vector<double>> ata(n, std::vector<double>(n, 0.0));
  std::vector<double> atb(n, 0.0);
  for (std::size_t r = 0; r < rows; ++r)
    for (std::size_t i = 0; i < n; ++i) {
      if (norm[i] == 0) continue;
      const double xi = x[r][i] * weight[r] / norm[i];
      atb[i] += xi * y[r] * weight[r];
      for (std::size_t j = 0; j < n; ++j)
        if (norm[j] > 0) ata[i][j] += xi * x[r][j] * weight[r] / norm[j];
    }
  std::vector<double> p(n, 0.0);
  for (int sweep = 0; sweep < 20000; ++sweep) {
    double change = 0;
    for (std::size_t j = 0; j < n; ++j) {
      if (ata[j][j] <= 0) continue;
      double g = atb[j];
      for (std::size_t k = 0; k < n; ++k)
        if (k != j) g -= ata[j][k] * p[k];
      const double v = std::max(0.0, g / ata[j][j]);
      change = std::max(change, std::fabs(v - p[j]));
      p[j] = v;
    }
    if (change < 1e-12) break;
  }
  for (std::size_t j = 0; j < n; ++j) p[j] = norm[j] > 0 ? p[j] / norm[j] : 0;
  return p;
}

TimingFit fit_timing(const std::vector<FitSample>& samples, const BoardTiming& base) {
  TimingFit f;
  BoardTiming& b = f.timing;
  b = base;
  b.cycles_per_command = b.cycles_per_triangle = b.cycles_per_scanned_pixel = b.cycles_per_pixel = 0;
  b.cycles_per_textured_pixel = b.cycles_per_blended_pixel = 0;
  b.setup_cycles = b.row_cycles = b.column_cycles = b.pixel_cycles = {};
  b.cycles_per_rejected_triangle = b.cycles_per_clear = b.cycles_per_clear_row = b.cycles_per_clear_pixel = 0;
  b.cycles_per_mem_write = b.cycles_per_texel_byte = b.cycles_per_color_byte = 0;
  b.cycles_per_texel_footprint_byte = b.cycles_per_texel_fetch = 0;
  b.cycles_per_sdram_access = b.cycles_per_row_open = b.cycles_per_row_miss = 0;
  b.cycles_per_textured_row_miss = b.cycles_per_depth_write = b.drained_cycles_per_tail_pixel = 0;
  // The refresh terms are the controller's (tREFI, and tRP + tRFC + tRCD per refresh), kept from
  // `base`: the fit sees each stage's clocks without the refresh's share.
  const bool sdram = b.refresh_interval_cycles > 0;
  const double stretch = sim::refresh_stretch(b);
  b.memory_bound = false;  // the terms are fitted on cycles that include the memory's
  double clear_byte_cycles = 0;
  std::vector<double> weight;  // relative error of the whole frame
  for (const auto& s : samples) weight.push_back(1.0 / std::max(1.0, double(s.rtl.work_cycles)));
  for (Stage stage : {kSetup, kRaster, kRest}) {
    const auto terms = stage_terms(stage, clear_byte_cycles, sdram);
    std::vector<std::vector<double>> x;
    std::vector<double> y;
    for (const auto& s : samples) {
      std::vector<double> row;
      for (const auto& t : terms) row.push_back(t.count(s));
      x.push_back(std::move(row));
      y.push_back(stage_target(stage, s.rtl) / stretch);
    }
    const auto p = nnls(x, y, weight);
    for (std::size_t j = 0; j < terms.size(); ++j) terms[j].param(b) += p[j];
  }
  b.clear_bytes_per_cycle = clear_byte_cycles > 1e-9 ? 1.0 / clear_byte_cycles : 1e9;
  // the listing: every non-zero parameter as a setting
  double unused = 0;
  for (Stage stage : {kSetup, kRaster, kRest})
    for (const auto& t : stage_terms(stage, unused, sdram)) {
      const double v = t.key == "clear_bytes_per_cycle" ? b.clear_bytes_per_cycle : t.param(b);
      const bool listed = std::any_of(f.parameters.begin(), f.parameters.end(), [&](const auto& kv) { return kv.first == t.key; });
      if (!listed && v != 0 && !(t.key == "clear_bytes_per_cycle" && v >= 1e9)) f.parameters.emplace_back(t.key, v);
    }
  return f;
}

}  // namespace gpubridge::cli
