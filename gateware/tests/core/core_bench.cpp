// Throughput of the render core in clock cycles, by scene class and per example scene, with the
// memory port served at one request per cycle and a read latency of two cycles (the core's own
// limits; the soc's arbiter, SPRAM or SDRAM add theirs). Not a test: the figures for
// docs/gateware.md. Run: build/gateware/tests/core/rtl_core_<profile>_bench [--json]
#include <cstdio>
#include <cstring>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "cosim.hpp"
#include "gpubridge/draw/context.hpp"
#include "gpubridge/draw/sink.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "rtl_config.hpp"

namespace gpubridge::rtl {
namespace {

using protocol::Reg;

const MemoryTiming kIdeal{1.0, 2, 2};

sim::DeviceOptions device(std::uint64_t vram) {
  sim::DeviceOptions o;
  o.vram_bytes = vram;
  o.features = kCoreFeatures;
  return o;
}

struct Row {
  std::string name;
  double value;
  std::string unit;
};
std::vector<Row> rows;

void vertex(Cosim& cs, int x16, int y16, std::uint32_t z, std::uint32_t rgba, std::uint32_t q = 0xFFFFFFFFu,
            std::int32_t s = 0, std::int32_t t = 0) {
  cs.write(Reg::COLOR, (std::uint64_t{q} << 32) | rgba);
  cs.write(Reg::TEXCOORD, (std::uint64_t{std::uint32_t(s)} << 32) | std::uint32_t(t));
  cs.write(Reg::VERTEX, (std::uint64_t{z} << 32) | (std::uint64_t{std::uint16_t(y16)} << 16) | std::uint16_t(x16));
}

void frame_setup(Cosim& cs, unsigned w, unsigned h, unsigned fmt) {
  cs.write(Reg::FB_FORMAT, (std::uint64_t{fmt} << 32) | (std::uint64_t{h} << 16) | w);
  cs.write(Reg::FB_DRAW, 0);
  cs.write(Reg::FB_Z, 0x40000);
  cs.write(Reg::TEX_BASE, 0x80000);
  cs.write(Reg::TEX_FMT, 0x66);  // 64 x 64 RGBA8888
  cs.write(Reg::SCISSOR, (std::uint64_t{h} << 48) | (std::uint64_t{w} << 32));
  cs.write(Reg::PRIM, 0);
}

// Pixels per cycle drawing a w x h rectangle as two triangles (setup included), mode m.
void fill(const char* name, unsigned fmt, std::uint64_t mode, unsigned w = 256, unsigned h = 128, bool bilinear = false) {
  if (fmt == 1 && !(kCoreFeatures & sim::FEATURE_RGB565)) return;
  if (fmt == 2 && !(kCoreFeatures & sim::FEATURE_RGBA2222)) return;
  if ((mode & 2) && !kCoreTexture) return;
  if (((mode >> 7) & 3) && !(kCoreFeatures & sim::FEATURE_BLEND)) return;
  Cosim cs(device(std::min<std::uint64_t>(kCoreVramBytes, 1u << 20)), 1, kIdeal);
  frame_setup(cs, w, h, fmt);
  if (bilinear) cs.write(Reg::TEX_FMT, 0x1066);
  cs.write(Reg::TRI_MODE, mode);
  cs.core().run_until_idle();
  const auto p0 = cs.core().perf();
  const int X = int(w) * 16, Y = int(h) * 16;
  const std::uint32_t q = 0xFFFFFFFFu;
  vertex(cs, 0, 0, 100, 0xFF0000FF, q, 0, 0);
  vertex(cs, X, 0, 200, 0x00FF00FF, q, 0x02000000, 0);
  vertex(cs, X, Y, 300, 0x0000FFFF, q, 0x02000000, 0x01000000);
  vertex(cs, 0, 0, 100, 0xFF0000FF, q, 0, 0);
  vertex(cs, X, Y, 300, 0x0000FFFF, q, 0x02000000, 0x01000000);
  vertex(cs, 0, Y, 400, 0xFFFFFF80, q, 0, 0x01000000);
  cs.core().run_until_idle();
  const auto p1 = cs.core().perf();
  rows.push_back({name, double(p1.pixels - p0.pixels) / double(p1.busy - p0.busy), "px/clk"});
}

// Cycles per triangle: n small triangles (a few pixels each), mode m; setup cycles alone too.
void setup_cost(const char* name, std::uint64_t mode) {
  if ((mode & 2) && !kCoreTexture) return;
  Cosim cs(device(std::min<std::uint64_t>(kCoreVramBytes, 1u << 20)), 1, kIdeal);
  frame_setup(cs, 128, 128, 0);
  cs.write(Reg::TRI_MODE, mode);
  cs.core().run_until_idle();
  const auto p0 = cs.core().perf();
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> pos(16 * 8, 16 * 120), d(-48, 48);
  const int n = 300;
  for (int i = 0; i < n; ++i) {
    const int x = pos(rng), y = pos(rng);
    vertex(cs, x, y, rng() & 0xFFFFFF, rng() | 0xFF, 0x80000000u + (rng() >> 2), rng() >> 6, rng() >> 6);
    vertex(cs, x + 40 + d(rng), y + d(rng), rng() & 0xFFFFFF, rng() | 0xFF, 0x80000000u + (rng() >> 2), rng() >> 6, rng() >> 6);
    vertex(cs, x + d(rng), y + 40 + d(rng), rng() & 0xFFFFFF, rng() | 0xFF, 0x80000000u + (rng() >> 2), rng() >> 6, rng() >> 6);
  }
  cs.core().run_until_idle();
  const auto p1 = cs.core().perf();
  const double tris = double(p1.triangles - p0.triangles);
  rows.push_back({std::string(name) + ": setup", double(p1.setup - p0.setup) / tris, "cycles/triangle"});
  rows.push_back({std::string(name) + ": total (" + std::to_string((p1.pixels - p0.pixels) / unsigned(tris)) + " px each)",
                  double(p1.busy - p0.busy) / tris, "cycles/triangle"});
}

class Sink final : public draw::CommandSink {
 public:
  explicit Sink(Cosim& cs) : cs_(cs) {}
  Result<void> write_frames(protocol::FrameView f) override {
    for (std::size_t i = 0; i < f.size(); ++i) cs_.write(f[i]);
    return {};
  }
  Result<void> upload(std::uint32_t a, std::span<const std::uint8_t> b) override {
    cs_.upload(a, b.data(), b.size());
    return {};
  }
  Result<std::vector<std::uint8_t>> readback(std::uint32_t, std::uint32_t) override { return make_error("none"); }
  Result<void> flush() override { return {}; }
  // the simulator beside the core: its VRAM, framebuffer limits and CAPS
  backends::DeviceInfo device() const override {
    const auto& o = cs_.device().options();
    backends::DeviceInfo d;
    d.backend = "sim";
    d.vram_bytes = o.vram_bytes;
    d.max_width = o.max_width;
    d.max_height = o.max_height;
    d.caps = cs_.device().read(protocol::index_of(protocol::Reg::CAPS));
    return d;
  }

 private:
  Cosim& cs_;
};

void scenes() {
  if (!kCoreTexture || kCoreVramBytes < (2u << 20)) return;
  for (const auto& name : examples::example_names()) {
    auto ex = examples::make_example(name);
    Cosim cs(device(2u << 20), 1, kIdeal);
    Sink sink(cs);
    auto ctx = draw::Context::create(sink, ex->options());
    if (!ctx) continue;
    CoreHarness::Perf p0{};
    bool measured = false;
    (void)examples::run_frames(*ex, *ctx, examples::kGoldenFrame, 1, [&](unsigned) -> Result<void> {
      cs.core().run_until_idle();
      const auto p = cs.core().perf();
      rows.push_back({"scene " + name + ": cycles per frame", double(p.busy - p0.busy), "cycles"});
      rows.push_back({"scene " + name + ": triangles", double(p.triangles - p0.triangles), ""});
      rows.push_back({"scene " + name + ": pixels", double(p.pixels - p0.pixels), ""});
      rows.push_back({"scene " + name + ": setup cycles", double(p.setup - p0.setup), "cycles"});
      measured = true;
      return {};
    });
    (void)measured;
  }
}

}  // namespace
}  // namespace gpubridge::rtl

int main(int argc, char** argv) {
  using namespace gpubridge::rtl;
  const bool json = argc > 1 && std::strcmp(argv[1], "--json") == 0;
  fill("fill RGBA8888 flat", 0, 0);
  fill("fill RGB565 flat", 1, 0);
  fill("fill RGBA2222 flat", 2, 0);
  fill("RGBA8888 Gouraud", 0, 1);
  fill("RGBA8888 flat, Z test + write", 0, 0x4 | (1u << 3) | 0x40);
  fill("RGBA8888 Gouraud, Z test + write", 0, 0x1 | 0x4 | (1u << 3) | 0x40);
  fill("RGBA2222 Gouraud, dithered", 2, 0x1 | (1u << 9));
  fill("RGBA8888 alpha blend", 0, 0x1 | (1u << 7));
  fill("RGBA8888 textured nearest (64x64 RGBA8888)", 0, 0x2);
  fill("RGBA8888 textured bilinear (64x64 RGBA8888)", 0, 0x2, 256, 128, true);
  fill("RGB565 textured nearest (64x64 RGBA8888)", 1, 0x2);
  fill("RGB565 textured bilinear (64x64 RGBA8888)", 1, 0x2, 256, 128, true);
  setup_cost("flat", 0);
  setup_cost("flat, Z", 0x4 | (1u << 3) | 0x40);
  setup_cost("Gouraud", 0x1);
  setup_cost("Gouraud, Z", 0x1 | 0x4 | (1u << 3) | 0x40);
  setup_cost("Gouraud, Z, textured", 0x1 | 0x2 | 0x4 | (1u << 3) | 0x40);
  scenes();
  if (json) {
    std::printf("[\n");
    for (std::size_t i = 0; i < rows.size(); ++i)
      std::printf("  {\"name\": \"%s\", \"value\": %.4f, \"unit\": \"%s\"}%s\n", rows[i].name.c_str(), rows[i].value,
                  rows[i].unit.c_str(), i + 1 < rows.size() ? "," : "");
    std::printf("]\n");
  } else {
    for (const auto& r : rows) std::printf("%-56s %12.3f %s\n", r.name.c_str(), r.value, r.unit.c_str());
  }
  return 0;
}
