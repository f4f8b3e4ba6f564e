// `gpubridge compare A.png B.png`: per-pixel comparison for golden-image checks. Exit 0 when the
// largest channel difference is within --tolerance, 1 beyond it (or on an error), 2 on usage.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gpubridge/common/image.hpp"
#include "gpubridge/common/json_text.hpp"

namespace gpubridge::cli {
namespace {

struct CompareArgs {
  std::string a, b, diff;
  unsigned tolerance = 0;
};

int run_compare(const GlobalOptions& g, const CompareArgs& args) {
  auto a = load_png(args.a);
  if (!a) return std::fprintf(stderr, "gpubridge compare: %s\n", a.error().message.c_str()), 1;
  auto b = load_png(args.b);
  if (!b) return std::fprintf(stderr, "gpubridge compare: %s\n", b.error().message.c_str()), 1;
  if (a->width != b->width || a->height != b->height) {
    std::fprintf(stderr, "gpubridge compare: %s is %ux%u but %s is %ux%u; only images of the same size compare\n",
                 args.a.c_str(), a->width, a->height, args.b.c_str(), b->width, b->height);
    return 1;
  }
  // Diff image: matching pixels as a dimmed grey copy of A, differences within tolerance yellow,
  // beyond tolerance red (brighter = larger).
  Image diff{a->width, a->height, std::vector<std::uint8_t>(a->rgba.size())};
  std::uint64_t differing = 0, beyond = 0;
  unsigned max_diff = 0;
  for (std::size_t i = 0; i < a->rgba.size(); i += 4) {
    unsigned d = 0;
    for (int c = 0; c < 4; ++c) d = std::max(d, static_cast<unsigned>(std::abs(int(a->rgba[i + c]) - int(b->rgba[i + c]))));
    max_diff = std::max(max_diff, d);
    std::uint8_t* p = &diff.rgba[i];
    if (d == 0) {
      const unsigned luma = (a->rgba[i] * 77u + a->rgba[i + 1] * 150u + a->rgba[i + 2] * 29u) >> 8;
      p[0] = p[1] = p[2] = static_cast<std::uint8_t>(luma / 4);
    } else if (d <= args.tolerance) {
      ++differing;
      p[0] = 255, p[1] = 255, p[2] = 0;
    } else {
      ++differing;
      ++beyond;
      p[0] = static_cast<std::uint8_t>(std::min(255u, 128 + d)), p[1] = 0, p[2] = 0;
    }
    p[3] = 255;
  }
  if (!args.diff.empty())
    if (auto r = save_png(args.diff, diff); !r)
      return std::fprintf(stderr, "gpubridge compare: %s\n", r.error().message.c_str()), 1;
  const bool ok = max_diff <= args.tolerance;
  if (g.json) {
    nlohmann::json j{{"a", args.a},
                     {"b", args.b},
                     {"width", a->width},
                     {"height", a->height},
                     {"pixels", std::uint64_t{a->width} * a->height},
                     {"differing_pixels", differing},
                     {"pixels_beyond_tolerance", beyond},
                     {"max_difference", max_diff},
                     {"tolerance", args.tolerance},
                     {"match", ok}};
    if (!args.diff.empty()) j["diff"] = args.diff;
    std::puts(json_text(j, 2).c_str());
  } else {
    std::printf("%s: %llu of %llu pixels differ, max channel difference %u (tolerance %u, %llu beyond)%s\n",
                ok ? "match" : "MISMATCH", static_cast<unsigned long long>(differing),
                static_cast<unsigned long long>(std::uint64_t{a->width} * a->height), max_diff, args.tolerance,
                static_cast<unsigned long long>(beyond), args.diff.empty() ? "" : ("; diff image " + args.diff).c_str());
  }
  return ok ? 0 : 1;
}

}  // namespace

GPUBRIDGE_COMMAND("compare", 11, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  auto* sub = app.add_subcommand("compare", "compare two PNG images; exit 1 when they differ beyond --tolerance");
  auto a = std::make_shared<CompareArgs>();
  sub->add_option("A", a->a, "first PNG")->required();
  sub->add_option("B", a->b, "second PNG")->required();
  sub->add_option("--tolerance,-t", a->tolerance, "largest allowed per-channel difference (0..255)")
      ->check(CLI::Range(0u, 255u))
      ->capture_default_str();
  sub->add_option("--diff", a->diff, "write a diff image (grey: equal, yellow: within tolerance, red: beyond)");
  runners.emplace_back(sub, [&g, a] { return run_compare(g, *a); });
});

}  // namespace gpubridge::cli
