// The gateware behind every bridge chip: client code -> BoardBackend -> driver -> libusb/hidapi
// shaped transport -> byte-exact chip model -> SPI pins -> Verilated gateware, with the simulator
// on the same wires. Scenes and examples must leave byte-identical video memory and scanned-out
// frames (docs/gateware.md "Co-simulation").
#include <gtest/gtest.h>

#include <filesystem>

#include "gateware_board.hpp"
#include "gpubridge/draw/context.hpp"
#include "gpubridge/draw/sink.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/scene/scene.hpp"
#include "gpubridge/sim/timing.hpp"

namespace gpubridge::test {
namespace {

using protocol::Reg;

struct Wiring {
  std::string name;
  usb::BoardProfile profile;
};
void PrintTo(const Wiring& w, std::ostream* os) { *os << w.name; }

// One board per bridge chip, each with the gateware it is tested with (the clock each bridge can
// run against the gateware: docs/gateware.md "Clocking").
std::vector<Wiring> wirings() {
  return {
      {"ft2232h_icebreaker_up5k", board_profile("icebreaker")},
      {"ft232h_ulx3s_ecp5", board_profile("ulx3s")},
      {"mcp2210_up5k", with_gateware(board_profile("mcp2210-generic"), "up5k", 4'000'000)},
      {"ch341a_up5k", with_gateware(board_profile("ch341a-generic"), "up5k", 1'500'000)},
      {"cp2130_up5k", with_gateware(board_profile("cp2130-generic"), "up5k", 4'000'000)},
  };
}

class Bridge : public ::testing::TestWithParam<Wiring> {
 protected:
  void SetUp() override {
    if (!rtl::RtlDevice::available()) GTEST_SKIP() << rtl::RtlDevice::unavailable_reason();
  }
};

TEST_P(Bridge, AttachesAndIdentifiesTheGateware) {
  auto g = GatewareBoard::open(GetParam().profile);
  ASSERT_TRUE(g) << g.error().message;
  const auto info = (*g)->backend().info();
  const auto caps = rtl::caps_of(*rtl::parse_gateware_profile(GetParam().profile.gateware));
  EXPECT_EQ(info.id, caps.id_register());
  EXPECT_EQ(info.caps, caps.caps_register());
  EXPECT_EQ(info.caps2, caps.caps2_register());  // attach reads CAPS2 on a 1.4 device
  EXPECT_EQ(protocol::has_depth_buffer(info.id, info.caps2), caps.features2 != 0);
  // an upload, a readback, a swap
  std::vector<std::uint8_t> bytes(1000);
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i * 7 + 3);
  auto up = (*g)->backend().upload(0x1000, bytes);
  ASSERT_TRUE(up) << up.error().message;
  std::copy(bytes.begin(), bytes.end(), (*g)->sim().memory().begin() + 0x1000);
  auto back = (*g)->backend().readback(0x1000, 1000);
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(*back, bytes);
  const std::vector<protocol::Frame> frames{protocol::write_frame(Reg::FB_FORMAT, (2ull << 32) | (10 << 16) | 25),
                                            protocol::write_frame(Reg::FB_DISPLAY, 0x1000)};
  std::vector<std::uint8_t> wire;
  for (const auto& f : frames) protocol::append(wire, f);
  ASSERT_TRUE((*g)->backend().write_frames(protocol::FrameView{wire}));
  EXPECT_EQ((*g)->compare(), "");
  EXPECT_EQ((*g)->gateware_frames().size(), 1u);
  EXPECT_GT((*g)->reads_compared(), 3u);
}

INSTANTIATE_TEST_SUITE_P(Chips, Bridge, ::testing::ValuesIn(wirings()), [](const auto& p) { return p.param.name; });

// Every scene file (examples/scenes) on both profiles: the small up5k device refuses what it lacks
// (sizes, formats) with the same flags as the simulator configured like it.
struct SceneCase {
  std::string scene;
  std::string board;
};
void PrintTo(const SceneCase& c, std::ostream* os) { *os << c.scene << " on " << c.board; }

class Scenes : public ::testing::TestWithParam<SceneCase> {
 protected:
  void SetUp() override {
    if (!rtl::RtlDevice::available()) GTEST_SKIP() << rtl::RtlDevice::unavailable_reason();
  }
};

TEST_P(Scenes, MatchTheSimulatorThroughTheBridge) {
  const auto profile = board_profile(GetParam().board);
  auto g = GatewareBoard::open(profile);
  ASSERT_TRUE(g) << g.error().message;
  const auto path = std::filesystem::path(GPUBRIDGE_SCENE_DIR) / (GetParam().scene + ".json");
  // scenes are laid out for at least 8 MiB: what lies beyond a smaller device's VRAM is dropped
  // and flagged by both devices alike
  auto built = scene::load_scene(path, {.vram_bytes = std::max<std::uint64_t>(8u << 20, std::uint64_t{profile.vram_kib} * 1024)});
  ASSERT_TRUE(built) << built.error().message;
  for (const auto& tc : built->stream.commands) {
    if (const auto* f = std::get_if<protocol::FramesCmd>(&tc.command)) {
      ASSERT_TRUE((*g)->backend().write_frames(f->view()));
    } else if (const auto* u = std::get_if<protocol::UploadCmd>(&tc.command)) {
      ASSERT_TRUE((*g)->backend().upload(u->address, u->data));
      const auto m = (*g)->sim().memory();
      for (std::size_t i = 0; i < u->data.size() && u->address + i < m.size(); ++i) m[u->address + i] = u->data[i];
    }
  }
  EXPECT_EQ((*g)->compare(), "") << GetParam().scene << " on " << GetParam().board;
  ASSERT_GE((*g)->gateware_frames().size(), 1u);
  // The timing model's preset for the gateware profile predicts the gateware's work cycles from the
  // simulator's counters of the same stream (docs/gateware.md "Timing model": the scene files are
  // within 10 % on both profiles).
  auto preset = sim::timing_preset(profile.gateware);
  ASSERT_TRUE(preset) << preset.error().message;
  const double rtl_cycles = double((*g)->gateware().counters().work_cycles);
  const unsigned bpp = protocol::bytes_per_pixel((*g)->gateware_frames().back().format);
  const double model = sim::estimate_timing((*g)->sim().stats(), *preset, bpp).board_cycles;
  EXPECT_NEAR(model / rtl_cycles, 1.0, 0.10) << GetParam().scene << " on " << profile.gateware << ": model " << model
                                             << " cycles, RTL " << rtl_cycles;
}

std::vector<SceneCase> scene_cases() {
  std::vector<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(GPUBRIDGE_SCENE_DIR))
    if (e.path().extension() == ".json") names.push_back(e.path().stem().string());
  std::sort(names.begin(), names.end());
  std::vector<SceneCase> out;
  for (const auto& n : names)
    for (const char* b : {"icebreaker", "ulx3s"}) out.push_back({n, b});
  return out;
}

INSTANTIATE_TEST_SUITE_P(Files, Scenes, ::testing::ValuesIn(scene_cases()), [](const auto& p) {
  std::string n = p.param.scene + "_" + p.param.board;
  for (char& c : n)
    if (c == '-') c = '_';
  return n;
});

}  // namespace
}  // namespace gpubridge::test
