// The ecp5 profile's Verilated model (PROFILE=1): video memory in the behavioural SDRAM chip.
#include "Vspigpu_ecp5.h"
#include "Vspigpu_ecp5___024root.h"
#include "model_impl.hpp"

namespace gpubridge::rtl::detail {
namespace {

class Ecp5Model final : public ModelImpl<Vspigpu_ecp5> {
 public:
  std::uint64_t vram_bytes() const override { return 32ull << 20; }
  // The controller's mapping (gateware/rtl/soc/sdram_ctrl.v): word w -> bank w[9:8], row w[22:10],
  // columns {w[7:0], 0} (bytes 4w, 4w+1) and {w[7:0], 1} (bytes 4w+2, 4w+3); the chip's array is
  // indexed {bank, row, column}.
  void read_vram(std::uint64_t address, std::uint8_t* out, std::size_t length) const override {
    const auto& mem = m_->rootp->spigpu_sim__DOT__g_sdram__DOT__chip__DOT__mem;
    for (std::size_t i = 0; i < length; ++i) {
      const std::uint64_t a = address + i;
      if (a >= vram_bytes()) {
        out[i] = 0;
        continue;
      }
      const std::uint32_t w = static_cast<std::uint32_t>(a >> 2);
      const std::uint32_t index = (((w >> 8) & 3) << 22) | ((w >> 10) << 9) | ((w & 0xFF) << 1) | ((a >> 1) & 1);
      const std::uint16_t v = mem[index];
      out[i] = static_cast<std::uint8_t>((a & 1) ? v : v >> 8);
    }
  }
};

}  // namespace

std::unique_ptr<GatewareModel> make_model_ecp5() { return std::make_unique<Ecp5Model>(); }

}  // namespace gpubridge::rtl::detail
