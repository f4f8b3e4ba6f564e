#pragma once
// `gpubridge bringup`: the checks a new board goes through, as a library so tests can run them
// against emulated boards. Each step reports pass/fail with a detail line.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/usb/board_backend.hpp"

namespace gpubridge::usb {

struct BringupOptions {
  std::uint32_t mem_base = 0;
  std::uint32_t mem_bytes = 64 * 1024;  // memory test range (clamped to video memory)
  unsigned clock_iterations = 8;        // passes per SPI clock in the sweep
  std::vector<std::uint32_t> clocks;    // candidate SCK frequencies (empty: standard ladder ≤ max_clock_hz)
  std::uint32_t max_clock_hz = 0;       // top of the ladder (0: the profile's clock)
  bool readback = false;                // compare scene pixels too, not only FRAME_CRC
  std::string diff_dir;                 // with readback: write <scene>-diff.png here on mismatch
  std::function<void(const std::string& step, unsigned percent)> progress;
};

struct BringupStep {
  std::string name;
  bool ok = false;
  bool skipped = false;
  std::string detail;
  double seconds = 0;
};

struct BringupReport {
  std::vector<BringupStep> steps;
  std::uint32_t best_clock_hz = 0;
  bool ok() const {
    for (const auto& s : steps)
      if (!s.ok && !s.skipped) return false;
    return true;
  }
};

BringupReport run_bringup(BoardBackend& board, const BringupOptions& opts);

}  // namespace gpubridge::usb
