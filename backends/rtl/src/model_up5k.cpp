// The up5k profile's Verilated model (PROFILE=0): video memory in four SB_SPRAM256KA models.
#include "Vspigpu_up5k.h"
#include "Vspigpu_up5k___024root.h"
#include "model_impl.hpp"

namespace gpubridge::rtl::detail {
namespace {

class Up5kModel final : public ModelImpl<Vspigpu_up5k> {
 public:
  std::uint64_t vram_bytes() const override { return 128 * 1024; }
  // Word w (bytes 4w..4w+3) lives at index w mod 16384 of bank w / 16384: the "hi" RAM holds bytes
  // 4w and 4w+1 (big-endian 16-bit value), the "lo" RAM bytes 4w+2 and 4w+3.
  void read_vram(std::uint64_t address, std::uint8_t* out, std::size_t length) const override {
    auto* r = m_->rootp;
    for (std::size_t i = 0; i < length; ++i) {
      const std::uint64_t a = address + i;
      if (a >= vram_bytes()) {
        out[i] = 0;
        continue;
      }
      const std::uint32_t w = static_cast<std::uint32_t>(a >> 2), idx = w & 0x3FFF;
      const bool bank1 = (w >> 14) & 1, hi = (a & 2) == 0;
      std::uint16_t v;
      if (!bank1)
        v = hi ? r->spigpu_sim__DOT__dut__DOT__u_soc__DOT__g_spram__DOT__u_vram__DOT__g_bank__BRA__0__KET____DOT__ram_hi__DOT__mem[idx]
               : r->spigpu_sim__DOT__dut__DOT__u_soc__DOT__g_spram__DOT__u_vram__DOT__g_bank__BRA__0__KET____DOT__ram_lo__DOT__mem[idx];
      else
        v = hi ? r->spigpu_sim__DOT__dut__DOT__u_soc__DOT__g_spram__DOT__u_vram__DOT__g_bank__BRA__1__KET____DOT__ram_hi__DOT__mem[idx]
               : r->spigpu_sim__DOT__dut__DOT__u_soc__DOT__g_spram__DOT__u_vram__DOT__g_bank__BRA__1__KET____DOT__ram_lo__DOT__mem[idx];
      out[i] = static_cast<std::uint8_t>((a & 1) ? v : v >> 8);
    }
  }
};

}  // namespace

std::unique_ptr<GatewareModel> make_model_up5k() { return std::make_unique<Up5kModel>(); }

}  // namespace gpubridge::rtl::detail
