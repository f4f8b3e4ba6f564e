// The example scenes through the render core: every demo example (its golden frame) and every
// scene file in examples/scenes, drawn by the Verilated core and by the simulator from the same
// register stream; video memory must be byte-identical after every swap.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "cosim.hpp"
#include "gpubridge/draw/context.hpp"
#include "gpubridge/draw/sink.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/scene/scene.hpp"
#include "rtl_config.hpp"

namespace gpubridge::rtl {
namespace {

// The drawing API's commands into the co-simulation.
class CosimSink final : public draw::CommandSink {
 public:
  explicit CosimSink(Cosim& cs) : cs_(cs) {}
  Result<void> write_frames(protocol::FrameView frames) override {
    for (std::size_t i = 0; i < frames.size(); ++i) cs_.write(frames[i]);
    return {};
  }
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override {
    cs_.upload(address, bytes.data(), bytes.size());
    return {};
  }
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override {
    auto m = cs_.device().memory();
    if (std::uint64_t{address} + length > m.size()) return make_error("readback beyond VRAM");
    return std::vector<std::uint8_t>(m.begin() + address, m.begin() + address + length);
  }
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

sim::DeviceOptions scene_device() {
  sim::DeviceOptions o;
  o.vram_bytes = std::min<std::uint64_t>(2u << 20, kCoreVramBytes);
  o.features = kCoreFeatures;
  return o;
}

class CoreExample : public ::testing::TestWithParam<std::string> {};

TEST_P(CoreExample, GoldenFrameMatchesSimulator) {
  // The examples texture and draw 320 x 240 RGBA8888 frames: a profile without texturing or
  // with less video memory cannot show them (the soc-level tests check its error flags).
  if (!kCoreTexture || kCoreVramBytes < (2u << 20)) GTEST_SKIP() << "the profile cannot draw the examples";
  auto ex = examples::make_example(GetParam());
  ASSERT_NE(ex, nullptr);
  Cosim cs(scene_device(), 1234);
  CosimSink sink(cs);
  auto ctx = draw::Context::create(sink, ex->options());
  ASSERT_TRUE(ctx) << ctx.error().message;
  const auto r = examples::run_frames(*ex, *ctx, examples::kGoldenFrame, 1, [&](unsigned n) -> Result<void> {
    const std::string diff = cs.compare();
    if (!diff.empty()) return make_error("frame " + std::to_string(n) + ":\n" + diff);
    return {};
  });
  ASSERT_TRUE(r) << GetParam() << ": " << r.error().message;
  const auto p = cs.core().perf();
  std::printf("%s: %u triangles, %u pixels, %u textured, %u busy cycles (%u setup, %u raster)\n",
              GetParam().c_str(), p.triangles, p.pixels, p.textured, p.busy, p.setup, p.raster);
}

INSTANTIATE_TEST_SUITE_P(Examples, CoreExample, ::testing::ValuesIn(examples::example_names()), [](const auto& p) {
  std::string n = p.param;  // torus-temporal: no '-' in test names
  for (char& c : n)
    if (c == '-') c = '_';
  return n;
});

class CoreSceneFile : public ::testing::TestWithParam<std::string> {};

TEST_P(CoreSceneFile, MatchesSimulator) {
  const auto path = std::filesystem::path(GPUBRIDGE_SCENE_DIR) / (GetParam() + ".json");
  const auto o = scene_device();
  auto parsed = scene::read_scene_file(path);
  ASSERT_TRUE(parsed) << parsed.error().message;
  if (!scene::plan_memory(*parsed, o.vram_bytes)) GTEST_SKIP() << "the scene does not fit the profile's video memory";
  auto built = scene::build_commands(*parsed, {.vram_bytes = o.vram_bytes});
  ASSERT_TRUE(built) << built.error().message;
  Cosim cs(o, 99);
  for (const auto& tc : built->stream.commands) {
    if (const auto* f = std::get_if<protocol::FramesCmd>(&tc.command)) {
      const auto v = f->view();
      for (std::size_t i = 0; i < v.size(); ++i) cs.write(v[i]);
    } else if (const auto* u = std::get_if<protocol::UploadCmd>(&tc.command)) {
      cs.upload(u->address, u->data.data(), u->data.size());
    }
  }
  const std::string diff = cs.compare();
  EXPECT_TRUE(diff.empty()) << GetParam() << ":\n" << diff;
}

std::vector<std::string> scene_files() {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(GPUBRIDGE_SCENE_DIR))
    if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

INSTANTIATE_TEST_SUITE_P(Scenes, CoreSceneFile, ::testing::ValuesIn(scene_files()), [](const auto& p) {
  std::string n = p.param;
  for (char& c : n)
    if (c == '-') c = '_';
  return n;
});

}  // namespace
}  // namespace gpubridge::rtl
