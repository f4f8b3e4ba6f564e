#include "core_harness.hpp"

#include <stdexcept>

#include "rtl_config.hpp"
#include "verilated.h"
#include GPUBRIDGE_RTL_MODEL_HEADER

namespace gpubridge::rtl {
namespace {

void put_vertex(VlWide<6>& w, const CoreVertex& v) {
  // {t, s, q, rgba, z, y, x}: x in bits [15:0]
  const std::uint32_t words[6] = {
      std::uint32_t(std::uint16_t(v.x)) | (std::uint32_t(std::uint16_t(v.y)) << 16),
      (v.z & 0xFFFFFF) | (v.rgba << 24),
      (v.rgba >> 8) | (v.q << 24),
      (v.q >> 8) | (std::uint32_t(v.s) << 24),
      (std::uint32_t(v.s) >> 8) | (std::uint32_t(v.t) << 24),
      std::uint32_t(v.t) >> 8,
  };
  for (int i = 0; i < 6; ++i) w[i] = words[i];
}

// Word w of a vertex slot of the soc's read port (command_exec, VPORT = 1): {Y, X}, Z, COLOR;
// "vertex" 3 holds CLEAR_COLOR and CLEAR_DEPTH.
std::uint32_t port_word(const CoreCommand& c, unsigned slot, unsigned w) {
  if (slot == 3) return w == 0 ? c.clear_color : w == 1 ? (c.clear_depth & 0xFFFFFF) : 0xDEADBEEFu;
  const CoreVertex& v = c.v[slot];
  switch (w) {
    case 0: return std::uint32_t(std::uint16_t(v.x)) | (std::uint32_t(std::uint16_t(v.y)) << 16);
    case 1: return v.z & 0xFFFFFF;
    case 2: return v.rgba;
    default: return 0xDEADBEEFu;
  }
}

}  // namespace

CoreHarness::CoreHarness(std::uint64_t vram_bytes, std::uint32_t seed, MemoryTiming timing)
    : ctx_(std::make_unique<VerilatedContext>()), mem_(vram_bytes, 0), rng_(seed), timing_(timing) {
  top_ = std::make_unique<Model>(ctx_.get());
  top_->rst = 1;
  top_->cmd_valid = 0;
  top_->mem_req_ready = 0;
  top_->mem_rsp_valid = 0;
  for (int i = 0; i < 4; ++i) tick();
  top_->rst = 0;
}

CoreHarness::~CoreHarness() {
  // the model's scopes are unregistered through the thread's context (Verilator 5.006,
  // verilator#8265; see backends/rtl/src/model_impl.hpp): ours while it goes, never a freed one
  Verilated::threadContextp(ctx_.get());
  top_->final();
  top_.reset();
  ctx_.reset();
  Verilated::threadContextp(Verilated::defaultContextp());
}

void CoreHarness::tick() {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  top_->mem_req_ready = u(rng_) < timing_.ready_probability;
  const bool rsp = !reads_.empty() && reads_.front().due <= cycles_;
  top_->mem_rsp_valid = rsp;
  top_->mem_rsp_rdata = rsp ? reads_.front().data : 0xDEADBEEFu;
  top_->clk = 0;
  top_->eval();
  const bool req = top_->mem_req_valid && top_->mem_req_ready;
  const bool we = top_->mem_req_we;
  const std::uint64_t addr = std::uint64_t(top_->mem_req_addr) * 4;
  const std::uint32_t wdata = top_->mem_req_wdata;
  const unsigned be = top_->mem_req_be;
  const unsigned vp = top_->vp_addr;
  top_->clk = 1;
  top_->eval();
  // the read port answers the address of this edge a clock later, as the block RAM does
  top_->vp_data = port_word(port_, vp >> 2, vp & 3);
  ++cycles_;
  if (rsp) reads_.pop_front();
  if (req) {
    const bool inside = addr + 4 <= mem_.size();
    if (!inside) range_error_ = true;
    if (we) {
      if (inside)
        for (unsigned b = 0; b < 4; ++b)
          if (be & (8u >> b)) mem_[addr + b] = std::uint8_t(wdata >> (24 - 8 * b));
    } else {
      std::uint32_t d = 0;
      if (inside) d = (std::uint32_t(mem_[addr]) << 24) | (std::uint32_t(mem_[addr + 1]) << 16) |
                      (std::uint32_t(mem_[addr + 2]) << 8) | mem_[addr + 3];
      std::uniform_int_distribution<unsigned> lat(timing_.min_latency, timing_.max_latency);
      std::uint64_t due = cycles_ + lat(rng_) - 1;
      if (!reads_.empty() && reads_.back().due >= due) due = reads_.back().due + 1;
      reads_.push_back({due, d});
    }
  }
}

void CoreHarness::submit(const CoreCommand& c) {
  top_->cmd_op = c.op;
  top_->cmd_tri_mode = c.tri_mode;
  top_->cmd_tex_base = c.tex_base >> 4;
  top_->cmd_tex_fmt = c.tex_fmt & 0x3FFFF;
  const std::uint64_t s = c.scissor;
  const std::uint64_t x0 = s & 0x7FF, y0 = (s >> 16) & 0x7FF, x1 = (s >> 32) & 0x7FF, y1 = (s >> 48) & 0x7FF;
  top_->cmd_scissor = x0 | (y0 << 11) | (x1 << 22) | (y1 << 33);
  top_->cmd_fb_draw = c.fb_draw >> 4;
  top_->cmd_fb_z = c.fb_z >> 4;
  top_->cmd_fb_format = (c.fb_format >> 32) & 3;
  top_->cmd_fb_width = c.fb_format & 0x7FF;
  top_->cmd_fb_height = (c.fb_format >> 16) & 0x7FF;
  top_->cmd_clear_color = c.clear_color;
  top_->cmd_clear_depth = c.clear_depth & 0xFFFFFF;
  put_vertex(top_->cmd_v0, c.v[0]);
  put_vertex(top_->cmd_v1, c.v[1]);
  put_vertex(top_->cmd_v2, c.v[2]);
  port_ = c;
  top_->cmd_valid = 1;
  for (std::uint64_t n = 0;; ++n) {
    top_->clk = 0;
    top_->eval();
    const bool taken = top_->cmd_ready;
    tick();
    if (taken) break;
    if (n > 100'000'000) throw std::runtime_error("core never accepted a command");
  }
  top_->cmd_valid = 0;
}

bool CoreHarness::idle() const { return top_->core_idle && reads_.empty(); }

bool CoreHarness::run_until_idle(std::uint64_t max_cycles) {
  for (std::uint64_t n = 0; n < max_cycles; ++n) {
    top_->clk = 0;
    top_->eval();
    if (idle()) return true;
    tick();
  }
  return false;
}

CoreHarness::Perf CoreHarness::perf() const {
  return {top_->perf_triangles, top_->perf_pixels, top_->perf_passed, top_->perf_textured,
          top_->perf_busy,      top_->perf_setup,  top_->perf_raster};
}

}  // namespace gpubridge::rtl
