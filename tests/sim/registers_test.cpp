// Register file behaviour and every error flag of docs/protocol.md sections 5 and 13.
#include <gtest/gtest.h>

#include <algorithm>

#include "gpubridge/protocol/registers.hpp"
#include "sim_test_util.hpp"

namespace gpubridge::sim::test {
namespace {

using namespace protocol;

TEST(SimRegisters, ResetValuesIdAndCaps) {
  DeviceOptions o;
  o.vram_bytes = 2u << 20;
  o.fifo_depth = 100;
  o.variant = 7;
  o.max_width = 320;
  o.max_height = 240;
  auto d = make_device(o);
  EXPECT_EQ(rd(*d, Reg::ID), 0x5350475501040007ull);  // protocol 1.4
  EXPECT_EQ(rd(*d, Reg::CAPS2), 1u);                  // FEATURES2: the depth buffer
  const std::uint64_t caps = rd(*d, Reg::CAPS);
  EXPECT_EQ(caps & 0xFFFFFF, 2048u);                // VRAM_KIB
  EXPECT_EQ((caps >> 24) & 0x7FF, 320u);            // MAX_WIDTH
  EXPECT_EQ((caps >> 35) & 0x7FF, 240u);            // MAX_HEIGHT
  EXPECT_EQ((caps >> 46) & 0x3FF, 100u);            // FIFO_DEPTH
  EXPECT_EQ(caps >> 56, 0xFFu);                     // FEATURES (bit 6: temporal dither, bit 7: texturing)
  for (const auto& r : register_table()) {
    if (r.access != Access::ReadWrite || r.path != Path::Queued) continue;
    EXPECT_EQ(d->read(r.index), r.reset) << r.name;
  }
  EXPECT_EQ(errors_of(*d), 0);
  EXPECT_EQ((rd(*d, Reg::STATUS) >> 17) & 1, 1u);  // VBLANK always for the untimed simulator
}

TEST(SimRegisters, ReservedBitsAreIgnoredAndFlagged) {
  auto d = make_device();
  w(*d, Reg::TRI_MODE, (1ull << 40) | 1);
  EXPECT_EQ(rd(*d, Reg::TRI_MODE), 1u);
  EXPECT_EQ(errors_of(*d), ERR_RESERVED_BITS);
}

TEST(SimRegisters, UndefinedEnumBecomesZero) {
  auto d = make_device();
  w(*d, Reg::PRIM, 3);
  EXPECT_EQ(rd(*d, Reg::PRIM), 0u);
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
  w(*d, Reg::ERR_CLEAR, 0xFFFF);
  w(*d, Reg::TEX_FMT, (3ull << 8) | 0x55);  // WRAP_S = 3 undefined
  EXPECT_EQ(rd(*d, Reg::TEX_FMT), 0x55u);
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
}

TEST(SimRegisters, BadRegisterAccess) {
  auto d = make_device();
  EXPECT_EQ(d->read(0x40), 0u);
  EXPECT_EQ(errors_of(*d), ERR_BAD_REGISTER);
  w(*d, Reg::ERR_CLEAR, ERR_BAD_REGISTER);
  EXPECT_EQ(errors_of(*d), 0);
  w(*d, Reg::STATUS, 0);  // read-only
  EXPECT_EQ(errors_of(*d), ERR_BAD_REGISTER);
  w(*d, Reg::ERR_CLEAR, 0xFFFF);
  d->write(Frame{false, 0x55, 1});  // undefined
  EXPECT_EQ(errors_of(*d), ERR_BAD_REGISTER);
  w(*d, Reg::ERR_CLEAR, 0xFFFF);
  EXPECT_EQ(rd(*d, Reg::CLEAR), 0u);  // write-only reads 0 without an error
  EXPECT_EQ(errors_of(*d), 0);
}

TEST(SimRegisters, RangeRulesReplaceValues) {
  DeviceOptions o;
  o.max_width = 800;
  o.max_height = 600;
  auto d = make_device(o);
  w(*d, Reg::TEX_FMT, 0xB2);  // HEIGHT_LOG2 11 → 10, WIDTH_LOG2 2 → 3
  EXPECT_EQ(rd(*d, Reg::TEX_FMT), 0xA3u);
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
  w(*d, Reg::ERR_CLEAR, 0xFFFF);
  w(*d, Reg::FB_FORMAT, fb_format(0, 1000));
  EXPECT_EQ(rd(*d, Reg::FB_FORMAT), fb_format(1, 600));
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
  w(*d, Reg::ERR_CLEAR, 0xFFFF);
  w(*d, Reg::SCISSOR, scissor(2000, 5, 1025, 1024));
  EXPECT_EQ(rd(*d, Reg::SCISSOR), scissor(1024, 5, 1024, 1024));
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
  w(*d, Reg::ERR_CLEAR, 0xFFFF);
  w(*d, Reg::FB_FORMAT, fb_format(800, 600, 2));
  EXPECT_EQ(errors_of(*d), 0);
}

TEST(SimRegisters, MissingFeatureFallsBack) {
  DeviceOptions o;
  o.features = FEATURE_BILINEAR;  // no RGB565, no blend
  auto d = make_device(o);
  w(*d, Reg::FB_FORMAT, fb_format(64, 64, 1));
  EXPECT_EQ(rd(*d, Reg::FB_FORMAT), fb_format(64, 64, 0));
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
  w(*d, Reg::ERR_CLEAR, 0xFFFF);
  w(*d, Reg::TRI_MODE, 1u << 7);  // BLEND = ALPHA
  EXPECT_EQ(rd(*d, Reg::TRI_MODE), 0u);
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
}

// Section 5 rule 5 for the protocol 1.1 fields: a device without CAPS.FEATURES bit 6 replaces
// TEMPORAL and DITHER_PHASE by 0 (ERR_BAD_VALUE) and keeps the ordered dither; one with it keeps them.
TEST(SimRegisters, TemporalDitherNeedsItsFeatureBit) {
  const std::uint64_t mode = (1u << 9) | (1u << 15) | (std::uint64_t{11} << 16) | 1;  // DITHER, TEMPORAL, phase 11
  DeviceOptions o;
  o.features = kAllFeatures & ~FEATURE_TEMPORAL_DITHER;
  auto d = make_device(o);
  w(*d, Reg::TRI_MODE, mode);
  EXPECT_EQ(rd(*d, Reg::TRI_MODE), (1u << 9) | 1u);
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
  w(*d, Reg::ERR_CLEAR, 0xFFFF);
  w(*d, Reg::TRI_MODE, std::uint64_t{5} << 16);  // a phase alone is refused too
  EXPECT_EQ(rd(*d, Reg::TRI_MODE), 0u);
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);

  auto full = make_device();
  w(*full, Reg::TRI_MODE, mode);
  EXPECT_EQ(rd(*full, Reg::TRI_MODE), mode);
  EXPECT_EQ(errors_of(*full), 0);
  w(*full, Reg::TRI_MODE, std::uint64_t{1} << 20);  // bit 20 stays reserved
  EXPECT_EQ(errors_of(*full), ERR_RESERVED_BITS);
}

TEST(SimRegisters, TexturingNeedsItsFeatureBit) {
  // CAPS.FEATURES bit 7 (protocol 1.2): without it TRI_MODE.TEXTURED is refused and the triangle is
  // drawn with its vertex colours, exactly as an untextured draw.
  DeviceOptions with, without;
  without.features = kAllFeatures & ~FEATURE_TEXTURE;
  auto plain = make_device(with);
  auto d = make_device(without);
  EXPECT_EQ(rd(*d, Reg::CAPS) >> 63, 0u);
  EXPECT_EQ(rd(*plain, Reg::CAPS) >> 63, 1u);
  w(*d, Reg::TRI_MODE, 0x3);  // GOURAUD | TEXTURED
  EXPECT_EQ(rd(*d, Reg::TRI_MODE), 0x1u);
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
  w(*d, Reg::ERR_CLEAR, 0xFFFF);
  w(*plain, Reg::TRI_MODE, 0x1);
  for (auto* dev : {d.get(), plain.get()}) {
    w(*dev, Reg::FB_FORMAT, fb_format(16, 16, 0));
    w(*dev, Reg::SCISSOR, scissor(0, 0, 16, 16));
    w(*dev, Reg::TEX_FMT, 0x33);
    const std::uint32_t colours[3] = {0xFF0000FFu, 0x00FF00FFu, 0x0000FFFFu};
    const std::uint64_t xy[3] = {0x00000000u, 0x000000F0u, 0x00F00000u};
    for (int i = 0; i < 3; ++i) {
      w(*dev, Reg::COLOR, (std::uint64_t{0x80000000u} << 32) | colours[i]);
      w(*dev, Reg::TEXCOORD, 0x0100000001000000ull);
      w(*dev, Reg::VERTEX, xy[i]);
    }
  }
  EXPECT_EQ(errors_of(*d), 0);
  const auto a = d->memory(), b = plain->memory();
  EXPECT_TRUE(std::equal(a.begin(), a.begin() + 16 * 16 * 4, b.begin()));
  EXPECT_NE(a[4 * 17], 0);  // the triangle was drawn
}

TEST(SimRegisters, DepthNeedsCaps2Bit0) {
  // CAPS2.FEATURES2 bit 0 (protocol 1.4): without it TRI_MODE.Z_TEST and Z_WRITE are replaced by 0
  // with ERR_BAD_VALUE (Z_FUNC stays), and CLEAR_Z is refused when it executes, clearing nothing.
  DeviceOptions with, without;
  without.features2 = 0;
  auto plain = make_device(with);
  auto d = make_device(without);
  EXPECT_EQ(rd(*d, Reg::CAPS2), 0u);
  EXPECT_EQ(rd(*plain, Reg::CAPS2), 1u);
  EXPECT_EQ(errors_of(*d), 0);  // CAPS2 is defined: reading it is no error
  const std::uint64_t z_mode = (1u << 6) | (1u << 3) | (1u << 2) | 1u;  // Z_WRITE | LESS | Z_TEST | GOURAUD
  w(*d, Reg::TRI_MODE, z_mode);
  EXPECT_EQ(rd(*d, Reg::TRI_MODE), (1u << 3) | 1u);
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
  w(*d, Reg::ERR_CLEAR, 0xFFFF);
  w(*d, Reg::TRI_MODE, 1u << 6);  // Z_WRITE alone is refused too
  EXPECT_EQ(rd(*d, Reg::TRI_MODE), 0u);
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
  w(*d, Reg::ERR_CLEAR, 0xFFFF);
  w(*plain, Reg::TRI_MODE, z_mode);
  EXPECT_EQ(rd(*plain, Reg::TRI_MODE), z_mode);
  EXPECT_EQ(errors_of(*plain), 0);
  // CLEAR_Z over a 16 x 16 depth buffer at 0x1000 holding 0xAB bytes
  for (auto* dev : {d.get(), plain.get()}) {
    w(*dev, Reg::MEM_ADDR, 0x1000);
    for (int i = 0; i < 16 * 16 * 4 / 8; ++i) w(*dev, Reg::MEM_DATA, 0xABABABABABABABABull);
    w(*dev, Reg::FB_FORMAT, fb_format(16, 16, 0));
    w(*dev, Reg::SCISSOR, scissor(0, 0, 16, 16));
    w(*dev, Reg::FB_Z, 0x1000);
    w(*dev, Reg::CLEAR_DEPTH, 0x123456);
    w(*dev, Reg::CLEAR_Z, 0);
  }
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
  EXPECT_EQ(errors_of(*plain), 0);
  const auto a = d->memory(), b = plain->memory();
  EXPECT_TRUE(std::all_of(a.begin() + 0x1000, a.begin() + 0x1000 + 16 * 16 * 4, [](std::uint8_t v) { return v == 0xAB; }));
  EXPECT_EQ(b[0x1000 + 1], 0x12);  // the depth-capable device cleared (24-bit depth in 4 bytes, big-endian)
  EXPECT_EQ(b[0x1000 + 3], 0x56);
  // FB_Z and CLEAR_DEPTH stay plain state registers on both
  EXPECT_EQ(rd(*d, Reg::FB_Z), 0x1000u);
  EXPECT_EQ(rd(*d, Reg::CLEAR_DEPTH), 0x123456u);
}

TEST(SimRegisters, ResetNeedsMagicAndKeepsMemory) {
  auto d = make_device();
  w(*d, Reg::HOST_TAG, 0x1234);
  w(*d, Reg::TRI_MODE, 0x41);
  w(*d, Reg::MEM_ADDR, 0x40);
  w(*d, Reg::MEM_DATA, 0x0102030405060708ull);
  w(*d, Reg::RESET, 0x5245534555);  // wrong magic
  EXPECT_EQ(rd(*d, Reg::HOST_TAG), 0x1234u);
  EXPECT_EQ(errors_of(*d), ERR_BAD_VALUE);
  w(*d, Reg::RESET, kResetMagic);
  EXPECT_EQ(rd(*d, Reg::HOST_TAG), 0u);
  EXPECT_EQ(rd(*d, Reg::TRI_MODE), 0u);
  EXPECT_EQ(errors_of(*d), 0);
  EXPECT_EQ(d->memory()[0x40], 1);
  EXPECT_EQ(d->memory()[0x47], 8);
}

TEST(SimRegisters, FenceAndHostTag) {
  auto d = make_device();
  w(*d, Reg::FENCE, 0xDEADBEEFCAFEull);
  EXPECT_EQ(rd(*d, Reg::FENCE), 0xDEADBEEFCAFEull);
  w(*d, Reg::HOST_TAG, ~0ull);
  EXPECT_EQ(rd(*d, Reg::HOST_TAG), ~0ull);
}

TEST(SimRegisters, MemoryWriteAndPrefetchedReads) {
  auto d = make_device();
  w(*d, Reg::MEM_ADDR, 0x100);
  w(*d, Reg::MEM_DATA, 0x1111111111111111ull);
  w(*d, Reg::MEM_DATA, 0x2222222222222222ull);
  EXPECT_EQ(rd(*d, Reg::MEM_ADDR), 0x110u);
  EXPECT_EQ(d->memory()[0x100], 0x11);
  EXPECT_EQ(d->memory()[0x108], 0x22);
  w(*d, Reg::MEM_ADDR, 0x100);
  EXPECT_EQ((rd(*d, Reg::STATUS) >> 18) & 1, 1u);  // MEM_READY
  EXPECT_NE(d->miso_status() & MISO_MEM_READY, 0);
  EXPECT_EQ(rd(*d, Reg::MEM_DATA), 0x1111111111111111ull);
  EXPECT_EQ(rd(*d, Reg::MEM_DATA), 0x2222222222222222ull);
  EXPECT_EQ(rd(*d, Reg::MEM_DATA), 0u);
  EXPECT_EQ(rd(*d, Reg::MEM_ADDR), 0x118u);
  EXPECT_EQ(errors_of(*d), 0);
}

TEST(SimRegisters, MemoryBeyondVramReadsZeroAndFlags) {
  DeviceOptions o;
  o.vram_bytes = 64 << 10;
  auto d = make_device(o);
  w(*d, Reg::MEM_ADDR, (64 << 10) - 8);
  w(*d, Reg::MEM_DATA, 0xFFFFFFFFFFFFFFFFull);
  EXPECT_EQ(errors_of(*d), 0);  // the last word of memory is a legal write
  w(*d, Reg::MEM_DATA, 5);      // entirely beyond: dropped
  EXPECT_EQ(errors_of(*d), ERR_MEM_RANGE);
  w(*d, Reg::ERR_CLEAR, 0xFFFF);
  w(*d, Reg::MEM_ADDR, (64 << 10) - 8);
  EXPECT_EQ(rd(*d, Reg::MEM_DATA), ~0ull);
  EXPECT_EQ(errors_of(*d), 0);
  EXPECT_EQ(rd(*d, Reg::MEM_DATA), 0u);
  EXPECT_EQ(errors_of(*d), ERR_MEM_RANGE);
}

TEST(SimRegisters, MisoStatusByte) {
  auto d = make_device();
  std::uint8_t s = d->miso_status();
  EXPECT_TRUE(miso_status_valid(s));
  EXPECT_EQ(s & MISO_ERROR, 0);
  d->read(0x44);
  s = d->miso_status();
  EXPECT_NE(s & MISO_ERROR, 0);
  EXPECT_NE(s & MISO_VBLANK, 0);
}

TEST(SimRegisters, FramingErrorIsSticky) {
  auto d = make_device();
  d->frame_aborted();
  EXPECT_EQ(errors_of(*d), ERR_FRAMING);
  EXPECT_EQ(errors_of(*d), ERR_FRAMING);
  w(*d, Reg::ERR_CLEAR, ERR_LINK_CRC);  // clears only the named flags
  EXPECT_EQ(errors_of(*d), ERR_FRAMING);
  w(*d, Reg::ERR_CLEAR, ERR_FRAMING);
  EXPECT_EQ(errors_of(*d), 0);
}

TEST(SimRegisters, OptionsAreValidated) {
  DeviceOptions o;
  o.fifo_depth = 10;
  EXPECT_FALSE(Device::create(o).ok());
  o = {};
  o.vram_bytes = 1000;
  EXPECT_FALSE(Device::create(o).ok());
  o = {};
  o.threads = 0;
  EXPECT_FALSE(Device::create(o).ok());
  o = {};
  o.features2 = 0x02;  // CAPS2.FEATURES2 bits 1..7 are reserved
  EXPECT_FALSE(Device::create(o).ok());
  o.features2 = 0;
  EXPECT_TRUE(Device::create(o).ok());
}

TEST(SimKnobs, ParseAndErrors) {
  AccuracyKnobs k;
  EXPECT_TRUE(apply_knob(k, "recip_bits=8").ok());
  EXPECT_EQ(k.recip_bits, 8u);
  EXPECT_FALSE(k.exact());
  EXPECT_EQ(accuracy_mode(k), "knobs");
  EXPECT_TRUE(apply_knob(k, "exact").ok());  // back to the hardware values
  EXPECT_TRUE(k.exact());
  EXPECT_EQ(accuracy_mode(k), "exact");
  EXPECT_TRUE(apply_knob(k, "preview").ok());
  EXPECT_TRUE(apply_knob(k, "z_bits=16").ok());
  EXPECT_TRUE(k.preview);
  EXPECT_FALSE(k.exact());
  EXPECT_EQ(to_string(k), "preview z_bits=16");
  EXPECT_EQ(accuracy_mode(k), "preview");
  DeviceOptions o;
  o.accuracy = k;
  EXPECT_TRUE(o.validate().ok());
  o.accuracy.recip_bits = 8;  // preview has no reciprocal table
  auto no_table = o.validate();
  ASSERT_FALSE(no_table.ok());
  EXPECT_NE(no_table.error().message.find("no reciprocal table"), std::string::npos);
  // The retired knob `fast` (slower than exact mode) points to preview.
  auto retired = apply_knob(k, "fast=1");
  ASSERT_FALSE(retired.ok());
  EXPECT_NE(retired.error().message.find("--accuracy preview"), std::string::npos);
  auto bad = apply_knob(k, "recip_bits=40");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("1..16"), std::string::npos);
  EXPECT_FALSE(apply_knob(k, "nosuch=1").ok());
  EXPECT_FALSE(apply_knob(k, "z_bits").ok());
  EXPECT_FALSE(apply_knob(k, "z_bits=abc").ok());
  EXPECT_TRUE(AccuracyKnobs{}.exact());
}

}  // namespace
}  // namespace gpubridge::sim::test
