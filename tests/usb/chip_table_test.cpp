// The chip table (backends/usb/src/bridge_chips.cpp) is complete: every chip in it has a model
// that stands behind the transport its driver expects, a driver that attaches through that model,
// a board profile in configs/boards and an entry in configs/cables; the cables agree with the
// table. And the SPI pins are a real seam: a board runs with other pins behind the chip model.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "gpubridge/protocol/registers.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/bridge_chips.hpp"
#include "gpubridge/usb/emu/chip_model.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "gpubridge/usb/emu/reference_target.hpp"
#include "gpubridge/usb/emu/spi_slave.hpp"
#include "test_profiles.hpp"

namespace gpubridge::usb {
namespace {

TEST(ChipTable, EveryChipHasAModelADriverAProfileAndACable) {
  auto profiles = load_board_profiles(GPUBRIDGE_TEST_CONFIG_DIR);
  ASSERT_TRUE(profiles) << profiles.error().message;
  auto cables = load_cables(GPUBRIDGE_TEST_CONFIG_DIR);
  ASSERT_TRUE(cables) << cables.error().message;
  ASSERT_FALSE(bridge_chips().empty());
  for (const auto& chip : bridge_chips()) {
    SCOPED_TRACE(std::string(chip.name));
    EXPECT_EQ(parse_bridge_chip(chip.name), chip.chip);
    EXPECT_EQ(&chip_info(chip.chip), &chip);
    EXPECT_TRUE(std::any_of(profiles->begin(), profiles->end(), [&](const BoardProfile& p) { return p.chip == chip.chip; }))
        << "no board profile in configs/boards uses the " << chip.label << "; add one (configs/boards/" << chip.name
        << "-generic.json)";
    EXPECT_TRUE(std::any_of(cables->begin(), cables->end(), [&](const CableInfo& c) { return c.chip == chip.name; }))
        << "no cable in configs/cables names the " << chip.label << "; add configs/cables/" << chip.name << ".json";
    ASSERT_NE(chip.open_driver, nullptr);
    ASSERT_NE(chip.make_model, nullptr);

    // The model on its own: the transport the chip's API needs, with the table's USB ids.
    auto model = chip.make_model(test::profile_for(chip.chip), emu::EmulationOptions{}, nullptr);
    ASSERT_NE(model, nullptr);
    if (chip.api == UsbApi::Hidapi) {
      ASSERT_NE(model->hid(), nullptr);
      EXPECT_EQ(model->usb(), nullptr);
      EXPECT_EQ(model->hid()->info().vid, chip.vid);
      EXPECT_EQ(model->hid()->info().pid, chip.pid);
    } else {
      ASSERT_NE(model->usb(), nullptr);
      EXPECT_EQ(model->hid(), nullptr);
      EXPECT_EQ(model->usb()->info().vid, chip.vid);
      EXPECT_EQ(model->usb()->info().pid, chip.pid);
    }

    // Model + driver + simulator: the board attaches (ID magic read over the link) with no request
    // the model flags.
    auto board = emu::open_emulated_board(test::profile_for(chip.chip));
    ASSERT_TRUE(board) << board.error().message;
    EXPECT_EQ(board->backend->info().id >> 32, protocol::kIdMagic);
    EXPECT_TRUE(board->stack->violations().empty()) << board->stack->violations().front();
  }
}

TEST(ChipTable, CablesMustAgreeWithTheTable) {
  const auto dir = std::filesystem::temp_directory_path() / ("gpubridge-cable-check-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "cables");
  struct Case {
    const char* json;
    const char* key;
  };
  const Case cases[] = {
      {R"({"name":"x","chip":"mcp2210","vid":"0x04d8","pid":"0x00de","api":"libusb","max_spi_hz":1000000})", "api"},
      {R"({"name":"x","chip":"ch341a","vid":"0x1a86","pid":"0x5512","api":"libusb","max_spi_hz":30000000})", "max_spi_hz"},
      {R"({"name":"x","chip":"ft9999","vid":"0x0403","pid":"0x6014","api":"libusb","max_spi_hz":1000000})", "chip"},
      {R"({"name":"x","chip":"ft232h","vid":"0x0403","pid":"0x6014","api":"libusb","max_spi_hz":1000000,"interfaces":["A","B"]})",
       "interfaces"},
  };
  for (const auto& c : cases) {
    std::ofstream(dir / "cables" / "bad.json") << c.json;
    auto cables = load_cables(dir);
    ASSERT_FALSE(cables) << c.json;
    EXPECT_NE(cables.error().message.find("bad.json: " + std::string(c.key) + ":"), std::string::npos) << cables.error().message;
  }
  std::filesystem::remove_all(dir);
}

// Stands in for another SPI slave (the rtl backend's Verilated gateware): the C++ slave behind a
// wrapper that counts what the chip model drives.
class CountingPins final : public emu::SpiPins {
 public:
  CountingPins() : slave_(target_, nullptr, [this] { target_.tick(); }) {}
  void set_cs(bool asserted) override {
    ++cs_edges;
    slave_.set_cs(asserted);
  }
  bool cs_asserted() const override { return slave_.cs_asserted(); }
  bool shift_bit(bool mosi) override {
    ++bits;
    return slave_.shift_bit(mosi);
  }
  std::uint8_t shift_byte(std::uint8_t mosi) override {
    bits += 8;
    return slave_.shift_byte(mosi);
  }
  bool busy_pin() const override { return slave_.busy_pin(); }
  void idle_tick() override { slave_.idle_tick(); }
  void set_clock_hz(std::uint32_t hz) override { slave_.set_clock_hz(hz); }

  std::uint64_t cs_edges = 0, bits = 0;

 private:
  emu::ReferenceTarget target_{emu::ReferenceTargetConfig{}};
  emu::SpiSlave slave_;
};

TEST(ChipTable, OtherSpiPinsCanStandBehindEveryChipModel) {
  for (const auto& chip : bridge_chips()) {
    SCOPED_TRACE(std::string(chip.name));
    CountingPins* pins = nullptr;
    emu::EmulationOptions eo;
    eo.pins = [&pins](const BoardProfile&) -> Result<std::unique_ptr<emu::SpiPins>> {
      auto p = std::make_unique<CountingPins>();
      pins = p.get();
      return std::unique_ptr<emu::SpiPins>(std::move(p));
    };
    auto board = emu::open_emulated_board(test::profile_for(chip.chip), eo);
    ASSERT_TRUE(board) << board.error().message;
    ASSERT_NE(pins, nullptr);
    EXPECT_EQ(board->backend->info().id >> 32, protocol::kIdMagic);
    EXPECT_GE(pins->bits, 72u * 2) << "the attach reads ID and CAPS through the substituted pins";
    EXPECT_GT(pins->cs_edges, 0u);
    EXPECT_EQ(&board->stack->pins(), pins);
    EXPECT_THROW(board->stack->slave(), std::logic_error);
    EXPECT_FALSE(board->stack->target_is_simulator());
  }
}

}  // namespace
}  // namespace gpubridge::usb
