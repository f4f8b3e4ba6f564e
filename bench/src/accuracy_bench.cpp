// Orchestration of `gpubridge bench accuracy` (see accuracy_bench.hpp): llvmpipe first (in child
// processes, before any simulator worker threads exist), then every simulator configuration.
#include "gpubridge/bench/accuracy_bench.hpp"

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string_view>
#include <thread>

#include "error_measure.hpp"
#include "fill_ceiling.hpp"
#include "llvmpipe_runner.hpp"
#include "minimal_gl_runner.hpp"
#include "sim_runner.hpp"

namespace gpubridge::bench {
namespace {

sim::AccuracyKnobs knobs(unsigned recip, unsigned nr, unsigned sub, unsigned zb) {
  sim::AccuracyKnobs k;
  k.recip_bits = recip;
  k.nr_steps = nr;
  k.subpixel_bits = sub;
  k.z_bits = zb;
  return k;
}

sim::AccuracyKnobs preview() {
  sim::AccuracyKnobs k;
  k.preview = true;
  return k;
}

}  // namespace

std::string machine_description() {
  std::string cpu = "unknown CPU";
  std::ifstream info("/proc/cpuinfo");
  for (std::string line; std::getline(info, line);)
    if (line.rfind("model name", 0) == 0) {
      cpu = line.substr(line.find(':') + 2);
      break;
    }
  std::string load;
  std::ifstream la("/proc/loadavg");
  std::getline(la, load);
  std::ostringstream o;
  o << cpu << ", " << std::thread::hardware_concurrency() << " hardware threads, load average at start: "
    << load.substr(0, load.find(' ', load.find(' ', load.find(' ') + 1) + 1));
  return o.str();
}

std::vector<sim::AccuracyKnobs> bench_configs() {
  return {
      knobs(10, 1, 4, 24),  // exact: the hardware (docs/protocol.md)
      knobs(8, 1, 4, 24),   // hardware-precision knobs: smaller reciprocal table
      knobs(8, 0, 4, 24),   // table only, no Newton-Raphson
      knobs(6, 0, 4, 24),   // tiny table only
      knobs(12, 2, 4, 24),  // more precise than the hardware
      knobs(10, 1, 2, 24),  // 1/4-pixel vertices
      knobs(10, 1, 0, 24),  // whole-pixel vertices
      knobs(10, 1, 4, 16),  // 16-bit depth
      preview(),            // the preview rasteriser (float planes and perspective)
  };
}

Result<Report> run_accuracy_bench(const AccuracyBenchOptions& opt, const std::function<void(const std::string&)>& progress) {
  Report rep;
  rep.machine = machine_description();
  progress("generating scenes");
  auto scenes_r = make_scenes(opt.quick ? 200 : std::max(1u, opt.scale));
  if (!scenes_r) return scenes_r.error();
  rep.scenes = std::move(scenes_r).value();
  if (!opt.scenes.empty()) {
    std::vector<Scene> chosen;
    for (const auto& name : opt.scenes) {
      auto it = std::find_if(rep.scenes.begin(), rep.scenes.end(), [&](const Scene& s) { return s.name == name; });
      if (it == rep.scenes.end()) {
        std::string known;
        for (const auto& s : rep.scenes) known += (known.empty() ? "" : ", ") + s.name;
        return make_error("unknown scene '" + name + "' (scenes: " + known + ")");
      }
      chosen.push_back(std::move(*it));
      rep.scenes.erase(it);
    }
    rep.scenes = std::move(chosen);
  }
  const unsigned runs = opt.quick ? 1 : std::max(1u, opt.runs);
  // Every timed side (simulator, peer, minimal program) takes its best frame by this rule.
  const FrameBudget budget{runs, opt.quick ? 0.0 : std::clamp(opt.min_seconds, 0.0, 60.0)};
  rep.runs = budget.runs;
  rep.min_seconds = budget.min_seconds;
  const unsigned rounds = opt.quick ? 1 : std::max(1u, opt.peer_rounds);

  progress("reference rasterisation of the error subsets");
  std::vector<ReferenceFrame> refs;
  for (const auto& s : rep.scenes) refs.push_back(reference_frame(s));

  // llvmpipe: one child process per thread count (LP_NUM_THREADS 0 = one core, 2 = two threads),
  // each followed by the minimal GL program on the scenes it draws, at the same thread count.
  std::vector<std::optional<LlvmpipeResult>> lp(opt.threads.size());
  std::vector<std::vector<std::optional<MinimalGlRun>>> minimal(opt.threads.size(),
                                                               std::vector<std::optional<MinimalGlRun>>(rep.scenes.size()));
  if (opt.llvmpipe) {
    auto minimal_exe = find_minimal_gl();
    rep.minimal_gl = minimal_exe ? *minimal_exe : minimal_exe.error().message;
    // Rounds alternate the peer and the minimal program so a burst of load on the shared machine
    // does not land on one of them only; each keeps its best frame over the rounds.
    bool peer_failed = false;
    for (std::size_t ti = 0; ti < opt.threads.size() && !peer_failed; ++ti) {
      const unsigned t = opt.threads[ti];
      const unsigned lp_threads = t == 1 ? 0 : t;
      for (unsigned round = 0; round < rounds && !peer_failed; ++round) {
        progress("llvmpipe, " + std::to_string(t) + " thread(s), round " + std::to_string(round + 1));
        auto r = run_llvmpipe(rep.scenes, refs, lp_threads, budget, t == 1 && round == 0);
        if (!r) {
          rep.llvmpipe = r.error().message;
          rep.llvmpipe_ok = false;
          peer_failed = true;
          break;
        }
        rep.llvmpipe = r->renderer;
        rep.llvmpipe_ok = true;
        if (!lp[ti]) lp[ti] = std::move(r).value();
        else
          for (std::size_t si = 0; si < rep.scenes.size(); ++si)
            lp[ti]->seconds[si] = std::min(lp[ti]->seconds[si], r->seconds[si]);
        for (std::size_t si = 0; minimal_exe && si < rep.scenes.size(); ++si) {
          if (!minimal_gl_draws(rep.scenes[si])) continue;
          progress("minimal GL program, " + std::to_string(t) + " thread(s), " + rep.scenes[si].name);
          auto m = run_minimal_gl(*minimal_exe, rep.scenes[si], lp_threads, budget);
          if (!m) return m.error();  // llvmpipe ran a moment ago: a failure here is a bug to see
          if (!minimal[ti][si] || m->best_seconds < minimal[ti][si]->best_seconds) minimal[ti][si] = *m;
        }
      }
    }
    if (!rep.llvmpipe_ok) lp.assign(opt.threads.size(), std::nullopt);
  } else {
    rep.llvmpipe = "not measured (--no-llvmpipe)";
    rep.minimal_gl = "not run (--no-llvmpipe)";
  }

  progress("fill ceiling");
  rep.ceiling = measure_fill_ceiling(opt.threads, runs, opt.quick);
  auto fill_fraction = [&](unsigned t, double mpix_s) -> std::optional<double> {
    for (const auto& c : rep.ceiling)
      if (c.threads == t && c.cache_mpix_s > 0) return mpix_s / c.cache_mpix_s;
    return std::nullopt;
  };

  auto configs = bench_configs();
  if (opt.exact_only) configs.resize(1);
  if (opt.preview_only) configs = {configs.front(), configs.back()};
  // A simulator row's rates from its best frame, against the peer at the same thread count.
  auto set_sim_speed = [&](Row& row, double seconds, std::size_t si, std::size_t ti) {
    row.seconds = seconds;
    row.mtri_s = double(rep.scenes[si].triangles.size()) / seconds / 1e6;
    row.mpix_s = double(rep.scene_pixels[si]) / seconds / 1e6;
    row.fill_fraction = fill_fraction(row.threads, row.mpix_s);
    if (lp[ti]) row.ratio_vs_llvmpipe = lp[ti]->seconds[si] / seconds;
  };
  // Preview rows carry the exact rate measured alternately with them (same scene and threads), so
  // their ratio is side by side even when the machine's load drifts between configurations.
  struct PreviewPair {
    std::string scene;
    unsigned threads;
    double exact_seconds, preview_seconds;
  };
  std::vector<PreviewPair> pairs;
  rep.scene_pixels.assign(rep.scenes.size(), 0);
  for (std::size_t ci = 0; ci < configs.size(); ++ci) {
    const auto& k = configs[ci];
    for (std::size_t si = 0; si < rep.scenes.size(); ++si) {
      const Scene& s = rep.scenes[si];
      progress("sim " + sim::to_string(k) + ", " + s.name);
      std::optional<ErrorStats> err;
      auto frame = render_sim_error_pass(s, k);
      if (!frame) return frame.error();
      err = measure_error(s, refs[si], *frame);
      for (std::size_t ti = 0; ti < opt.threads.size(); ++ti) {
        const unsigned t = opt.threads[ti];
        auto timing = time_sim(s, k, t, budget);
        if (!timing) return timing.error();
        if (k.preview) {
          // Exact, preview, exact, preview: each keeps its best frame of both rounds.
          double exact_best = 1e30;
          for (unsigned round = 0; round < 2; ++round) {
            auto e = time_sim(s, configs.front(), t, budget);
            if (!e) return e.error();
            exact_best = std::min(exact_best, e->best_seconds);
            if (round == 0) continue;
            auto again = time_sim(s, k, t, budget);
            if (!again) return again.error();
            timing->best_seconds = std::min(timing->best_seconds, again->best_seconds);
          }
          pairs.push_back({s.name, t, exact_best, timing->best_seconds});
        }
        if (ci == 0 && ti == 0) rep.scene_pixels[si] = timing->pixels_covered;
        Row row;
        row.renderer = "sim";
        row.config = ci == 0 ? "exact" : sim::to_string(k);
        row.scene = s.name;
        row.threads = t;
        set_sim_speed(row, timing->best_seconds, si, ti);
        if (ti == 0) row.error = err;  // error does not depend on the thread count (tested)
        rep.rows.push_back(row);
      }
    }
  }
  // Issue 17's goals compare the exact rows with the peer, which keeps its best frame of `rounds`
  // rounds: the exact configuration gets as many rounds, the later ones after every other
  // configuration, so that one burst of load on the shared machine decides neither side alone.
  for (unsigned round = 1; rep.llvmpipe_ok && round < rounds; ++round)
    for (std::size_t si = 0; si < rep.scenes.size(); ++si)
      for (std::size_t ti = 0; ti < opt.threads.size(); ++ti) {
        const unsigned t = opt.threads[ti];
        progress("sim exact, " + rep.scenes[si].name + ", round " + std::to_string(round + 1));
        auto again = time_sim(rep.scenes[si], configs.front(), t, budget);
        if (!again) return again.error();
        for (auto& row : rep.rows)
          if (row.config == "exact" && row.scene == rep.scenes[si].name && row.threads == t &&
              again->best_seconds < row.seconds)
            set_sim_speed(row, again->best_seconds, si, ti);
      }
  for (std::size_t ti = 0; ti < opt.threads.size(); ++ti) {
    if (!lp[ti]) continue;
    for (std::size_t si = 0; si < rep.scenes.size(); ++si) {
      Row row;
      row.renderer = "llvmpipe";
      row.config = opt.threads[ti] == 1 ? "LP_NUM_THREADS=0" : "LP_NUM_THREADS=" + std::to_string(opt.threads[ti]);
      row.scene = rep.scenes[si].name;
      row.threads = opt.threads[ti];
      row.seconds = lp[ti]->seconds[si];
      row.mtri_s = double(rep.scenes[si].triangles.size()) / row.seconds / 1e6;
      row.mpix_s = double(rep.scene_pixels[si]) / row.seconds / 1e6;
      row.fill_fraction = fill_fraction(row.threads, row.mpix_s);
      row.error = lp[ti]->error[si];
      if (const auto& m = minimal[ti][si]) {
        row.minimal_gl_seconds = m->best_seconds;
        row.vs_minimal_gl = m->best_seconds / row.seconds;
        row.minimal_gl_same_image = m->pixel_sum == lp[ti]->pixel_sum[si];
      }
      rep.rows.push_back(row);
    }
  }

  // Speed goals of issue 17 against the fair peer, per thread count, with the measured values
  // (issue 3's goals, 2x / 1.5x / 1x at one thread, were met against the old one-shader peer).
  auto find = [&](const std::string& renderer, const std::string& config, const std::string& scene, unsigned t) -> const Row* {
    for (const auto& r : rep.rows)
      if (r.renderer == renderer && r.config == config && r.scene == scene && r.threads == t) return &r;
    return nullptr;
  };
  struct Goal {
    const char* scene;
    const char* what;
    double target;
    bool pixels;
  };
  const Goal goals[] = {
      {"tri10-front", "10-px triangles (front), tri/s", 1.5, false},
      {"tri1k-front", "1,000-px triangles (front), tri/s", 1.3, false},
      {"tri50k-front", "50,000-px triangles (front), px/s", 1.2, true},
      {"tri10-random", "10-px triangles (random Z), px/s", 1.0, true},
      {"tri1k-random", "1,000-px triangles (random Z), px/s", 1.0, true},
      {"tri50k-random", "50,000-px triangles (random Z), px/s", 1.0, true},
      {"road", "road (perspective, bilinear, 4 MiB texture), px/s", 1.0, true},
      {"cubes", "cubes (perspective, bilinear, 4 MiB texture), px/s", 1.0, true},
      {"fan", "fan, px/s", 1.2, true},
      {"alpha-blend", "alpha-blend, px/s", 1.2, true},
  };
  for (unsigned t : opt.threads)
    for (const Goal& g : goals) {
      const Row* a = find("sim", "exact", g.scene, t);
      if (!a) continue;  // scene not run (--scene)
      const std::string text = "exact, " + std::to_string(t) + (t == 1 ? " thread, " : " threads, ") + g.what + " vs llvmpipe";
      if (!a->ratio_vs_llvmpipe) {
        rep.goals.push_back(text + ": not measured (no llvmpipe row)");
        continue;
      }
      std::ostringstream o;
      o.precision(3);
      o << text << ": " << *a->ratio_vs_llvmpipe << "x (goal >= " << g.target << "x, "
        << (*a->ratio_vs_llvmpipe >= g.target ? "met" : "MISSED") << "; sim " << (g.pixels ? a->mpix_s : a->mtri_s)
        << (g.pixels ? " Mpix/s" : " Mtri/s") << ")";
      rep.goals.push_back(o.str());
    }
  // The goal is for large triangles; the medium scene's scaling is listed beside it, marked as such
  // (it was once labelled as a goal line by mistake).
  for (const char* scene : {"tri50k-front", "tri50k-random", "tri1k-front"}) {
    const Row* one = find("sim", "exact", scene, 1);
    const Row* two = find("sim", "exact", scene, 2);
    if (one && two) {
      std::ostringstream o;
      o << std::fixed;
      o.precision(2);
      const double ratio = one->seconds / two->seconds;
      const bool large = std::string_view(scene).starts_with("tri50k");
      o << "exact, 2 threads vs 1 thread, " << scene << ": " << ratio << "x ";
      if (large)
        o << "(goal >= 1.8x on large triangles, " << (ratio >= 1.8 ? "met" : "MISSED") << ")";
      else
        o << "(1,000-px triangles, for reference: the 1.8x goal is for large triangles)";
      rep.goals.push_back(o.str());
    }
  }
  // Issue 24's goal: the preview path at >= 2x the exact path's rate on every scene, 1 and 2 threads.
  for (const auto& p : pairs) {
    std::ostringstream o;
    o << std::fixed;
    o.precision(2);
    const double ratio = p.exact_seconds / p.preview_seconds;
    o << "preview vs exact, " << p.threads << (p.threads == 1 ? " thread, " : " threads, ") << p.scene << ": " << ratio
      << "x (goal >= 2x, " << (ratio >= 2.0 ? "met" : "MISSED") << "; measured alternately, best frame exact "
      << 1e3 * p.exact_seconds << " ms, preview " << 1e3 * p.preview_seconds << " ms)";
    rep.preview_goals.push_back(o.str());
  }
  for (auto& s : rep.scenes) rep.scene_triangles.push_back(s.triangles.size());
  for (auto& s : rep.scenes) s.triangles.clear();  // descriptions only from here on
  if (opt.cordic) {
    auto front = run_cordic_front({.runs = 4 * runs, .quick = opt.quick}, progress);
    if (!front) return front.error();
    rep.cordic = std::move(front).value();
  }
  return rep;
}

}  // namespace gpubridge::bench
