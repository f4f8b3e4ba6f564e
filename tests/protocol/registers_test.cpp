// The register table through every path that uses it: frame encode/decode, text form,
// check_write's reserved-bit and enum rules, and the CRC check value.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <string>

#include "gpubridge/protocol/crc32.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "gpubridge/protocol/text_trace.hpp"

namespace gpubridge::protocol {
namespace {

// Representative raw values of a field: 0, 1, the all-ones value, the top bit alone, and a
// mixed pattern, restricted to defined values for enums.
std::vector<std::uint64_t> sample_values(const Field& f) {
  std::vector<std::uint64_t> out;
  if (f.kind == FieldKind::Enum) {
    for (const auto& v : f.values) out.push_back(v.value);
    return out;
  }
  const std::uint64_t all = f.width >= 64 ? ~0ull : (1ull << f.width) - 1;
  out = {0, 1, all, 1ull << (f.width - 1), 0xA5A5'A5A5'A5A5'A5A5ull & all};
  return out;
}

TEST(Registers, EveryFieldRoundTripsThroughFramesAndText) {
  std::size_t checked = 0;
  for (const auto& r : register_table()) {
    for (const auto& f : r.fields) {
      if (f.width == 0) continue;
      for (std::uint64_t v : sample_values(f)) {
        SCOPED_TRACE(std::string(r.name) + "." + std::string(f.name) + " = " + std::to_string(v));
        const std::uint64_t data = f.put(0, v);
        ASSERT_EQ(f.get(data), v);
        // Frame: 9 bytes, R/W̄ and index in byte 0, data big-endian.
        const Frame fr{false, r.index, data};
        const auto bytes = encode(fr);
        EXPECT_EQ(bytes[0], r.index);
        EXPECT_EQ(bytes[8], static_cast<std::uint8_t>(data));
        EXPECT_EQ(bytes[1], static_cast<std::uint8_t>(data >> 56));
        EXPECT_EQ(decode(bytes), fr);
        // Text: the canonical line parses back to the same frame.
        const std::string line = format_register_write(r.index, data);
        auto parsed = parse_register_line(line);
        ASSERT_TRUE(parsed.ok()) << line << ": " << parsed.error().message;
        EXPECT_EQ(*parsed, fr) << line;
        if (r.access != Access::ReadOnly) {
          EXPECT_EQ(line.rfind(std::string(r.name), 0), 0u) << "writable registers print by name: " << line;
          if (v != 0) {
            EXPECT_NE(line.find(std::string(f.name) + "="), std::string::npos) << line;
          }
        }
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 200u);
}

TEST(Registers, ReadFramesRoundTrip) {
  for (const auto& r : register_table()) {
    const Frame fr{true, r.index, 0};
    const auto b = encode(fr);
    EXPECT_EQ(b[0], 0x80 | r.index);
    EXPECT_EQ(decode(b), fr);
  }
}

// The 8-frames-at-a-time scan must find the first read frame wherever it sits: in a whole block, in
// the tail, with other reads after it, and in batches with no read at all. Data bytes with bit 7 set
// (every data byte is 0xFF here) must never count.
TEST(Registers, FirstReadFrameFindsTheFirstReadBitAtEveryPosition) {
  for (std::size_t n = 0; n <= 40; ++n) {
    std::vector<std::uint8_t> bytes;
    for (std::size_t i = 0; i < n; ++i) append(bytes, Frame{false, 0x02, ~std::uint64_t{0}});
    EXPECT_EQ(first_read_frame(FrameView{bytes}), n) << "no read frame in " << n;
    for (std::size_t at = 0; at < n; ++at) {
      auto with_read = bytes;
      with_read[at * kFrameBytes] |= 0x80;
      if (at + 3 < n) with_read[(at + 3) * kFrameBytes] |= 0x80;  // a later read does not hide the first
      EXPECT_EQ(first_read_frame(FrameView{with_read}), at) << "batch of " << n << ", read at " << at;
    }
  }
}

TEST(Registers, FixedPointFieldsInText) {
  auto v = parse_register_line("VERTEX X=-2048 Y=2047.9375 Z=16777215");
  ASSERT_TRUE(v.ok()) << v.error().message;
  const auto& d = describe(Reg::VERTEX);
  EXPECT_EQ(d.field("X")->get_signed(v->data), -2048 * 16);
  EXPECT_EQ(d.field("Y")->get_signed(v->data), 2047 * 16 + 15);
  EXPECT_EQ(d.field("Z")->get(v->data), 0xFFFFFFu);
  auto q = parse_register_line("COLOR Q=0.5 R=1");
  ASSERT_TRUE(q.ok());
  EXPECT_EQ(q->data, (0x8000'0000ull << 32) | (1ull << 24));
  auto s = parse_register_line("texcoord s=-0.5 t=0x00000001");  // names are case-insensitive
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(s->data, (std::uint64_t{0xFF80'0000u} << 32) | 1u);
}

TEST(Registers, FormatFixedIsExact) {
  EXPECT_EQ(format_fixed(-56, 4), "-3.5");
  EXPECT_EQ(format_fixed(1, 4), "0.0625");
  EXPECT_EQ(format_fixed(1, 32), "0.00000000023283064365386962890625");
  EXPECT_EQ(format_fixed(32, 4), "2");
}

TEST(Registers, CheckWriteClearsReservedBits) {
  const auto w = check_write(index_of(Reg::VERTEX), 0xFF00'0000'0000'0000ull | 0x10);
  EXPECT_EQ(w.data, 0x10u);
  EXPECT_EQ(w.errors, ERR_RESERVED_BITS);
  EXPECT_NE(w.problem.find("reserved"), std::string::npos);
  const auto clean = check_write(index_of(Reg::VERTEX), 0x00FF'FFFF'FFFF'FFFFull);
  EXPECT_EQ(clean.errors, 0);
  EXPECT_EQ(clean.data, 0x00FF'FFFF'FFFF'FFFFull);
  // TEX_BASE bits [3:0] are reserved (16-byte alignment).
  EXPECT_EQ(check_write(index_of(Reg::TEX_BASE), 0x1008).errors, ERR_RESERVED_BITS);
  EXPECT_EQ(check_write(index_of(Reg::TEX_BASE), 0x1008).data, 0x1000u);
}

TEST(Registers, CheckWriteReplacesUndefinedEnumsWithZero) {
  const auto* type = describe(Reg::PRIM).field("TYPE");
  const auto w = check_write(index_of(Reg::PRIM), type->put(0, 3));
  EXPECT_EQ(w.errors, ERR_BAD_VALUE);
  EXPECT_EQ(type->get(w.data), 0u);
  const auto* fmt = describe(Reg::TEX_FMT).field("FORMAT");
  const auto t = check_write(index_of(Reg::TEX_FMT), fmt->put(0x33, 3));
  EXPECT_EQ(t.errors, ERR_BAD_VALUE);
  EXPECT_EQ(t.data, 0x33u);  // other fields untouched
  const auto* wrap = describe(Reg::TEX_FMT).field("WRAP_S");
  EXPECT_EQ(check_write(index_of(Reg::TEX_FMT), wrap->put(0, 3)).errors, ERR_BAD_VALUE);
  EXPECT_EQ(check_write(index_of(Reg::TEX_FMT), wrap->put(0, 2)).errors, 0);
}

TEST(Registers, CheckWriteRejectsUnknownAndReadOnly) {
  EXPECT_EQ(check_write(0x42, 0).errors, ERR_BAD_REGISTER);
  EXPECT_EQ(check_write(index_of(Reg::STATUS), 0).errors, ERR_BAD_REGISTER);
  EXPECT_EQ(check_write(index_of(Reg::ID), 1).errors, ERR_BAD_REGISTER);
}

TEST(Registers, NamesAreCaseInsensitiveAndUnique) {
  for (const auto& r : register_table()) {
    std::string lower(r.name);
    for (auto& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    ASSERT_NE(find_register(lower), nullptr) << lower;
    EXPECT_EQ(find_register(lower)->index, r.index);
    EXPECT_EQ(find_register(r.index), &r);
  }
}

// The fewest bit flips that turn a frame of register `r` (a write of any value the table allows,
// or a read: data 0, HOST_TAG reads carry the host's tag) into a LINK_CTRL write that leaves strict
// mode: STRICT = 0 and CLEAR_KEY = the key. Only the frame bits the device compares count (R/W̄, the
// index, bits [63:32] and bit 0); fields are taken at their full width (ranges ignored), so this is
// a lower bound. docs/protocol.md section 4 tabulates the same numbers.
unsigned flips_to_clear(const RegisterDesc& r, bool read) {
  constexpr std::uint64_t kClear = std::uint64_t{kLinkClearKey} << 32;
  constexpr std::uint64_t kCompared = 0xFFFF'FFFF'0000'0001ull;
  unsigned flips = static_cast<unsigned>(std::popcount(unsigned{r.index} ^ index_of(Reg::LINK_CTRL))) + (read ? 1 : 0);
  if (read) return flips + (r.index == index_of(Reg::HOST_TAG) ? 0 : static_cast<unsigned>(std::popcount(kClear)));
  // A host enables strict mode with CLEAR_KEY = 0 (section 4): STRICT is its only value.
  if (r.index == index_of(Reg::LINK_CTRL)) return static_cast<unsigned>(std::popcount(kClear ^ 1));
  std::uint64_t pinned = kCompared;  // compared bits a legal value cannot choose freely
  unsigned data = 0;
  for (const auto& f : r.fields) {
    if (!(f.mask() & kCompared)) continue;
    if (f.kind != FieldKind::Enum) {
      pinned &= ~f.mask();
      continue;
    }
    unsigned best = 64;
    for (const auto& v : f.values)
      best = std::min(best, static_cast<unsigned>(std::popcount((f.put(0, v.value) ^ kClear) & f.mask() & kCompared)));
    data += best;
    pinned &= ~f.mask();
  }
  return flips + data + static_cast<unsigned>(std::popcount(kClear & pinned));
}

// Protocol 1.3: the key is chosen so that no frame a host sends becomes a strict-mode clear by one
// or two bit errors, except through two index flips in a frame whose upper data word is a free
// host value (TEXCOORD.S, HOST_TAG), which would also have to equal the key exactly.
TEST(Registers, NoFrameTurnsIntoAStrictModeClearByOneOrTwoBitErrors) {
  unsigned free_two = 0;
  for (const auto& r : register_table()) {
    for (const bool read : {false, true}) {
      if (read ? r.access == Access::WriteOnly : r.access == Access::ReadOnly) continue;
      const unsigned n = flips_to_clear(r, read);
      SCOPED_TRACE(std::string(r.name) + (read ? " read" : " write") + ": " + std::to_string(n) + " flips");
      EXPECT_GE(n, 2u);
      if (n == 2) {
        EXPECT_TRUE(!read && (r.index == index_of(Reg::TEXCOORD) || r.index == index_of(Reg::HOST_TAG)));
        ++free_two;
      }
    }
  }
  EXPECT_EQ(free_two, 2u);
  // PRIM, the frame that found the hole (0x03 -> 0x13 is one flip): the key's 16 one bits on top.
  EXPECT_EQ(flips_to_clear(describe(Reg::PRIM), false), 17u);
  EXPECT_EQ(flips_to_clear(describe(Reg::RESET), false), 15u);  // 0x17 -> 0x13, MAGIC's [39:32] free
  EXPECT_EQ(flips_to_clear(describe(Reg::VERTEX), false), 8u);  // Z covers [55:32]; [63:56] is reserved
  EXPECT_EQ(flips_to_clear(describe(Reg::SCISSOR), false), 7u);
}

TEST(Registers, LinkCtrlClearValueFollowsTheDevicesMinorVersion) {
  const std::uint64_t v12 = (std::uint64_t{kIdMagic} << 32) | (1ull << 24) | (2ull << 16) | 7;
  EXPECT_EQ(link_ctrl_clear_value(v12), 0u) << "a 1.2 device has no CLEAR_KEY: its bits are reserved";
  EXPECT_EQ(link_ctrl_clear_value(describe(Reg::ID).reset), 0x6F666621'00000000ull);
  EXPECT_EQ(check_write(index_of(Reg::LINK_CTRL), link_ctrl_clear_value(describe(Reg::ID).reset)).errors, 0);
  EXPECT_EQ(protocol_minor(describe(Reg::ID).reset), kVersionMinor);
}

TEST(Registers, Caps2AdvertisesTheDepthBufferFromVersion14) {
  // 0x7D, next to CAPS: read-only, immediate, FEATURES2 in [7:0] (bit 0 depth buffer), the rest reserved
  const RegisterDesc* r = find_register(0x7D);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r, find_register("caps2"));
  EXPECT_EQ(r->name, "CAPS2");
  EXPECT_EQ(index_of(Reg::CAPS2), 0x7D);
  EXPECT_EQ(r->access, Access::ReadOnly);
  EXPECT_EQ(r->path, Path::Immediate);
  const Field* f = r->field("FEATURES2");
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->lsb, 0);
  EXPECT_EQ(f->width, 8);
  EXPECT_EQ(r->reserved_mask(), ~0xFFull);
  EXPECT_EQ(check_write(0x7D, 1).errors, ERR_BAD_REGISTER);  // read-only
  EXPECT_EQ(kVersionMinor, 4);
  const std::uint64_t id13 = (std::uint64_t{kIdMagic} << 32) | (1ull << 24) | (3ull << 16);
  const std::uint64_t id14 = describe(Reg::ID).reset;
  EXPECT_EQ(protocol_minor(id14), 4u);
  EXPECT_TRUE(has_depth_buffer(id13, 0)) << "1.0 ... 1.3 devices have no CAPS2 and always a depth buffer";
  EXPECT_TRUE(has_depth_buffer(id13, 1));
  EXPECT_FALSE(has_depth_buffer(id14, 0));
  EXPECT_FALSE(has_depth_buffer(id14, 0xFE)) << "only bit 0 is the depth buffer";
  EXPECT_TRUE(has_depth_buffer(id14, kFeature2Depth));
}

TEST(Crc32, CheckValue) {
  const std::string s = "123456789";
  EXPECT_EQ(crc32(std::span(reinterpret_cast<const std::uint8_t*>(s.data()), s.size())), 0xCBF43926u);
  // Incremental form gives the same answer in pieces.
  const auto* p = reinterpret_cast<const std::uint8_t*>(s.data());
  EXPECT_EQ(crc32_update(crc32_update(0, std::span(p, 4)), std::span(p + 4, 5)), 0xCBF43926u);
}

}  // namespace
}  // namespace gpubridge::protocol
