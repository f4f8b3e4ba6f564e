// Bring-up steps against emulated boards, including an SPI clock sweep that must stop below the
// clock where the emulated link starts flipping MISO bits.
#include <gtest/gtest.h>

#include "gpubridge/usb/board_factory.hpp"
#include "gpubridge/usb/bringup.hpp"
#include "test_profiles.hpp"

namespace gpubridge::usb {
namespace {

TEST(Bringup, PassesOnAnEmulatedFt232hAndFindsTheClockLimit) {
  auto profile = test::profile_for(BridgeChip::FT232H, /*busy_pin=*/true);
  profile.spi_clock_hz = 1'000'000;  // attach slowly, as the CLI does
  BoardOpenOptions o;
  o.emulate = true;
  o.emulated_max_reliable_hz = 16'000'000;
  auto board = open_board(profile, o);
  ASSERT_TRUE(board) << board.error().message;
  BringupOptions bo;
  bo.mem_bytes = 32 * 1024;
  bo.clock_iterations = 3;
  bo.max_clock_hz = 30'000'000;
  bo.readback = true;
  unsigned last_progress = 0;
  bo.progress = [&](const std::string&, unsigned p) { last_progress = p; };
  const auto rep = run_bringup(**board, bo);
  for (const auto& s : rep.steps) EXPECT_TRUE(s.ok || s.skipped) << s.name << ": " << s.detail;
  EXPECT_TRUE(rep.ok());
  EXPECT_EQ(last_progress, 100u);
  // 30 and 20 MHz flip bits; 15 MHz is the highest ladder step at or below 16 MHz.
  EXPECT_EQ(rep.best_clock_hz, 15'000'000u);
  ASSERT_GE(rep.steps.size(), 5u);
  EXPECT_EQ(rep.steps[3].name, "spi-clock");
  EXPECT_NE(rep.steps[3].detail.find("30 MHz FAIL"), std::string::npos) << rep.steps[3].detail;
}

TEST(Bringup, MemoryTestRejectsARangeBeyondVideoMemory) {
  BoardOpenOptions o;
  o.emulate = true;
  auto board = open_board(test::profile_for(BridgeChip::CP2130), o);
  ASSERT_TRUE(board) << board.error().message;
  BringupOptions bo;
  bo.mem_base = 0x7FFFFFF0;
  bo.clock_iterations = 1;
  const auto rep = run_bringup(**board, bo);
  EXPECT_FALSE(rep.ok());
  ASSERT_GE(rep.steps.size(), 3u);
  EXPECT_EQ(rep.steps[2].name, "memory");
  EXPECT_FALSE(rep.steps[2].ok);
  EXPECT_NE(rep.steps[2].detail.find("beyond video memory"), std::string::npos);
}

}  // namespace
}  // namespace gpubridge::usb
