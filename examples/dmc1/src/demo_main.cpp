// gpubridge-dmc1-demo: the DMC-1 example client. `write` saves frames along the camera path as a
// DMC-1 stream (.dmc1 text or tinygpus .nfo lines) for `gpubridge render --device dmc1` or a board;
// `goldens` renders the golden frames on the DMC-1 simulator and checks (or with --write, rewrites)
// examples/dmc1/golden/.
#include <cstdio>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

#include "gpubridge/common/image.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "gpubridge/dmc1/stream.hpp"
#include "gpubridge/examples/dmc1_level.hpp"

namespace {

using namespace gpubridge;
namespace level = examples::dmc1_level;

int fail(const std::string& msg) {
  std::fprintf(stderr, "gpubridge-dmc1-demo: %s\n", msg.c_str());
  return 1;
}

int write_stream(const std::string& out, unsigned first, unsigned frames, unsigned path_frames) {
  const auto lv = level::hall();
  std::vector<std::uint64_t> words;
  for (unsigned f = first; f < first + frames; ++f) {
    const auto frame = level::frame_commands(lv, level::camera_path(lv, static_cast<double>(f % path_frames) / path_frames));
    words.insert(words.end(), frame.begin(), frame.end());
  }
  if (auto r = dmc1::save_stream(out, words); !r) return fail(r.error().message);
  std::printf("wrote %s: %u frame(s), %zu commands\n", out.c_str(), frames, words.size());
  return 0;
}

int goldens(const std::string& dir, const std::string& textures, const std::string& palette, bool write) {
  auto mem = dmc1::load_texture_memory(textures);
  if (!mem) return fail(mem.error().message);
  auto pal = dmc1::load_palette(palette);
  if (!pal) return fail(pal.error().message);
  int status = 0;
  for (const unsigned f : level::kGoldenFrames) {
    auto dev = dmc1::Device::create({}, *mem, *pal);
    if (!dev) return fail(dev.error().message);
    Image img;
    (*dev)->set_frame_callback([&](const dmc1::Frame& fr) { img = dmc1::frame_image(fr.rgb565); });
    (*dev)->submit(level::golden_frame_commands(f));
    const auto path = std::filesystem::path(dir) / level::golden_name(f);
    if (write) {
      if (auto r = save_png(path, img); !r) return fail(r.error().message);
      std::printf("wrote %s\n", path.c_str());
      continue;
    }
    auto want = load_png(path);
    if (!want) return fail(want.error().message);
    const bool same = *want == img;
    std::printf("%s %s\n", same ? "same     " : "DIFFERENT", path.c_str());
    if (!same) status = 1;
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"gpubridge-dmc1-demo: a small level (walls, floor and ceiling planes, a terrain) ray-cast into DMC-1 spans"};
  app.require_subcommand(1);
  auto* write = app.add_subcommand("write", "write frames along the camera path as a DMC-1 stream file");
  unsigned frames = 1, first = 0, path_frames = level::kPathFrames;
  std::string out;
  write->add_option("--out,-o", out, "stream file (.dmc1 text, .nfo lines)")->required();
  write->add_option("--frames", frames, "frames to write")->check(CLI::Range(1u, 100000u))->capture_default_str();
  write->add_option("--first", first, "first frame (position on the path)")->capture_default_str();
  write->add_option("--path-frames", path_frames, "frames per lap of the camera path")
      ->check(CLI::Range(1u, 100000u))
      ->capture_default_str();
  auto* gold = app.add_subcommand("goldens", "render the golden frames on the DMC-1 simulator and compare them with DIR");
  std::string dir = "examples/dmc1/golden", textures = "tests/dmc1/data/textures.bin.gz", palette = "tests/dmc1/data/palette.bin";
  bool rewrite = false;
  gold->add_option("--dir", dir, "golden directory")->capture_default_str();
  gold->add_option("--textures", textures, "texture memory image")->capture_default_str();
  gold->add_option("--palette", palette, "palette")->capture_default_str();
  gold->add_flag("--write", rewrite, "rewrite the goldens (only when the rendering legitimately changed)");
  CLI11_PARSE(app, argc, argv);
  if (write->parsed()) return write_stream(out, first, frames, path_frames);
  return goldens(dir, textures, palette, rewrite);
}
