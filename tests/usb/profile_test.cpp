// Board profiles: every shipped file loads; broken files are rejected naming file and key.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "gpubridge/usb/board_profile.hpp"

namespace gpubridge::usb {
namespace {

TEST(BoardProfiles, ShippedProfilesLoad) {
  auto all = load_board_profiles(GPUBRIDGE_TEST_CONFIG_DIR);
  ASSERT_TRUE(all) << all.error().message;
  std::vector<std::string> names;
  for (const auto& p : *all) names.push_back(p.name);
  for (const char* want : {"icebreaker", "ft232h-generic", "icepi-zero", "ulx3s", "ch341a-generic", "mcp2210-generic", "cp2130-generic"})
    EXPECT_NE(std::find(names.begin(), names.end(), want), names.end()) << want;
  auto ice = find_board_profile(GPUBRIDGE_TEST_CONFIG_DIR, "icebreaker");
  ASSERT_TRUE(ice);
  EXPECT_EQ(ice->chip, BridgeChip::FT2232H);
  EXPECT_EQ(ice->interface, 0);
  EXPECT_EQ(ice->pid, 0x6010);
  // The iCEBreaker top's PLL clock and the FT2232H step its MISO timing allows (docs/gateware.md "Boards").
  EXPECT_DOUBLE_EQ(ice->clock_mhz, 25.125);
  EXPECT_EQ(ice->spi_clock_hz, 7'500'000u);
}

TEST(BoardProfiles, ShippedCablesLoad) {
  auto cables = load_cables(GPUBRIDGE_TEST_CONFIG_DIR);
  ASSERT_TRUE(cables) << cables.error().message;
  EXPECT_GE(cables->size(), 6u);
}

const char* kGood = R"({"name":"x","bridge":{"chip":"ft232h","vid":"0x0403","pid":"0x6014","spi_clock_hz":30000000},
  "device":{"vram_kib":128,"max_width":320,"max_height":240,"fifo_depth":64}})";

// device.clock_mhz is a number (the iCEBreaker's PLL makes 25.125 MHz), finite and within 1..1000.
TEST(BoardProfiles, CoreClockIsAFractionalNumberInRange) {
  const std::string at = "\"fifo_depth\":64";
  std::string text = kGood;
  text.replace(text.find(at), at.size(), at + ",\"clock_mhz\":25.125");
  auto r = parse_board_profile(text, "frac.json");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_DOUBLE_EQ(r->clock_mhz, 25.125);
  EXPECT_DOUBLE_EQ(parse_board_profile(kGood, "default.json")->clock_mhz, 50.0);
  for (const char* bad : {"0.5", "1000.5", "-25", "\"25\"", "null"}) {
    std::string t = kGood;
    t.replace(t.find(at), at.size(), at + ",\"clock_mhz\":" + bad);
    auto e = parse_board_profile(t, "boards/clk.json");
    ASSERT_FALSE(e) << bad;
    EXPECT_NE(e.error().message.find("boards/clk.json: device.clock_mhz"), std::string::npos) << e.error().message;
  }
}

TEST(BoardProfiles, ErrorsNameFileAndKey) {
  ASSERT_TRUE(parse_board_profile(kGood, "good.json"));
  struct Case {
    std::string from, to, key;
  };
  const Case cases[] = {
      {"30000000", "60000000", "bridge.spi_clock_hz"},
      {"\"ft232h\"", "\"ft9999\"", "bridge.chip"},
      {"\"0x0403\"", "\"0xZZ\"", "bridge.vid"},
      {"\"fifo_depth\":64", "\"fifo_depth\":8", "device.fifo_depth"},
      {"\"fifo_depth\":64}", "\"fifo_depth\":64,\"fifo_dept\":3}", "device.fifo_dept"},
      {"\"name\":\"x\"", "\"name\":\"Bad Name\"", "name"},
  };
  for (const auto& c : cases) {
    std::string text = kGood;
    text.replace(text.find(c.from), c.from.size(), c.to);
    auto r = parse_board_profile(text, "boards/bad.json");
    ASSERT_FALSE(r) << c.key;
    EXPECT_NE(r.error().message.find("boards/bad.json: " + c.key), std::string::npos) << r.error().message;
  }
  EXPECT_FALSE(parse_board_profile("{not json", "broken.json"));
  EXPECT_FALSE(parse_board_profile("[]", "array.json"));
}

TEST(BoardProfiles, StreamReadsIsAnFtdiSwitchDefaultingOn) {
  auto on = parse_board_profile(kGood, "good.json");
  ASSERT_TRUE(on) << on.error().message;
  EXPECT_TRUE(on->stream_reads);
  std::string off = kGood;
  off.replace(off.find("\"spi_clock_hz\":30000000"), 23, "\"spi_clock_hz\":30000000,\"stream_reads\":false");
  auto r = parse_board_profile(off, "off.json");
  ASSERT_TRUE(r) << r.error().message;
  EXPECT_FALSE(r->stream_reads);
  std::string ch341 = off;
  ch341.replace(ch341.find("\"ft232h\""), 8, "\"ch341a\"");
  ch341.replace(ch341.find("\"0x0403\""), 8, "\"0x1a86\"");
  ch341.replace(ch341.find("\"0x6014\""), 8, "\"0x5512\"");
  ch341.replace(ch341.find("30000000"), 8, "1000000");
  auto bad = parse_board_profile(ch341, "ch.json");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("ch.json: bridge.stream_reads"), std::string::npos) << bad.error().message;
  std::string ch341_on = ch341;
  ch341_on.replace(ch341_on.find("false"), 5, "true");
  EXPECT_FALSE(parse_board_profile(ch341_on, "ch.json")) << "the key belongs to FTDI profiles whatever its value";
}

// Found by fuzz_board_profile: a number literal beyond double's range makes nlohmann::json throw
// out_of_range (not parse_error), which escaped the parser and terminated the process.
TEST(BoardProfiles, NumberBeyondDoubleRangeIsAnError) {
  std::string text = kGood;
  text.replace(text.find("128"), 3, "1e999");
  auto r = parse_board_profile(text, "boards/huge.json");
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message.find("boards/huge.json: not valid JSON"), std::string::npos) << r.error().message;

  // load_cables reads its files the same way.
  const auto dir = std::filesystem::temp_directory_path() / ("gpubridge-cables-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "cables");
  std::ofstream(dir / "cables" / "huge.json") << R"({"name":"x","chip":"ft232h","max_spi_hz":1e999})";
  auto cables = load_cables(dir);
  std::filesystem::remove_all(dir);
  ASSERT_FALSE(cables);
  EXPECT_NE(cables.error().message.find("huge.json: not valid JSON"), std::string::npos) << cables.error().message;
}

}  // namespace
}  // namespace gpubridge::usb
