// Board profiles: every shipped file loads; broken files are rejected naming file and key.
#include <gtest/gtest.h>

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
}

TEST(BoardProfiles, ShippedCablesLoad) {
  auto cables = load_cables(GPUBRIDGE_TEST_CONFIG_DIR);
  ASSERT_TRUE(cables) << cables.error().message;
  EXPECT_GE(cables->size(), 6u);
}

const char* kGood = R"({"name":"x","bridge":{"chip":"ft232h","vid":"0x0403","pid":"0x6014","spi_clock_hz":30000000},
  "device":{"vram_kib":128,"max_width":320,"max_height":240,"fifo_depth":64}})";

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

}  // namespace
}  // namespace gpubridge::usb
