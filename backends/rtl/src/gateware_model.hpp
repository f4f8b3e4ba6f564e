#pragma once
// One Verilated profile model behind a small interface, so the pin engine (rtl_device.cpp) is
// written once and compiled with the project's warnings while the Verilated code is not.
#include <cstddef>
#include <cstdint>
#include <memory>

namespace gpubridge::rtl::detail {

struct ModelInputs {
  bool rst = true, sck = false, cs_n = true, mosi = false;
};

struct ModelFrame {
  bool valid = false, start = false, end = false;
  std::uint32_t word = 0;
  unsigned nbytes = 0, format = 0, width = 0, height = 0;
};

struct ModelCounters {
  std::uint32_t work_cycles = 0, cmds = 0, frames = 0, core_stalls = 0, refreshes = 0, sdram_violations = 0;
  std::uint32_t triangles = 0, pixels = 0, passed = 0, textured = 0, core_busy = 0, setup = 0, raster = 0;
};

class GatewareModel {
 public:
  virtual ~GatewareModel() = default;
  virtual void set_inputs(const ModelInputs& in) = 0;
  // One core clock (rising and falling edge). Returns true when a scanout frame signal is active.
  virtual bool tick() = 0;
  virtual bool miso() const = 0;      // pin level, 1 when not driven (pull-up)
  virtual bool busy() const = 0;
  virtual ModelFrame frame() const = 0;
  virtual ModelCounters counters() const = 0;
  virtual std::uint64_t vram_bytes() const = 0;
  virtual void read_vram(std::uint64_t address, std::uint8_t* out, std::size_t length) const = 0;
};

std::unique_ptr<GatewareModel> make_model_up5k();
std::unique_ptr<GatewareModel> make_model_ecp5();

}  // namespace gpubridge::rtl::detail
