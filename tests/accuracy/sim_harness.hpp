#pragma once
// A simulator device driven only through register frames, as a client would drive a board:
// FB_FORMAT / FB_DRAW / FB_Z / SCISSOR / CLEAR, TRI_MODE, PRIM, then COLOR / TEXCOORD / VERTEX per
// vertex. Results are read from video memory. Used by every accuracy test.
// Built with GPUBRIDGE_ACCURACY_GATEWARE (tests/rtl, `ctest -L rtl`), the same frames go through an
// FT232H board backend to the Verilated gateware with the simulator on the same wires; before any
// result is read, the gateware's video memory must equal the simulator's byte for byte.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "gpubridge/accuracy/from_device.hpp"
#include "gpubridge/accuracy/reference.hpp"
#include "gpubridge/geometry/convert.hpp"
#include "gpubridge/geometry/encode.hpp"
#include "gpubridge/protocol/pixel.hpp"
#include "gpubridge/sim/device.hpp"

namespace gpubridge::test {
class GatewareBoard;
}

namespace gpubridge::accuracy {

// Device vertex from whole-pixel or 1/16-pixel values, for readable test geometry.
geometry::DeviceVertex dv(int x16, int y16, std::uint32_t z = 0, std::uint32_t rgba = 0xFFFFFFFFu,
                          std::uint32_t q = 0xFFFFFFFFu, std::int32_t s = 0, std::int32_t t = 0);
geometry::DeviceTriangle to_device(const FixedTriangle& t);

class SimHarness {
 public:
  struct Setup {
    unsigned width = 64, height = 64;
    protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
    unsigned threads = 1;
    sim::AccuracyKnobs knobs{};
  };
  explicit SimHarness(const Setup& setup);
  SimHarness() : SimHarness(Setup{}) {}
  ~SimHarness();
  SimHarness(SimHarness&&) noexcept;

  unsigned width() const { return setup_.width; }
  unsigned height() const { return setup_.height; }
  PixelRect full_rect() const { return {0, 0, int(setup_.width), int(setup_.height)}; }

  void write(protocol::Reg reg, std::uint64_t data);
  void clear(std::uint32_t rgba = 0x000000FFu, std::uint32_t depth = 0xFFFFFFu);
  void scissor(unsigned x0, unsigned y0, unsigned x1, unsigned y1);
  void state(const geometry::RenderState& s);
  void prim(protocol::PrimType type);
  void vertex(const geometry::DeviceVertex& v);
  // One LIST triangle (writes PRIM first so earlier vertices never pair with it).
  void draw(const geometry::DeviceTriangle& tri);
  void draw(std::span<const geometry::DeviceTriangle> tris);
  // Uploads an RGBA8888 / other-format texture through MEM_ADDR/MEM_DATA and binds it.
  void texture(const std::vector<std::uint8_t>& bytes, const geometry::TextureFormat& fmt);

  protocol::Rgba8 color(int x, int y) const;
  std::uint32_t depth(int x, int y) const;
  std::vector<std::uint8_t> color_bytes() const;
  std::vector<std::uint8_t> depth_bytes() const;
  // Hit counts: draws every triangle flat with ADD blending and colour R = 1 into a cleared
  // buffer, so R counts the triangles covering each pixel (saturates at 255).
  std::vector<int> hit_counts(std::span<const geometry::DeviceTriangle> tris);
  std::uint16_t device_errors() const;
  sim::Device& device() { return *device_; }

 private:
  void send(const protocol::Frame& f);
  void sync() const;  // gateware builds: frames sent, devices idle, video memory compared
  void flush() const;  // gateware builds: the frames not yet sent go to the board

  Setup setup_;
  sim::Device* device_ = nullptr;
  std::unique_ptr<sim::Device> own_device_;
  std::unique_ptr<test::GatewareBoard> gateware_;
  mutable std::vector<protocol::Frame> pending_;
  mutable bool dirty_ = false;
  std::uint32_t z_base_ = 0, tex_base_ = 0;
};

// Reference hit counts for the same triangles inside `clip`.
std::vector<int> reference_hit_counts(std::span<const geometry::DeviceTriangle> tris, const PixelRect& clip,
                                      unsigned width, unsigned height);

}  // namespace gpubridge::accuracy
