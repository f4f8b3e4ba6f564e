#pragma once
// The hostile and careless clients of issue 14 as byte streams and traces, shared by the daemon's
// limit tests (daemon_limits_test.cpp) and the hand-run soak (daemon_soak.cpp).
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/messages.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::test {

using Bytes = std::vector<std::uint8_t>;

inline void add_message(Bytes& out, std::uint32_t id, protocol::Payload p) {
  protocol::encode(protocol::Message{id, std::move(p)}, out);
}

inline Bytes hello_message(const std::string& name, const std::string& token = "") {
  Bytes out;
  add_message(out, 1, protocol::Hello{protocol::kSocketVersion, name, token});
  return out;
}

// `n` pipelined requests of one kind, request ids from 2 on.
inline Bytes repeated(std::size_t n, const protocol::Payload& p) {
  Bytes out;
  for (std::size_t i = 0; i < n; ++i) add_message(out, static_cast<std::uint32_t>(2 + i), p);
  return out;
}

// A text trace of `frames` animation frames on a 1024x1024 RGB565 framebuffer: CLEAR, one Gouraud
// triangle that moves, FB_DISPLAY. The sim draws hundreds of these per second.
inline void write_animation_trace(const std::filesystem::path& path, int frames = 8) {
  std::ofstream t(path);
  t << "# issue 14: a looping animation on the largest framebuffer\n"
       "FB_FORMAT FORMAT=RGB565 WIDTH=1024 HEIGHT=1024\n"
       "CLEAR_COLOR R=16 G=16 B=48 A=255\n"
       "TRI_MODE GOURAUD=1\n"
       "PRIM TYPE=LIST\n";
  for (int i = 0; i < frames; ++i) {
    t << "CLEAR\n"
      << "COLOR R=255 A=255\nVERTEX X=" << 40 + 16 * i << " Y=1000\n"
      << "COLOR G=255 A=255\nVERTEX X=" << 512 + 8 * i << " Y=" << 20 + 4 * i << "\n"
      << "COLOR B=255 A=255\nVERTEX X=1000 Y=" << 1000 - 8 * i << "\n"
      << "FB_DISPLAY 0\n";
  }
}

// One WRITE_FRAMES payload of about `bytes` that keeps the device busy for a long time: full-screen
// clears of a 1024x1024 framebuffer, a swap after every 16th (so frames flow while it runs).
inline Bytes long_batch(std::size_t bytes) {
  using protocol::Reg;
  Bytes frames;
  protocol::append(frames, protocol::write_frame(Reg::FB_FORMAT, (1ull << 32) | (1024ull << 16) | 1024ull));
  for (std::size_t i = 0; frames.size() + protocol::kFrameBytes <= bytes; ++i) {
    if (i % 17 == 16)
      protocol::append(frames, protocol::write_frame(Reg::FB_DISPLAY, 0));
    else
      protocol::append(frames, protocol::write_frame(Reg::CLEAR, 0));
  }
  return frames;
}

}  // namespace gpubridge::test
