#pragma once
// The Verilated render core (gateware/rtl/core/spigpu_core.v) driven as the soc drives it: one
// command at a time on its command port, its memory port served by a behavioural memory with
// random ready stalls and a random in-order read latency (seeded, so a run reproduces).
#include <cstdint>
#include <deque>
#include <memory>
#include <random>
#include <vector>

class VerilatedContext;
class GPUBRIDGE_RTL_MODEL;

namespace gpubridge::rtl {

struct CoreVertex {
  std::int16_t x = 0, y = 0;  // s12.4
  std::uint32_t z = 0;        // 24 bits
  std::uint32_t rgba = 0;     // 0xRRGGBBAA
  std::uint32_t q = 0;        // u0.32
  std::int32_t s = 0, t = 0;  // s8.24
};

// A command with its render-state snapshot, as the soc presents it (validated register values).
struct CoreCommand {
  enum Op : unsigned { Triangle = 0, Clear = 1, ClearZ = 2 } op = Triangle;
  std::uint32_t tri_mode = 0;
  std::uint32_t tex_base = 0;   // TEX_BASE register bits [31:0] (byte address, 16-aligned)
  std::uint32_t tex_fmt = 0;    // TEX_FMT [17:0]
  std::uint64_t scissor = 0;    // SCISSOR register value
  std::uint32_t fb_draw = 0, fb_z = 0;  // byte addresses, 16-aligned
  std::uint64_t fb_format = 0;  // FB_FORMAT register value
  std::uint32_t clear_color = 0, clear_depth = 0;
  CoreVertex v[3];
};

struct MemoryTiming {
  double ready_probability = 0.75;  // mem_req_ready high in a cycle
  unsigned min_latency = 1, max_latency = 6;  // cycles from request to response
};

class CoreHarness {
 public:
  CoreHarness(std::uint64_t vram_bytes, std::uint32_t seed, MemoryTiming timing = {});
  ~CoreHarness();
  CoreHarness(const CoreHarness&) = delete;
  CoreHarness& operator=(const CoreHarness&) = delete;

  // Presents the command and clocks until the core accepts it.
  void submit(const CoreCommand& c);
  // Clocks until core_idle (every write accepted). Returns false after max_cycles.
  bool run_until_idle(std::uint64_t max_cycles = 200'000'000);

  std::vector<std::uint8_t>& memory() { return mem_; }
  bool range_error() const { return range_error_; }
  void clear_range_error() { range_error_ = false; }
  std::uint64_t cycles() const { return cycles_; }
  void set_timing(MemoryTiming t) { timing_ = t; }

  struct Perf {
    std::uint32_t triangles, pixels, passed, textured, busy, setup, raster;
  };
  Perf perf() const;

 private:
  void tick();
  bool idle() const;

  std::unique_ptr<VerilatedContext> ctx_;
  using Model = GPUBRIDGE_RTL_MODEL;
  std::unique_ptr<Model> top_;
  std::vector<std::uint8_t> mem_;
  std::mt19937 rng_;
  MemoryTiming timing_;
  struct Pending {
    std::uint64_t due;
    std::uint32_t data;
  };
  std::deque<Pending> reads_;
  // the soc's vertex read port (up5k core): the command's vertices and clear values, as the
  // executor's block RAM holds them
  CoreCommand port_;
  std::uint64_t cycles_ = 0;
  bool range_error_ = false;
};

}  // namespace gpubridge::rtl
