// The command field table and the builders derived from it.
#include <set>

#include <gtest/gtest.h>

#include "gpubridge/dmc1/command.hpp"

namespace gpubridge::dmc1 {
namespace {

TEST(Command, KindOfEveryBuilder) {
  EXPECT_EQ(kind_of(wall({0, 239, 15, 0}, 0xFFFF, 0, 0)), CommandKind::Wall);
  EXPECT_EQ(kind_of(plane({10, 20, 3, 130}, -5, 7)), CommandKind::Plane);
  EXPECT_EQ(kind_of(terrain({0, 239, 3, 663}, 0, 2047, true)), CommandKind::Terrain);
  EXPECT_EQ(kind_of(ray_cs(-4096, 4095)), CommandKind::RayCs);
  EXPECT_EQ(kind_of(uv_offset(-1, 1, true)), CommandKind::UvOffset);
  EXPECT_EQ(kind_of(plane_a(-512, 511, 0, -8192, 8191)), CommandKind::PlaneA);
  EXPECT_EQ(kind_of(view_z(-32768)), CommandKind::ViewZ);
  EXPECT_EQ(kind_of(end_of_column()), CommandKind::EndOfColumn);
  // The end of column ignores tex0; a parameter needs bit 0 clear.
  EXPECT_EQ(kind_of(0xFFFFFFFFC0000001ull), CommandKind::EndOfColumn);
  EXPECT_EQ(kind_of(0x40000000C0000000ull), CommandKind::UvOffset);
}

TEST(Command, TheFrameNfoFirstLineIsAUvOffset) {
  // 0,0x43,0x20,0xbc,0x0c,0xc0,0x00,0x00,0x00, from tinygpus' frame.nfo
  const std::uint64_t w = 0x4320BC0CC0000000ull;
  EXPECT_EQ(kind_of(w), CommandKind::UvOffset);
  EXPECT_EQ(get_field(w, *find_field(CommandKind::UvOffset, "v_offset")), 0x20BC0C);
  EXPECT_EQ(get_field(w, *find_field(CommandKind::UvOffset, "u_offset")), 0);
}

TEST(Command, WallWordMatchesTheSheetsAssembly) {
  // tex1 = L<<26 | end<<18 | start<<10 | tid; tex0 = d | v_init<<16 | u_init<<24
  const std::uint64_t w = wall({17, 200, 9, 321}, 0x1234, 0x56, 0x78);
  const std::uint32_t tex1 = (9u << 26) | (200u << 18) | (17u << 10) | 321u;
  const std::uint32_t tex0 = 0x1234u | (0x56u << 16) | (0x78u << 24);
  EXPECT_EQ(w, (std::uint64_t{tex0} << 32) | tex1);
}

TEST(Command, SignedFieldsRoundTripAtTheirExtremes) {
  for (const Field& f : fields()) {
    if (!f.is_signed) continue;
    const std::int64_t lo = -(std::int64_t{1} << (f.width - 1)), hi = (std::int64_t{1} << (f.width - 1)) - 1;
    for (std::int64_t v : {lo, std::int64_t{-1}, std::int64_t{0}, hi}) {
      std::uint64_t w = blank_word(f.kind);
      set_field(w, f, v);
      EXPECT_EQ(get_field(w, f), v) << to_string(f.kind) << "." << f.name;
      EXPECT_EQ(kind_of(w), f.kind) << to_string(f.kind) << "." << f.name << " = " << v << " changed the kind";
    }
  }
}

TEST(Command, ValuesAreTruncatedToTheirField) {
  const std::uint64_t w = plane_a(512, 0, 0, 0, 0);  // 512 does not fit int10: wraps to -512
  EXPECT_EQ(get_field(w, *find_field(CommandKind::PlaneA, "ny")), -512);
  EXPECT_EQ(get_field(w, *find_field(CommandKind::PlaneA, "uy")), 0);
}

// Within a kind, fields never overlap each other, the tag (bits 31:30), the parameter sub-type
// (63:62) or the end-of-column bit (0).
TEST(Command, FieldsDoNotOverlapEachOtherOrTheTags) {
  for (unsigned k = 0; k < kCommandKinds; ++k) {
    const auto kind = static_cast<CommandKind>(k);
    std::uint64_t reserved = 3ull << 30;
    if (!is_span(kind)) reserved |= (3ull << 62) | 1;
    std::set<std::string_view> names;
    for (const Field& f : fields_of(kind)) {
      const std::uint64_t m = ((f.width == 64 ? 0 : (1ull << f.width)) - 1) << f.lsb;
      EXPECT_EQ(m & reserved, 0u) << to_string(kind) << "." << f.name;
      reserved |= m;
      EXPECT_TRUE(names.insert(f.name).second) << "duplicate " << f.name;
    }
  }
}

TEST(Command, DescribeNamesKindAndFields) {
  EXPECT_EQ(describe(wall({1, 2, 3, 4}, 5, 6, 7)), "wall texture=4 start=1 end=2 light=3 depth=5 v_init=6 u_init=7");
  EXPECT_EQ(describe(end_of_column()), "eoc");
  EXPECT_EQ(describe(view_z(-2)), "view_z z=-2");
}

TEST(Command, KindNamesRoundTrip) {
  for (unsigned k = 0; k < kCommandKinds; ++k) {
    const auto kind = static_cast<CommandKind>(k);
    EXPECT_EQ(parse_command_kind(to_string(kind)), kind);
  }
  EXPECT_FALSE(parse_command_kind("triangle").has_value());
}

}  // namespace
}  // namespace gpubridge::dmc1
