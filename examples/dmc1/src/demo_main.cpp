// gpubridge-dmc1-demo: the DMC-1 example client. `write` saves the camera path's frames as a DMC-1
// stream (.dmc1 text or tinygpus .nfo lines) for `gpubridge render --device dmc1` or a board.
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "gpubridge/dmc1/stream.hpp"
#include "gpubridge/examples/dmc1_level.hpp"

int main(int argc, char** argv) {
  using namespace gpubridge;
  CLI::App app{"gpubridge-dmc1-demo: a small level (walls, floor and ceiling planes, a terrain) ray-cast into DMC-1 spans"};
  app.require_subcommand(1);
  auto* write = app.add_subcommand("write", "write frames along the camera path as a DMC-1 stream file");
  unsigned frames = 1, first = 0, path_frames = 64;
  std::string out;
  write->add_option("--out,-o", out, "stream file (.dmc1 text, .nfo lines)")->required();
  write->add_option("--frames", frames, "frames to write")->check(CLI::Range(1u, 100000u))->capture_default_str();
  write->add_option("--first", first, "first frame (position on the path)")->capture_default_str();
  write->add_option("--path-frames", path_frames, "frames per lap of the camera path")
      ->check(CLI::Range(1u, 100000u))
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const auto level = examples::dmc1_level::hall();
  std::vector<std::uint64_t> words;
  for (unsigned f = first; f < first + frames; ++f) {
    const auto cam = examples::dmc1_level::camera_path(level, static_cast<double>(f % path_frames) / path_frames);
    const auto frame = examples::dmc1_level::frame_commands(level, cam);
    words.insert(words.end(), frame.begin(), frame.end());
  }
  if (auto r = dmc1::save_stream(out, words); !r) {
    std::fprintf(stderr, "gpubridge-dmc1-demo: %s\n", r.error().message.c_str());
    return 1;
  }
  std::printf("wrote %s: %u frame(s), %zu commands\n", out.c_str(), frames, words.size());
  return 0;
}
