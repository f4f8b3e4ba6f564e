#pragma once
// `gpubridge render --device dmc1`: a DMC-1 command stream on the in-process bit-exact DMC-1.
#include <string>
#include <vector>

#include "command.hpp"

namespace gpubridge::cli {

struct Dmc1RenderArgs {
  std::string input, out, raw, frames_dir, textures, palette;
  std::string board, tty;  // --board: also stream to that board over its UART; --tty overrides the port
  std::vector<std::string> timing_params;
  unsigned threads = 1;
  bool timing = false;
};
int render_dmc1(const GlobalOptions& g, const Dmc1RenderArgs& a);

}  // namespace gpubridge::cli
