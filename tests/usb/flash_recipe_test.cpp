// Flashing recipes: the shipped boards' "flash" sections, the programmer command lines built from
// them, the recipe's errors, and the bitstream checks made before anything touches a board.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/flash_recipe.hpp"

namespace gpubridge::usb {
namespace {

using Argv = std::vector<std::string>;

const auto kAllInstalled = [](std::string_view) { return true; };
const auto kNoneInstalled = [](std::string_view) { return false; };

FlashRequest request_for(const BoardProfile& p, FlashTarget target = FlashTarget::Flash) {
  FlashRequest rq;
  rq.board = p.name;
  rq.family = *fpga_family(p.fpga);
  rq.recipe = p.flash;
  rq.vid = p.vid;
  rq.pid = p.pid;
  rq.board_serial = p.serial;
  rq.target = target;
  rq.bitstream = "/b/" + p.flash.bitstream;
  return rq;
}

BoardProfile shipped(const std::string& name) {
  auto p = find_board_profile(GPUBRIDGE_TEST_CONFIG_DIR, name);
  EXPECT_TRUE(p) << p.error().message;
  return p ? *p : BoardProfile{};
}

TEST(FlashRecipe, ShippedGatewareBoardsNameTheirBitstreamAndProgrammers) {
  const auto ice = shipped("icebreaker");
  ASSERT_TRUE(ice.flash.present);
  EXPECT_EQ(ice.flash.bitstream, "icebreaker.bin");
  EXPECT_EQ(ice.flash.openfpgaloader_board, "ice40_generic");
  EXPECT_TRUE(ice.flash.iceprog);
  const auto ulx = shipped("ulx3s");
  ASSERT_TRUE(ulx.flash.present);
  EXPECT_EQ(ulx.flash.bitstream, "ulx3s.bit");
  EXPECT_FALSE(ulx.flash.iceprog);
  // The DMC-1 board runs someone else's bitstream: no file name, a source instead.
  auto dmc1 = find_uart_board_profile(GPUBRIDGE_TEST_CONFIG_DIR, "icebreaker-dmc1");
  ASSERT_TRUE(dmc1) << dmc1.error().message;
  EXPECT_TRUE(dmc1->flash.present);
  EXPECT_TRUE(dmc1->flash.bitstream.empty());
  EXPECT_NE(dmc1->flash.source.find("tinygpus"), std::string::npos);
}

TEST(FlashRecipe, IcebreakerCommandLines) {
  const auto ice = shipped("icebreaker");
  auto plan = plan_flash(request_for(ice), kAllInstalled);
  ASSERT_TRUE(plan) << plan.error().message;
  EXPECT_EQ(plan->tool, FlashTool::OpenFpgaLoader);
  EXPECT_EQ(plan->argv, (Argv{"openFPGALoader", "-b", "ice40_generic", "/b/icebreaker.bin"}));
  // SRAM: only iceprog (-S) can; openFPGALoader writes an iCE40 board's flash.
  plan = plan_flash(request_for(ice, FlashTarget::Sram), kAllInstalled);
  ASSERT_TRUE(plan) << plan.error().message;
  EXPECT_EQ(plan->argv, (Argv{"iceprog", "-d", "i:0x0403:0x6010", "-I", "A", "-S", "/b/icebreaker.bin"}));
  // Without openFPGALoader installed the flash goes through iceprog; a serial picks the adapter.
  auto rq = request_for(ice);
  rq.serial = "ib0042";
  plan = plan_flash(rq, [](std::string_view exe) { return exe == "iceprog"; });
  ASSERT_TRUE(plan) << plan.error().message;
  EXPECT_EQ(plan->argv, (Argv{"iceprog", "-d", "s:0x0403:0x6010:ib0042", "-I", "A", "/b/icebreaker.bin"}));
  EXPECT_TRUE(plan->installed);
}

TEST(FlashRecipe, Ulx3sCommandLines) {
  const auto ulx = shipped("ulx3s");
  auto plan = plan_flash(request_for(ulx), kAllInstalled);
  ASSERT_TRUE(plan) << plan.error().message;
  EXPECT_EQ(plan->argv, (Argv{"openFPGALoader", "-b", "ulx3s", "-f", "/b/ulx3s.bit"}));
  plan = plan_flash(request_for(ulx, FlashTarget::Sram), kAllInstalled);
  ASSERT_TRUE(plan) << plan.error().message;
  EXPECT_EQ(plan->argv, (Argv{"openFPGALoader", "-b", "ulx3s", "-m", "/b/ulx3s.bit"}));
  // The profile's serial is the SPI bridge's (an FT232H on the header), not the programmer's
  // (the on-board FT231X): openFPGALoader gets a serial only when the user gives one.
  auto rq = request_for(ulx);
  rq.board_serial = "FT232H-1";
  plan = plan_flash(rq, kAllInstalled);
  ASSERT_TRUE(plan);
  EXPECT_EQ(plan->argv, (Argv{"openFPGALoader", "-b", "ulx3s", "-f", "/b/ulx3s.bit"}));
}

TEST(FlashRecipe, RefusalsNameWhatCanBeDone) {
  const auto ulx = shipped("ulx3s");
  auto rq = request_for(ulx);
  rq.tool = FlashTool::Iceprog;
  auto plan = plan_flash(rq, kAllInstalled);
  ASSERT_FALSE(plan);
  EXPECT_NE(plan.error().message.find("iceprog cannot write its flash (can: openfpgaloader)"), std::string::npos) << plan.error().message;

  const auto ice = shipped("icebreaker");
  rq = request_for(ice, FlashTarget::Sram);
  rq.recipe.iceprog = false;
  plan = plan_flash(rq, kAllInstalled);
  ASSERT_FALSE(plan);
  EXPECT_NE(plan.error().message.find("no programmer in its profile can write its sram"), std::string::npos) << plan.error().message;
  EXPECT_NE(plan.error().message.find("--to flash"), std::string::npos) << plan.error().message;

  const auto generic = shipped("ft232h-generic");
  EXPECT_FALSE(generic.flash.present);
  rq = FlashRequest{};
  rq.board = generic.name;
  plan = plan_flash(rq, kAllInstalled);
  ASSERT_FALSE(plan);
  EXPECT_NE(plan.error().message.find("no \"flash\" section"), std::string::npos);

  // Nothing installed: the plan still names the preferred tool, marked not installed.
  plan = plan_flash(request_for(ice), kNoneInstalled);
  ASSERT_TRUE(plan);
  EXPECT_EQ(plan->tool, FlashTool::OpenFpgaLoader);
  EXPECT_FALSE(plan->installed);
}

std::string board_with_flash(const std::string& fpga, const std::string& flash) {
  return R"({"name": "b", "fpga": ")" + fpga + R"(", "bridge": {"chip": "ft2232h", "vid": "0x0403", "pid": "0x6010",
            "interface": "A", "spi_clock_hz": 1000000}, "device": {"vram_kib": 128, "max_width": 64, "max_height": 64,
            "fifo_depth": 64}, "flash": )" + flash + "}";
}

TEST(FlashRecipe, BadSectionsAreRefusedNamingTheKey) {
  struct Case {
    std::string fpga, flash, expect;
  };
  const Case cases[] = {
      {"iCE40 UP5K", R"("x.bin")", "b.json: flash: expected an object"},
      {"iCE40 UP5K", R"({"bitstream": "x.bin", "openfpgaloader_board": "ice40_generic", "speed": 1})", "flash.speed: unknown key"},
      {"iCE40 UP5K", R"({"bitstream": "x.bit", "iceprog": true})", "flash.bitstream: an iCE40 bitstream ends in .bin"},
      {"ECP5 LFE5U-85F", R"({"bitstream": "x.bin", "openfpgaloader_board": "ulx3s"})", "flash.bitstream: an ECP5 bitstream ends in .bit"},
      {"iCE40 UP5K", R"({"bitstream": "../x.bin", "iceprog": true})", "flash.bitstream: a file name in the bitstream directory"},
      {"ECP5 LFE5U-85F", R"({"bitstream": "x.bit", "iceprog": true})", "flash.iceprog: iceprog programs iCE40 parts only"},
      {"iCE40 UP5K", R"({"bitstream": "x.bin"})", "flash.openfpgaloader_board: missing"},
      {"iCE40 UP5K", R"({"iceprog": true})", "flash.source: say where the bitstream comes from"},
      {"Gowin GW1N", R"({"bitstream": "x.fs", "openfpgaloader_board": "tangnano"})", "flash: needs \"fpga\" to name the part"},
      {"iCE40 UP5K", R"({"bitstream": 3, "iceprog": true})", "flash.bitstream: expected a string"},
  };
  for (const auto& c : cases) {
    auto p = parse_board_profile(board_with_flash(c.fpga, c.flash), "b.json");
    ASSERT_FALSE(p) << c.flash;
    EXPECT_NE(p.error().message.find(c.expect), std::string::npos) << p.error().message;
  }
}

TEST(FlashRecipe, PartsAndIdcodes) {
  EXPECT_EQ(fpga_family("iCE40 UP5K"), FpgaFamily::Ice40);
  EXPECT_EQ(fpga_family("ECP5 LFE5U-25F"), FpgaFamily::Ecp5);
  EXPECT_FALSE(fpga_family("Gowin GW1N-9"));
  EXPECT_EQ(ecp5_idcode("ECP5 LFE5U-85F"), 0x41113043u);
  EXPECT_EQ(ecp5_idcode("ECP5 LFE5U-25F, 256 Mbit SDRAM"), 0x41111043u);
  EXPECT_EQ(ecp5_idcode("ECP5 LFE5U-25F1"), std::nullopt);  // the part name must end there
  EXPECT_EQ(ecp5_idcode("ECP5 LFE5UM-85F"), std::nullopt);
}

// The head of a file icepack writes: a comment block, then the sync word.
std::vector<std::uint8_t> ice40_bitstream() {
  std::vector<std::uint8_t> b{0xFF, 0x00};
  for (char c : std::string("Lattice\0iCE40 UP5K", 18)) b.push_back(static_cast<std::uint8_t>(c));
  b.insert(b.end(), {0x00, 0xFF, 0x7E, 0xAA, 0x99, 0x7E, 0x51, 0x00, 0x01, 0x05});
  b.resize(104090, 0x00);
  return b;
}

// ecppack's: comment, preamble, dummy bytes, LSC_RESET_CRC, VERIFY_ID with the IDCODE.
std::vector<std::uint8_t> ecp5_bitstream(std::uint32_t idcode) {
  std::vector<std::uint8_t> b{0xFF, 0x00, 'P', 'a', 'r', 't', 0x00, 0x00, 0xFF, 0xFF, 0xFF, 0xBD, 0xB3, 0xFF, 0xFF, 0xFF, 0xFF,
                              0x3B, 0x00, 0x00, 0x00, 0xE2, 0x00, 0x00, 0x00};
  for (int shift = 24; shift >= 0; shift -= 8) b.push_back(static_cast<std::uint8_t>(idcode >> shift));
  b.resize(4096, 0x00);
  return b;
}

TEST(FlashRecipe, BitstreamChecks) {
  EXPECT_TRUE(check_bitstream(ice40_bitstream(), FpgaFamily::Ice40, std::nullopt, "f.bin"));
  EXPECT_TRUE(check_bitstream(ecp5_bitstream(0x41113043), FpgaFamily::Ecp5, 0x41113043u, "f.bit"));
  EXPECT_TRUE(check_bitstream(ecp5_bitstream(0x41113043), FpgaFamily::Ecp5, std::nullopt, "f.bit"));

  const auto expect_error = [](const std::vector<std::uint8_t>& bytes, FpgaFamily family, std::optional<std::uint32_t> id,
                               const std::string& what) {
    auto r = check_bitstream(bytes, family, id, "f");
    ASSERT_FALSE(r) << what;
    EXPECT_NE(r.error().message.find(what), std::string::npos) << r.error().message;
  };
  expect_error({}, FpgaFamily::Ice40, std::nullopt, "f: empty file");
  expect_error(ecp5_bitstream(0x41113043), FpgaFamily::Ice40, std::nullopt, "not an iCE40 bitstream");
  expect_error(ice40_bitstream(), FpgaFamily::Ecp5, std::nullopt, "not an ECP5 bitstream");
  expect_error(ecp5_bitstream(0x41111043), FpgaFamily::Ecp5, 0x41113043u, "packed for IDCODE 0x41111043 (an LFE5U-25F)");
  // A sync word beyond the header window is not a header.
  auto late = std::vector<std::uint8_t>(5000, 0x00);
  late.insert(late.end(), {0x7E, 0xAA, 0x99, 0x7E});
  expect_error(late, FpgaFamily::Ice40, std::nullopt, "not an iCE40 bitstream");
  // A truncated VERIFY_ID is no IDCODE to compare, not an out-of-bounds read.
  auto cut = ecp5_bitstream(0x41113043);
  cut.resize(27);
  EXPECT_TRUE(check_bitstream(cut, FpgaFamily::Ecp5, 0x41111043u, "f"));
}

}  // namespace
}  // namespace gpubridge::usb
