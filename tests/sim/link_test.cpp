// Link integrity (docs/protocol.md section 4) and flow control (section 3), checked against
// zlib's crc32 computed the way a host does.
#include <gtest/gtest.h>
#include <zlib.h>

#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

using namespace protocol;

// The host side of the link: sends frames and keeps the CRC of everything since the last check.
struct Host {
  Device& d;
  uLong crc = crc32(0L, Z_NULL, 0);
  unsigned frames = 0;
  void track(const Frame& f) {
    if (f.index == index_of(Reg::LINK_CHECK) || f.index == index_of(Reg::LINK_CTRL)) return;
    const auto b = encode(f);
    crc = crc32(crc, b.data(), static_cast<uInt>(b.size()));
    ++frames;
  }
  void send(Reg r, std::uint64_t data) {
    const Frame f = write_frame(r, data);
    track(f);
    d.write(f);
  }
  std::uint64_t read(Reg r) {
    track(read_frame(r));
    return d.read(index_of(r));
  }
  void check(std::uint32_t value) {
    d.write(write_frame(Reg::LINK_CHECK, value));
    restart();
  }
  void check() { check(static_cast<std::uint32_t>(crc)); }
  void restart() {
    crc = crc32(0L, Z_NULL, 0);
    frames = 0;
  }
  void ctrl(bool strict) {
    d.write(write_frame(Reg::LINK_CTRL, strict ? 1 : 0));
    restart();
  }
};

std::uint16_t ok_groups(Device& d) { return static_cast<std::uint16_t>(d.read_register(index_of(Reg::LINK_STATUS)) >> 32); }
std::uint16_t bad_groups(Device& d) { return static_cast<std::uint16_t>(d.read_register(index_of(Reg::LINK_STATUS)) >> 48); }
bool discarding(Device& d) { return (d.read_register(index_of(Reg::LINK_STATUS)) >> 24) & 1; }

TEST(SimLink, CrcMatchesZlibOverReadsAndWrites) {
  auto d = make_device();
  Host h{*d};
  h.ctrl(false);
  h.send(Reg::TRI_MODE, 3);
  h.send(Reg::HOST_TAG, 99);
  h.read(Reg::STATUS);
  h.send(Reg::VERTEX, vtx(5, 5));
  EXPECT_EQ(d->read_register(index_of(Reg::LINK_STATUS)) & 0xFFFFFF, h.frames);  // FRAMES
  h.check();
  EXPECT_EQ(ok_groups(*d), 1);
  EXPECT_EQ(bad_groups(*d), 0);
  EXPECT_EQ(d->errors(), 0);
  EXPECT_EQ(d->read_register(index_of(Reg::LINK_STATUS)) & 0xFFFFFF, 0u);
  h.send(Reg::TRI_MODE, 1);
  h.check(static_cast<std::uint32_t>(h.crc) ^ 1);
  EXPECT_EQ(bad_groups(*d), 1);
  EXPECT_EQ(d->errors(), ERR_LINK_CRC);
  EXPECT_EQ(d->read_register(index_of(Reg::TRI_MODE)), 1u);  // non-strict: the write executed
}

TEST(SimLink, StrictModeHoldsUntilMatchingCheck) {
  auto d = make_device();
  Host h{*d};
  h.ctrl(true);
  h.send(Reg::TRI_MODE, 5);
  h.send(Reg::HOST_TAG, 7);  // immediate: acts at once even in strict mode
  EXPECT_EQ(d->read_register(index_of(Reg::TRI_MODE)), 0u);
  EXPECT_EQ(d->read_register(index_of(Reg::HOST_TAG)), 7u);
  const std::uint64_t status = d->read_register(index_of(Reg::STATUS));
  EXPECT_EQ(status & 0xFFFF, 1u);        // FIFO_LEVEL
  EXPECT_EQ((status >> 20) & 1, 1u);     // LINK_PENDING
  EXPECT_EQ((status >> 16) & 1, 1u);     // BUSY
  // Direct read_register calls are not link frames; the host's CRC stays in step.
  h.check();
  EXPECT_EQ(ok_groups(*d), 1);
  EXPECT_EQ(d->read_register(index_of(Reg::TRI_MODE)), 5u);
  EXPECT_EQ(d->read_register(index_of(Reg::STATUS)) & 0xFFFF, 0u);
}

TEST(SimLink, FailedCheckDiscardsUntilLinkCtrl) {
  auto d = make_device();
  Host h{*d};
  h.ctrl(true);
  h.send(Reg::TRI_MODE, 5);
  h.check(0x12345678);
  EXPECT_TRUE(discarding(*d));
  EXPECT_EQ(bad_groups(*d), 1);
  EXPECT_EQ(d->errors() & ERR_LINK_CRC, ERR_LINK_CRC);
  EXPECT_EQ(d->read_register(index_of(Reg::TRI_MODE)), 0u);  // the held write was discarded
  h.send(Reg::TRI_MODE, 6);
  h.check();  // ignored while discarding, even though it matches
  EXPECT_EQ(ok_groups(*d), 0);
  EXPECT_EQ(bad_groups(*d), 1);
  EXPECT_EQ(d->read_register(index_of(Reg::TRI_MODE)), 0u);
  h.ctrl(true);
  EXPECT_FALSE(discarding(*d));
  h.send(Reg::TRI_MODE, 6);
  h.check();
  EXPECT_EQ(ok_groups(*d), 1);
  EXPECT_EQ(d->read_register(index_of(Reg::TRI_MODE)), 6u);
}

// Protocol 1.3: leaving strict mode takes LINK_CTRL.CLEAR_KEY. Without it the write is refused
// whole (ERR_BAD_VALUE; STRICT, the held writes and the running CRC stay), so a queued frame that a
// bit error turns into LINK_CTRL (PRIM 0x03 -> 0x13 with TYPE LIST or FAN) cannot switch the
// protection off: the group it was in still fails its check.
TEST(SimLink, LeavingStrictModeTakesTheClearKey) {
  auto d = make_device();
  Host h{*d};
  h.ctrl(true);
  h.send(Reg::TRI_MODE, 5);
  d->write(write_frame(Reg::LINK_CTRL, 0));  // PRIM LIST garbled into LINK_CTRL: the host never sent it
  EXPECT_EQ(d->errors(), ERR_BAD_VALUE);
  EXPECT_EQ(d->read_register(index_of(Reg::LINK_CTRL)), 1u);
  EXPECT_EQ(d->read_register(index_of(Reg::STATUS)) & 0xFFFF, 1u) << "the held write was discarded";
  EXPECT_EQ(d->read_register(index_of(Reg::LINK_STATUS)) & 0xFFFFFF, h.frames) << "the CRC restarted";
  d->write(write_frame(Reg::LINK_CTRL, 2));  // PRIM FAN: reserved bit 1 flagged, refused all the same
  EXPECT_EQ(d->errors(), ERR_BAD_VALUE | ERR_RESERVED_BITS);
  d->write(write_frame(Reg::LINK_CTRL, std::uint64_t{kLinkClearKey ^ 0x100} << 32));  // one bit off the key
  EXPECT_EQ(d->read_register(index_of(Reg::LINK_CTRL)), 1u);
  h.check();  // the group is intact: released
  EXPECT_EQ(ok_groups(*d), 1);
  EXPECT_EQ(d->read_register(index_of(Reg::TRI_MODE)), 5u);

  d->write(write_frame(Reg::ERR_CLEAR, kAllErrors));
  h.send(Reg::TRI_MODE, 6);
  d->write(write_frame(Reg::LINK_CTRL, link_ctrl_clear_value(d->read_register(index_of(Reg::ID)))));
  h.restart();
  EXPECT_EQ(d->errors(), 0);
  EXPECT_EQ(d->read_register(index_of(Reg::LINK_CTRL)), 0u) << "CLEAR_KEY is write-only";
  EXPECT_EQ(d->read_register(index_of(Reg::TRI_MODE)), 5u) << "the unchecked write was discarded";
  h.send(Reg::TRI_MODE, 7);
  EXPECT_EQ(d->read_register(index_of(Reg::TRI_MODE)), 7u) << "strict mode is off";
  // Outside strict mode there is nothing to leave: a plain 0 acts (restarts the CRC), unflagged.
  d->write(write_frame(Reg::LINK_CTRL, 0));
  EXPECT_EQ(d->errors(), 0);
  EXPECT_EQ(d->read_register(index_of(Reg::LINK_STATUS)) & 0xFFFFFF, 0u);
  // Enabling stays a plain write, and the key with STRICT = 1 is simply not stored.
  d->write(write_frame(Reg::LINK_CTRL, (std::uint64_t{kLinkClearKey} << 32) | 1));
  EXPECT_EQ(d->errors(), 0);
  EXPECT_EQ(d->read_register(index_of(Reg::LINK_CTRL)), 1u);
}

TEST(SimLink, AbortedFrameFailsTheGroup) {
  auto d = make_device();
  Host h{*d};
  h.ctrl(true);
  h.send(Reg::TRI_MODE, 5);
  d->frame_aborted();
  h.check();  // CRC matches the complete frames, but the group lost a frame
  EXPECT_EQ(ok_groups(*d), 0);
  EXPECT_EQ(bad_groups(*d), 1);
  EXPECT_EQ(d->errors() & (ERR_FRAMING | ERR_LINK_CRC), ERR_FRAMING | ERR_LINK_CRC);
}

TEST(SimLink, OverflowDropsWritesAndFailsTheGroup) {
  DeviceOptions o;
  o.fifo_depth = 64;
  auto d = make_device(o);
  Host h{*d};
  h.ctrl(true);
  for (int i = 0; i < 64; ++i) h.send(Reg::FENCE, static_cast<std::uint64_t>(i));
  EXPECT_TRUE(d->busy_pin());
  EXPECT_EQ(d->errors(), 0);
  h.send(Reg::FENCE, 1000);  // the 65th
  EXPECT_EQ(d->errors(), ERR_OVERFLOW);
  h.check();
  EXPECT_EQ(bad_groups(*d), 1);
  EXPECT_EQ(d->read_register(index_of(Reg::FENCE)), 0u);
}

TEST(SimLink, SlowDeviceFillsFifoAndRaisesBusy) {
  DeviceOptions o;
  o.fifo_depth = 64;
  o.fifo_drain_per_frame = 1;
  o.fifo_drain_interval = 4;  // one entry per four frames: four times slower than the link
  auto d = make_device(o);
  unsigned sent = 0;
  while (!d->busy_pin() && sent < 1000) {
    d->write(write_frame(Reg::FENCE, ++sent));
  }
  ASSERT_TRUE(d->busy_pin());
  EXPECT_NE(d->miso_status() & MISO_FIFO_NEARLY_FULL, 0);
  const std::uint64_t level = d->read_register(index_of(Reg::STATUS)) & 0xFFFF;
  EXPECT_GT(level, 64u - 32u);
  EXPECT_LT(d->read_register(index_of(Reg::FENCE)), sent);  // not all executed yet
  EXPECT_EQ(d->step(3), 3u);
  d->drain();
  EXPECT_FALSE(d->busy_pin());
  EXPECT_EQ(d->read_register(index_of(Reg::FENCE)), sent);  // in order, none lost
  EXPECT_EQ(d->errors(), 0);
}

}  // namespace
}  // namespace gpubridge::sim::test
