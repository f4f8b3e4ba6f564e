// Fault sweep (reliability-tests.md section 4): a fault is injected at every transport operation
// index (and at sampled SPI bit / frame indices) of a whole session — attach, upload, a frame
// swap, readback. Every run must end in a specific error or in correct data: never a hang, a
// crash, or a silently wrong result.
#include <gtest/gtest.h>

#include <random>

#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/usb/emu/emulated_stack.hpp"
#include "test_profiles.hpp"

namespace gpubridge::usb {
namespace {

using protocol::Reg;

struct Outcome {
  bool ok = false;
  Error error;
  std::uint64_t usb_ops = 0;
  std::uint64_t frames = 0;
  std::uint64_t streamed_reads = 0;  // FTDI reads that went through the asynchronous IN queue
};

std::vector<std::uint8_t> payload() {
  std::vector<std::uint8_t> v(1200);  // 150 memory words: 1,350 MISO bytes, more than the FT232H RX FIFO (streamed reads)
  std::mt19937 rng(5);
  for (auto& b : v) b = static_cast<std::uint8_t>(rng());
  return v;
}

// The session under test. `arm` injects the fault after the stack exists, before the driver opens.
template <class Arm>
Outcome run_session(BridgeChip chip, Arm arm) {
  Outcome o;
  auto stack = emu::EmulatedStack::create(test::profile_for(chip), emu::EmulationOptions{});
  if (!stack) {
    o.error = stack.error();
    return o;
  }
  std::shared_ptr<emu::EmulatedStack> s = std::move(*stack);
  arm(*s);
  auto finish = [&](Error e) {
    o.error = std::move(e);
    o.usb_ops = s->usb_faults().ops;
    o.frames = s->slave().frames_completed();
    return o;
  };
  const auto profile = test::profile_for(chip);
  auto bridge = open_bridge(profile, s->transport());
  if (!bridge) return finish(bridge.error());
  BoardOptions bo;
  bo.max_status_polls = 200;
  bo.host_tag = 0x1234;
  auto board = BoardBackend::attach(profile, s, std::move(*bridge), bo);
  if (!board) return finish(board.error());
  auto& b = **board;
  const auto data = payload();
  std::shared_ptr<const backends::ScanoutFrame> shown;
  b.set_scanout_callback([&](auto f) { shown = std::move(f); });
  if (auto r = b.upload(0x1000, data); !r) return finish(r.error());
  std::vector<std::uint8_t> bytes;
  protocol::append(bytes, protocol::write_frame(Reg::FB_FORMAT, (std::uint64_t{10} << 16) | 30));  // 30x10 RGBA = 1200 bytes
  protocol::append(bytes, protocol::write_frame(Reg::FB_DISPLAY, 0x1000));
  if (auto r = b.write_frames(protocol::FrameView{bytes}); !r) return finish(r.error());
  auto back = b.readback(0x1000, static_cast<std::uint32_t>(data.size()));
  if (!back) return finish(back.error());
  // Success must mean correct data everywhere.
  EXPECT_EQ(*back, data) << "silently wrong readback";
  EXPECT_TRUE(shown) << "no scanout frame";
  if (shown) {
    EXPECT_EQ(shown->pixels, data) << "silently wrong scanout frame";
    EXPECT_EQ(shown->crc, protocol::crc32(data));
  }
  o.ok = true;
  o.streamed_reads = b.bridge().stats().streamed_reads;
  o.usb_ops = s->usb_faults().ops;
  o.frames = s->slave().frames_completed();
  return o;
}

bool specific(const Error& e) {
  return !e.message.empty() && (e.code == backends::kDeviceGone || e.code == backends::kDeviceTimeout ||
                                e.code == backends::kDeviceProtocol);
}

class FaultSweep : public ::testing::TestWithParam<BridgeChip> {};

TEST_P(FaultSweep, UsbFaultsAtEveryOperation) {
  const auto clean = run_session(GetParam(), [](emu::EmulatedStack&) {});
  ASSERT_TRUE(clean.ok) << clean.error.message;
  ASSERT_GT(clean.usb_ops, 10u);
  if (GetParam() == BridgeChip::FT232H) {
    ASSERT_GT(clean.streamed_reads, 0u) << "the sweep must cover the streamed (asynchronous) read path";
  }
  for (auto fault : {emu::UsbFault::NoDevice, emu::UsbFault::TimeoutPartial, emu::UsbFault::Stall}) {
    unsigned recovered = 0, failed = 0;
    for (std::uint64_t op = 0; op < clean.usb_ops; ++op) {
      SCOPED_TRACE("fault " + std::to_string(static_cast<int>(fault)) + " at op " + std::to_string(op));
      const auto o = run_session(GetParam(), [&](emu::EmulatedStack& s) {
        s.usb_faults().at_op = op;
        s.usb_faults().fault = fault;
        s.usb_faults().partial_bytes = 5;
      });
      if (o.ok) {
        ++recovered;
        continue;
      }
      ++failed;
      ASSERT_TRUE(specific(o.error)) << "op " << op << ": code " << o.error.code << " " << o.error.message;
      if (fault == emu::UsbFault::NoDevice) {
        EXPECT_EQ(o.error.code, backends::kDeviceGone) << "op " << op << ": " << o.error.message;
      }
    }
    if (fault == emu::UsbFault::NoDevice) {
      EXPECT_EQ(recovered, 0u) << "an unplug cannot be survived";
    }
    EXPECT_EQ(recovered + failed, clean.usb_ops);
  }
}

TEST_P(FaultSweep, SpiBitFlipsStuckMisoAndPowerCycles) {
  const auto clean = run_session(GetParam(), [](emu::EmulatedStack&) {});
  ASSERT_TRUE(clean.ok) << clean.error.message;
  const std::uint64_t bits = clean.frames * 72;
  const std::uint64_t step = std::max<std::uint64_t>(1, bits / 150);
  for (std::uint64_t bit = 0; bit < bits; bit += step) {
    for (bool mosi : {true, false}) {
      SCOPED_TRACE(std::string(mosi ? "MOSI" : "MISO") + " bit " + std::to_string(bit));
      const auto o = run_session(GetParam(), [&](emu::EmulatedStack& s) {
        if (mosi) s.spi_faults().flip_mosi_bit = bit;
        else s.spi_faults().flip_miso_bit = bit;
      });
      if (!o.ok) {
        ASSERT_TRUE(specific(o.error)) << (mosi ? "MOSI" : "MISO") << " bit " << bit << ": " << o.error.message;
      }
    }
  }
  for (std::uint8_t stuck : {std::uint8_t{0xFF}, std::uint8_t{0x00}}) {
    const auto o = run_session(GetParam(), [&](emu::EmulatedStack& s) { s.spi_faults().miso_stuck = stuck; });
    ASSERT_FALSE(o.ok);
    EXPECT_EQ(o.error.code, backends::kDeviceProtocol);
    EXPECT_NE(o.error.message.find(stuck ? "all 1s" : "all 0s"), std::string::npos) << o.error.message;
  }
  const std::uint64_t frame_step = std::max<std::uint64_t>(1, clean.frames / 60);
  for (std::uint64_t f = 1; f < clean.frames; f += frame_step) {
    SCOPED_TRACE("power cycle at frame " + std::to_string(f));
    const auto o = run_session(GetParam(), [&](emu::EmulatedStack& s) { s.spi_faults().power_cycle_at_frame = f; });
    if (!o.ok) {
      ASSERT_TRUE(specific(o.error)) << "power cycle at frame " << f << ": " << o.error.message;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Chips, FaultSweep,
                         ::testing::Values(BridgeChip::FT232H, BridgeChip::CH341A, BridgeChip::MCP2210, BridgeChip::CP2130),
                         [](const auto& i) { return std::string(to_string(i.param)); });

}  // namespace
}  // namespace gpubridge::usb
