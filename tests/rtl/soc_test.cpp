// The gateware's SoC (everything around the render core) against the simulator configured with the
// same CAPS, at the pins: identification, register validation and read-back, MEM_ADDR / MEM_DATA
// with back-to-back prefetched reads, link CRC and strict mode, aborted frames, swaps with
// FRAME_CRC and the scanned-out bytes, RESET. Streams here need no rendering.
#include <gtest/gtest.h>

#include <random>

#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/rtl/rtl_device.hpp"
#include "gpubridge/rtl/simulator_options.hpp"
#include "gpubridge/sim/device.hpp"
#include "pin_host.hpp"

namespace {

using namespace gpubridge;
using protocol::Frame;
using protocol::Reg;
using protocol::index_of;

// STATUS fields a timed device and the untimed simulator share once both are idle: the errors and
// the frame counter (BUSY, FIFO_LEVEL and VBLANK are timing; the host waited for them).
constexpr std::uint64_t kStatusCompared = 0xFFFFFFFF00000000ull | (1ull << 18);

class SocBench : public ::testing::TestWithParam<rtl::GatewareProfile> {
 protected:
  void SetUp() override {
    if (!rtl::RtlDevice::available()) GTEST_SKIP() << rtl::RtlDevice::unavailable_reason();
    auto d = rtl::RtlDevice::create(GetParam());
    ASSERT_TRUE(d) << d.error().message;
    rtl_ = std::move(*d);
    auto s = sim::Device::create(rtl::simulator_options(rtl_->caps()));
    ASSERT_TRUE(s) << s.error().message;
    sim_ = std::move(*s);
    host_ = std::make_unique<test::PinHost>(*rtl_);
    rtl_->set_frame_callback([this](const rtl::ScanFrame& f) { rtl_frames_.push_back(f); });
    sim_->set_scanout_callback([this](std::shared_ptr<const backends::ScanoutFrame> f) { sim_frames_.push_back(*f); });
  }

  void TearDown() override {
    if (!rtl_) return;
    const rtl::RtlCounters c = rtl_->counters();
    EXPECT_EQ(c.sdram_violations, 0u) << "the SDRAM controller broke the part's timing (see the model's messages)";
    EXPECT_EQ(c.sck_edges_too_fast, 0u);
  }

  // A burst to both devices.
  std::vector<test::PinFrameResult> burst(const std::vector<Frame>& frames) {
    for (const auto& f : frames) {
      if (f.read) sim_->read(f.index);
      else sim_->write(f);
    }
    return host_->burst(frames);
  }
  void write(Reg r, std::uint64_t v) { burst({Frame{false, index_of(r), v}}); }
  void write(std::uint8_t i, std::uint64_t v) { burst({Frame{false, i, v}}); }
  void expect_read_equal(std::uint8_t index, std::uint64_t mask = ~0ull) {
    const std::uint64_t s = sim_->read(index);
    const std::uint64_t r = host_->read(index);
    EXPECT_EQ(r & mask, s & mask) << "register 0x" << std::hex << int(index) << ": gateware 0x" << r << ", simulator 0x" << s;
  }
  void wait_idle() {
    unsigned polls = 0;
    const std::uint64_t s = host_->wait_idle(polls);
    ASSERT_EQ(s & 0x1FFFFF & ~(1ull << 17) & ~(1ull << 18), 0u) << "gateware did not become idle: STATUS 0x" << std::hex << s;
    // the host's polls are frames on the link (LINK_STATUS.FRAMES, the link CRC) for the simulator too
    for (unsigned i = 0; i < polls; ++i) sim_->read(index_of(Reg::STATUS));
  }
  void expect_vram_equal() {
    const auto r = rtl_->vram();
    const auto s = sim_->memory();
    ASSERT_EQ(r.size(), s.size());
    for (std::size_t i = 0; i < r.size(); ++i)
      if (r[i] != s[i]) FAIL() << "video memory differs first at byte 0x" << std::hex << i << ": gateware 0x" << int(r[i])
                               << ", simulator 0x" << int(s[i]);
  }

  std::unique_ptr<rtl::RtlDevice> rtl_;
  std::unique_ptr<sim::Device> sim_;
  std::unique_ptr<test::PinHost> host_;
  std::vector<rtl::ScanFrame> rtl_frames_;
  std::vector<backends::ScanoutFrame> sim_frames_;
};

TEST_P(SocBench, IdentityAndCapsMatchTheProfile) {
  EXPECT_EQ(host_->read(Reg::ID), rtl_->caps().id_register());
  EXPECT_EQ(host_->read(Reg::CAPS), rtl_->caps().caps_register());
  EXPECT_EQ(host_->read(Reg::CAPS), sim_->caps());
  // the MISO status byte carries the marker bits 10
  const auto r = host_->burst(std::vector<Frame>{Frame{true, index_of(Reg::ID), 0}, Frame{true, index_of(Reg::CAPS), 0}});
  EXPECT_EQ(r[0].status & 0xC0, 0x80);
  EXPECT_EQ(r[1].status & 0xC0, 0x80);
  EXPECT_EQ(r[1].data, rtl_->caps().caps_register());
}

TEST_P(SocBench, Caps2MatchesTheProfile) {
  // protocol 1.4: CAPS2.FEATURES2 bit 0 is the depth buffer (ecp5 has it, up5k not)
  EXPECT_EQ(protocol::protocol_minor(host_->read(Reg::ID)), 4u);
  EXPECT_EQ(host_->read(Reg::CAPS2), rtl_->caps().caps2_register());
  EXPECT_EQ(host_->read(Reg::CAPS2), sim_->caps2());
  EXPECT_EQ(rtl_->caps().caps2_register(), GetParam() == rtl::GatewareProfile::Ecp5 ? 1u : 0u);
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);  // a defined register: no ERR_BAD_REGISTER
}

// Without a depth buffer TRI_MODE.Z_TEST / Z_WRITE read back as 0 with ERR_BAD_VALUE and CLEAR_Z is
// refused when it executes; with one they act. Both devices the same, memory and flags.
TEST_P(SocBench, DepthWritesAreRefusedExactlyWhenTheProfileHasNoDepthBuffer) {
  const bool depth = rtl_->caps().features2 & 1;
  // a 16 x 8 RGBA8888 colour buffer at 0, its depth buffer at 0x1000 (filled with a pattern first)
  std::vector<Frame> frames{Frame{false, index_of(Reg::MEM_ADDR), 0x1000}};
  for (int i = 0; i < 64; ++i) frames.push_back(Frame{false, index_of(Reg::MEM_DATA), 0x0102030405060708ull * (i + 1)});
  frames.push_back(Frame{false, index_of(Reg::FB_FORMAT), (8ull << 16) | 16});
  frames.push_back(Frame{false, index_of(Reg::FB_DRAW), 0});
  frames.push_back(Frame{false, index_of(Reg::FB_Z), 0x1000});  // ADDR [31:4]: the byte address
  frames.push_back(Frame{false, index_of(Reg::SCISSOR), (8ull << 48) | (16ull << 32)});
  frames.push_back(Frame{false, index_of(Reg::CLEAR_DEPTH), 0x123456});
  burst(frames);
  wait_idle();
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  write(Reg::ERR_CLEAR, 0x7F);
  write(Reg::CLEAR_Z, 0);
  wait_idle();
  const std::uint64_t status = host_->read(Reg::STATUS);
  sim_->read(index_of(Reg::STATUS));
  EXPECT_EQ(((status >> 48) & protocol::ERR_BAD_VALUE) != 0, !depth) << "CLEAR_Z";
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  expect_vram_equal();
  write(Reg::ERR_CLEAR, 0x7F);
  // Z_TEST | Z_FUNC LESS | Z_WRITE | GOURAUD, then a triangle over the buffer
  const std::uint64_t tri_mode = (1u << 6) | (1u << 3) | (1u << 2) | 1u;
  write(Reg::TRI_MODE, tri_mode);
  wait_idle();
  EXPECT_EQ(host_->read(Reg::TRI_MODE), depth ? tri_mode : (1u << 3) | 1u);
  expect_read_equal(index_of(Reg::TRI_MODE));
  const std::uint64_t st = host_->read(Reg::STATUS);
  sim_->read(index_of(Reg::STATUS));
  EXPECT_EQ(((st >> 48) & protocol::ERR_BAD_VALUE) != 0, !depth) << "TRI_MODE";
  const std::uint64_t verts[] = {(std::uint64_t{0x100000} << 32) | (0 << 16) | 0, (std::uint64_t{0x100000} << 32) | (0 << 16) | (16 * 16),
                                 (std::uint64_t{0x100000} << 32) | ((8 * 16) << 16) | 0};
  burst({Frame{false, index_of(Reg::PRIM), 0}, Frame{false, index_of(Reg::COLOR), 0xFFFFFFFF'FF8040FFull},
         Frame{false, index_of(Reg::VERTEX), verts[0]}, Frame{false, index_of(Reg::VERTEX), verts[1]},
         Frame{false, index_of(Reg::VERTEX), verts[2]}});
  wait_idle();
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  expect_vram_equal();
}

TEST_P(SocBench, RegisterValidationAndReadBackMatchTheSimulator) {
  std::mt19937_64 rng(1234);
  const std::uint8_t rw[] = {0x00, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08, 0x0A, 0x0D, 0x0E, 0x0F, 0x16, 0x18};
  for (int round = 0; round < 6; ++round) {
    std::vector<Frame> frames;
    for (std::uint8_t i : rw) {
      std::uint64_t v = rng();
      if (round % 2 == 0) v &= protocol::find_register(i) ? ~protocol::find_register(i)->reserved_mask() : ~0ull;
      if (round == 4) v &= 0x00000FFF0000FFFFull;  // small values: in-range fields
      frames.push_back(Frame{false, i, v});
    }
    frames.push_back(Frame{false, 0x55, rng()});                 // undefined index
    frames.push_back(Frame{false, index_of(Reg::STATUS), 1});    // read-only
    burst(frames);
    wait_idle();
    for (std::uint8_t i : rw) expect_read_equal(i);
    expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
    expect_read_equal(index_of(Reg::CLEAR));   // write-only: 0
    expect_read_equal(0x66);                   // undefined: 0 and ERR_BAD_REGISTER
    expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
    write(Reg::ERR_CLEAR, round == 3 ? 0xFFFFFFFFFFFF0005ull : 0x7F);  // round 3: reserved bits set
    expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  }
}

TEST_P(SocBench, UploadAndBackToBackReadback) {
  std::mt19937_64 rng(99);
  std::vector<Frame> frames{Frame{false, index_of(Reg::MEM_ADDR), 0x1000}};
  for (int i = 0; i < 40; ++i) frames.push_back(Frame{false, index_of(Reg::MEM_DATA), rng()});
  burst(frames);
  wait_idle();
  expect_vram_equal();
  write(Reg::MEM_ADDR, 0x1008);
  wait_idle();
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);  // MEM_READY
  std::vector<Frame> reads(39, Frame{true, index_of(Reg::MEM_DATA), 0});
  const auto r = burst(reads);
  std::vector<std::uint8_t> mem(39 * 8);
  rtl_->read_vram(0x1008, mem.data(), mem.size());
  for (std::size_t i = 0; i < r.size(); ++i) {
    std::uint64_t want = 0;
    for (int b = 0; b < 8; ++b) want = (want << 8) | mem[i * 8 + b];
    EXPECT_EQ(r[i].data, want) << "MEM_DATA read " << i << " of a burst";
  }
  expect_read_equal(index_of(Reg::MEM_ADDR));
  // the last word of VRAM, then beyond: the look-ahead is no error, the read returning it is
  const std::uint64_t end = std::uint64_t{rtl_->caps().vram_kib} * 1024;
  write(Reg::MEM_ADDR, end - 8);
  write(Reg::MEM_DATA, 0x0123456789ABCDEFull);
  wait_idle();
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  expect_read_equal(index_of(Reg::MEM_DATA));
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  write(Reg::MEM_DATA, 1);  // beyond VRAM: dropped, ERR_MEM_RANGE
  wait_idle();
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  expect_vram_equal();
}

TEST_P(SocBench, SwapScansTheBufferAsItWasWhenFbDisplayExecuted) {
  // a 12 x 5 RGBA2222 frame (60 bytes: the last word is partial), then an RGB565 one
  std::mt19937_64 rng(7);
  std::vector<Frame> frames{Frame{false, index_of(Reg::MEM_ADDR), 0x2000}};
  for (int i = 0; i < 32; ++i) frames.push_back(Frame{false, index_of(Reg::MEM_DATA), rng()});
  frames.push_back(Frame{false, index_of(Reg::FB_FORMAT), (2ull << 32) | (5 << 16) | 12});
  frames.push_back(Frame{false, index_of(Reg::FB_DISPLAY), 0x2000});
  // written right after the swap into the displayed buffer: not part of that frame
  frames.push_back(Frame{false, index_of(Reg::MEM_ADDR), 0x2000});
  frames.push_back(Frame{false, index_of(Reg::MEM_DATA), 0xFFFFFFFFFFFFFFFFull});
  burst(frames);
  wait_idle();
  burst({Frame{false, index_of(Reg::FB_FORMAT), (1ull << 32) | (3 << 16) | 7}, Frame{false, index_of(Reg::FB_DISPLAY), 0x2010}});
  wait_idle();
  expect_read_equal(index_of(Reg::FRAME_CRC));
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  ASSERT_EQ(rtl_frames_.size(), 2u);
  ASSERT_EQ(sim_frames_.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(rtl_frames_[i].width, sim_frames_[i].width);
    EXPECT_EQ(rtl_frames_[i].height, sim_frames_[i].height);
    EXPECT_EQ(rtl_frames_[i].format, sim_frames_[i].format);
    EXPECT_EQ(rtl_frames_[i].bytes, sim_frames_[i].pixels) << "frame " << i;
    EXPECT_EQ(protocol::crc32(rtl_frames_[i].bytes), sim_frames_[i].crc);
  }
  expect_vram_equal();
}

TEST_P(SocBench, DisplayBeyondVramReadsZerosAndFlagsMemRange) {
  const std::uint64_t end = std::uint64_t{rtl_->caps().vram_kib} * 1024;
  burst({Frame{false, index_of(Reg::FB_FORMAT), (0ull << 32) | (2 << 16) | 8}, Frame{false, index_of(Reg::FB_DISPLAY), end - 16}});
  wait_idle();
  expect_read_equal(index_of(Reg::FRAME_CRC));
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  ASSERT_EQ(rtl_frames_.size(), 1u);
  EXPECT_EQ(rtl_frames_[0].bytes, sim_frames_.at(0).pixels);
}

TEST_P(SocBench, StrictLinkHoldsReleasesAndDiscardsGroups) {
  if (!(rtl_->caps().features & 0x08)) GTEST_SKIP() << "profile without strict link";
  burst({Frame{false, index_of(Reg::LINK_CTRL), 1}});
  host_->restart_crc();
  auto check = [&](std::uint32_t crc) { burst({Frame{false, index_of(Reg::LINK_CHECK), crc}}); };
  // group 1: held until its check matches
  burst({Frame{false, index_of(Reg::CLEAR_COLOR), 0x11223344}, Frame{false, index_of(Reg::FENCE), 5},
         Frame{false, index_of(Reg::TRI_MODE), 0x41}});
  rtl_->idle_ns(5000);
  expect_read_equal(index_of(Reg::CLEAR_COLOR));  // still the reset value on both
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared | (1ull << 20) | 0xFFFF);  // LINK_PENDING, 3 held
  check(host_->take_crc());
  wait_idle();
  for (std::uint8_t i : {0x04, 0x0A, 0x18, 0x15}) expect_read_equal(i);
  // group 2: a MOSI bit error the host does not know about; the check fails, the group is dropped
  const Frame sent{false, index_of(Reg::CLEAR_COLOR), 0x55};
  const Frame received{false, index_of(Reg::CLEAR_COLOR), 0x55 ^ (1ull << 40)};
  sim_->write(received);
  host_->burst(std::vector<Frame>{received});
  host_->restart_crc();  // burst() counted the received frame; the host only knows the sent one
  host_->account(sent);
  check(host_->take_crc());
  // DISCARDING: further queued writes are dropped, checks ignored
  burst({Frame{false, index_of(Reg::CLEAR_COLOR), 0x77}});
  check(host_->take_crc());
  wait_idle();
  for (std::uint8_t i : {0x0A, 0x15}) expect_read_equal(i);
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  // LINK_CTRL restarts; an aborted frame fails its group even with a matching CRC
  burst({Frame{false, index_of(Reg::LINK_CTRL), 1}});
  host_->restart_crc();
  burst({Frame{false, index_of(Reg::CLEAR_COLOR), 0x99}});
  rtl_->set_cs(true);
  for (int i = 0; i < 30; ++i) rtl_->shift_bit(true);
  rtl_->set_cs(false);
  sim_->frame_aborted();
  check(host_->take_crc());
  burst({Frame{false, index_of(Reg::LINK_CTRL), protocol::link_ctrl_clear_value(rtl_->caps().id_register())}});
  wait_idle();
  for (std::uint8_t i : {0x0A, 0x13, 0x15}) expect_read_equal(i);
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
}

// Protocol 1.3: leaving strict mode takes LINK_CTRL.CLEAR_KEY. A queued PRIM frame that a MOSI bit
// error turns into LINK_CTRL (0x03 -> 0x13, TYPE LIST: data 0) is refused on both devices
// (ERR_BAD_VALUE; STRICT, the held writes and the running CRC unchanged), so its group fails the
// check and is discarded instead of executing unchecked; the key then leaves strict mode.
TEST_P(SocBench, LeavingStrictModeTakesTheClearKey) {
  if (!(rtl_->caps().features & 0x08)) GTEST_SKIP() << "profile without strict link";
  burst({Frame{false, index_of(Reg::LINK_CTRL), 1}});
  host_->restart_crc();
  auto check = [&](std::uint32_t crc) { burst({Frame{false, index_of(Reg::LINK_CHECK), crc}}); };
  auto read = [&](Reg r) {  // the gateware's value; the simulator sees the same read frame
    sim_->read(index_of(r));
    return host_->read(r);
  };
  const Frame sent{false, index_of(Reg::PRIM), 0};
  const Frame received{false, index_of(Reg::LINK_CTRL), 0};
  burst({Frame{false, index_of(Reg::CLEAR_COLOR), 0x11223344}});
  burst({received});
  host_->account(sent);  // the host believes it sent the PRIM frame
  burst({Frame{false, index_of(Reg::FENCE), 5}, Frame{false, index_of(Reg::LINK_CTRL), 2},
         Frame{false, index_of(Reg::LINK_CTRL), std::uint64_t{protocol::kLinkClearKey ^ 0x10000u} << 32}});
  rtl_->idle_ns(5000);
  for (std::uint8_t i : {0x0A, 0x13, 0x15, 0x18}) expect_read_equal(i);
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared | (1ull << 20) | 0xFFFF);  // LINK_PENDING, 2 held
  EXPECT_EQ(read(Reg::LINK_CTRL), 1u);
  EXPECT_EQ(read(Reg::STATUS) >> 48 & protocol::ERR_BAD_VALUE, protocol::ERR_BAD_VALUE);
  check(host_->take_crc());  // fails: the device never received the PRIM frame
  wait_idle();
  for (std::uint8_t i : {0x0A, 0x13, 0x15, 0x18}) expect_read_equal(i);
  EXPECT_EQ(read(Reg::CLEAR_COLOR), 0xFFu) << "the group was discarded";
  // with the key: strict mode off, DISCARDING cleared; writes execute at once
  burst({Frame{false, index_of(Reg::LINK_CTRL), protocol::link_ctrl_clear_value(rtl_->caps().id_register())}});
  burst({Frame{false, index_of(Reg::CLEAR_COLOR), 0x55}});
  wait_idle();
  for (std::uint8_t i : {0x0A, 0x13, 0x15}) expect_read_equal(i);
  EXPECT_EQ(read(Reg::LINK_CTRL), 0u);
  EXPECT_EQ(read(Reg::CLEAR_COLOR), 0x55u);
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
}

TEST_P(SocBench, NonStrictChecksCountGroupsAndFlagMismatches) {
  host_->restart_crc();
  burst({Frame{false, index_of(Reg::TEX_BASE), 0x100}, Frame{true, index_of(Reg::ID), 0}});
  burst({Frame{false, index_of(Reg::LINK_CHECK), host_->take_crc()}});
  burst({Frame{false, index_of(Reg::TEX_BASE), 0x200}});
  burst({Frame{false, index_of(Reg::LINK_CHECK), host_->take_crc() ^ 0x80000000u}});
  wait_idle();
  for (std::uint8_t i : {0x05, 0x15}) expect_read_equal(i);
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
}

TEST_P(SocBench, AbortedFrameSetsFramingAndIsDropped) {
  rtl_->set_cs(true);
  for (int i = 0; i < 20; ++i) rtl_->shift_bit(i & 1);
  rtl_->set_cs(false);
  sim_->frame_aborted();
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  expect_read_equal(index_of(Reg::LINK_STATUS));
}

TEST_P(SocBench, ResetRestoresRegistersAndKeepsMemory) {
  burst({Frame{false, index_of(Reg::MEM_ADDR), 0x40}, Frame{false, index_of(Reg::MEM_DATA), 0xAABBCCDD00112233ull},
         Frame{false, index_of(Reg::HOST_TAG), 77}, Frame{false, index_of(Reg::TRI_MODE), 0x1},
         Frame{false, index_of(Reg::FB_FORMAT), (2 << 16) | 2}, Frame{false, index_of(Reg::FB_DISPLAY), 0x40},
         Frame{false, 0x7A, 0}});
  wait_idle();
  write(Reg::RESET, 0x1234);  // wrong magic: BAD_VALUE, no reset
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  expect_read_equal(index_of(Reg::HOST_TAG));
  write(Reg::RESET, protocol::kResetMagic);
  rtl_->idle_ns(3000);
  for (std::uint8_t i : {0x00, 0x04, 0x06, 0x07, 0x0F, 0x12, 0x15, 0x16, 0x70}) expect_read_equal(i);
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  expect_read_equal(index_of(Reg::MEM_DATA));   // prefetch 0, pointer advances
  expect_read_equal(index_of(Reg::MEM_ADDR));
  expect_vram_equal();
}

// RESET empties the FIFO: writes held by strict link mode (not yet released by a LINK_CHECK) are
// discarded on both devices whatever their speed, so this is where RESET meets queued writes
// deterministically (tests/rtl/random_test.cpp drains before its RESETs).
TEST_P(SocBench, ResetDiscardsHeldWrites) {
  if (!(rtl_->caps().features & 0x08)) GTEST_SKIP() << "profile without strict link";
  burst({Frame{false, index_of(Reg::LINK_CTRL), 1}});
  host_->restart_crc();
  burst({Frame{false, index_of(Reg::MEM_ADDR), 0x80}, Frame{false, index_of(Reg::MEM_DATA), 0x0123456789ABCDEFull},
         Frame{false, index_of(Reg::CLEAR_COLOR), 0x11223344}, Frame{false, index_of(Reg::FENCE), 9}});
  rtl_->idle_ns(5000);
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared | (1ull << 20) | 0xFFFF);  // LINK_PENDING, 4 held
  write(Reg::RESET, protocol::kResetMagic);
  rtl_->idle_ns(3000);
  wait_idle();
  for (std::uint8_t i : {0x0A, 0x13, 0x15, 0x18, 0x70}) expect_read_equal(i);
  expect_read_equal(index_of(Reg::STATUS), kStatusCompared);
  EXPECT_EQ(host_->read(Reg::FENCE), 0u);  // the FENCE never executed
  expect_vram_equal();
  const auto m = rtl_->vram();
  EXPECT_EQ(m[0x80] | m[0x81] | m[0x82] | m[0x83], 0);  // nor did the MEM_DATA write
}

INSTANTIATE_TEST_SUITE_P(Profiles, SocBench, ::testing::Values(rtl::GatewareProfile::Up5k, rtl::GatewareProfile::Ecp5),
                         [](const auto& p) { return std::string(rtl::to_string(p.param)); });

}  // namespace
