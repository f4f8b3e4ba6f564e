#pragma once
// GatewareModel over one Verilated top level (included by model_up5k.cpp / model_ecp5.cpp only).
#include <verilated.h>

#include <memory>

#include "gateware_model.hpp"

namespace gpubridge::rtl::detail {

template <class V>
class ModelImpl : public GatewareModel {
 public:
  ModelImpl() : ctx_(std::make_unique<VerilatedContext>()) {
    ctx_->randReset(0);  // every register and memory starts at 0, deterministically
    ctx_->fatalOnError(false);
    m_ = std::make_unique<V>(ctx_.get(), "spigpu_sim");
    m_->clk = 0;
    m_->rst = 1;
    m_->spi_sck = 0;
    m_->spi_cs_n = 1;
    m_->spi_mosi = 0;
    m_->eval();
  }
  ~ModelImpl() override {
    // Verilator 5.006 unregisters a model's scopes through the calling thread's context, not the
    // model's own (verilator#8265): point it at ours while the model goes, and at the default
    // context once ours is gone, so that no later destructor locks a freed context (which hung
    // rtl_accuracy_tests in SimHarness::~SimHarness).
    Verilated::threadContextp(ctx_.get());
    m_->final();
    m_.reset();
    ctx_.reset();
    Verilated::threadContextp(Verilated::defaultContextp());
  }

  void set_inputs(const ModelInputs& in) override {
    m_->rst = in.rst;
    m_->spi_sck = in.sck;
    m_->spi_cs_n = in.cs_n;
    m_->spi_mosi = in.mosi;
  }
  bool tick() override {
    m_->clk = 1;
    m_->eval();
    m_->clk = 0;
    m_->eval();
    return m_->frame_valid || m_->frame_start || m_->frame_end;
  }
  bool miso() const override { return m_->spi_miso_oe ? m_->spi_miso != 0 : true; }
  bool busy() const override { return m_->busy_pin != 0; }
  ModelFrame frame() const override {
    ModelFrame f;
    f.valid = m_->frame_valid;
    f.start = m_->frame_start;
    f.end = m_->frame_end;
    f.word = m_->frame_word;
    f.nbytes = m_->frame_nbytes;
    f.format = m_->frame_format;
    f.width = m_->frame_width;
    f.height = m_->frame_height;
    return f;
  }
  ModelCounters counters() const override {
    ModelCounters c;
    c.work_cycles = m_->perf_work_cycles;
    c.cmds = m_->perf_cmds;
    c.frames = m_->perf_frames;
    c.core_stalls = m_->perf_core_stalls;
    c.refreshes = m_->perf_refreshes;
    c.sdram_violations = m_->sdram_violations;
    c.triangles = m_->perf_triangles;
    c.pixels = m_->perf_pixels;
    c.passed = m_->perf_passed;
    c.textured = m_->perf_textured;
    c.core_busy = m_->perf_core_busy;
    c.setup = m_->perf_setup;
    c.raster = m_->perf_raster;
    return c;
  }

 protected:
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<V> m_;
};

}  // namespace gpubridge::rtl::detail
