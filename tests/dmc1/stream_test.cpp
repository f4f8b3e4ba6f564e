// Stream files: the .dmc1 text format, tinygpus' timestamp,b0..b7 lines, and their errors.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "gpubridge/dmc1/command.hpp"
#include "gpubridge/dmc1/stream.hpp"

namespace gpubridge::dmc1 {
namespace {

namespace fs = std::filesystem;

fs::path temp_file(const std::string& name, const std::string& text) {
  const fs::path p = fs::path(::testing::TempDir()) / name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

TEST(TextStream, CommentsBlankLinesAndCase) {
  auto r = parse_text_stream("# header\n\n  0000FFFF3FBC0000  # background\r\n\t00000000c0000001\n", "s.dmc1");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(*r, (std::vector<std::uint64_t>{0x0000FFFF3FBC0000ull, end_of_column()}));
}

TEST(TextStream, ErrorsNameFileLineAndTheFix) {
  const char* bad[] = {"0000ffff3fbc000\n", "0000ffff3fbc00000\n", "0000ffff3fbc000g\n", "0000ffff 3fbc0000\n", "0x0000ffff3fbc00\n"};
  for (const char* text : bad) {
    auto r = parse_text_stream(std::string("00000000c0000001\n# ok\n") + text, "s.dmc1");
    ASSERT_FALSE(r.ok()) << text;
    EXPECT_NE(r.error().message.find("s.dmc1:3: '"), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find("16 hex digits"), std::string::npos) << r.error().message;
  }
}

TEST(TextStream, NonPrintableBytesAreEscapedInErrors) {
  auto r = parse_text_stream(std::string("\xff\x01zz\n", 4), "s.dmc1");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("'\\xFF\\x01zz'"), std::string::npos) << r.error().message;
}

TEST(LineStream, TheFrameNfoFormat) {
  auto r = parse_line_stream("0,0x43,0x20,0xbc,0x0c,0xc0,0x00,0x00,0x00,\n0,0x00,0x00,0x00,0x00,0xc0,0x00,0x00,0x01,\n", "frame.nfo");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(*r, (std::vector<std::uint64_t>{0x4320BC0CC0000000ull, end_of_column()}));
}

TEST(LineStream, BasesAsPythonReadsThemAndOptionalTrailingComma) {
  auto r = parse_line_stream("123, 0 , 0b1, 0o7, 0X1f, 255, 0, 0, 1\n", "x.nfo");
  ASSERT_TRUE(r.ok()) << r.error().message;
  EXPECT_EQ(*r, (std::vector<std::uint64_t>{0x0001071FFF000001ull}));
}

TEST(LineStream, Errors) {
  struct Case {
    const char* line;
    const char* expect;
  } cases[] = {
      {"0,1,2,3,4,5,6,7\n", "9 comma-separated numbers"},
      {"0,1,2,3,4,5,6,7,8,9,\n", "more than 9 fields"},
      {"0,1,2,3,256,5,6,7,8,\n", "byte b3 = 256 does not fit"},
      {"0,1,2,0x,4,5,6,7,8,\n", "field 4 '0x' is not a number"},
      {"0,012,2,3,4,5,6,7,8,\n", "field 2 '012' is not a number"},
      {"0,1,2,3,4,5,6,7,99999999999999999999999,\n", "is not a number"},
  };
  for (const auto& c : cases) {
    auto r = parse_line_stream(std::string("\n") + c.line, "f.nfo");
    ASSERT_FALSE(r.ok()) << c.line;
    EXPECT_NE(r.error().message.find("f.nfo:2: "), std::string::npos) << r.error().message;
    EXPECT_NE(r.error().message.find(c.expect), std::string::npos) << r.error().message;
  }
}

TEST(Streams, FormatThenParseRoundTrips) {
  const std::vector<std::uint64_t> words{wall({0, 239, 15, 0}, 0xFFFF, 0, 0), plane({3, 9, 2, 140}, -100, 300),
                                         0, ~0ull, end_of_column()};
  auto text = parse_text_stream(format_text_stream(words, "a header\nof two lines"), "t");
  ASSERT_TRUE(text.ok()) << text.error().message;
  EXPECT_EQ(*text, words);
  auto lines = parse_line_stream(format_line_stream(words), "l");
  ASSERT_TRUE(lines.ok()) << lines.error().message;
  EXPECT_EQ(*lines, words);
}

TEST(Streams, FilesByExtensionOrSniffed) {
  const std::vector<std::uint64_t> words{view_z(5), end_of_column()};
  for (const char* name : {"a.dmc1", "a.nfo", "a.dat"}) {
    const fs::path p = fs::path(::testing::TempDir()) / name;
    ASSERT_TRUE(save_stream(p, words).ok());
    auto s = load_stream(p);
    ASSERT_TRUE(s.ok()) << s.error().message;
    EXPECT_EQ(s->words, words) << name;
  }
  EXPECT_EQ(load_stream(temp_file("b.txt", "0,1,2,3,4,5,6,7,8,\n"))->format, StreamFormat::Lines);
  EXPECT_EQ(load_stream(temp_file("c.txt", "# x\n00000000c0000001\n"))->format, StreamFormat::Text);
}

TEST(Streams, RefusedFiles) {
  auto missing = load_stream(fs::path(::testing::TempDir()) / "nope.dmc1");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("No such file"), std::string::npos) << missing.error().message;
  auto dir = load_stream(::testing::TempDir());
  ASSERT_FALSE(dir.ok());
  EXPECT_NE(dir.error().message.find("is a directory"), std::string::npos) << dir.error().message;
  auto trace = load_stream(temp_file("t.dmc1", std::string("GBTRACE\0\1\0\0\0\2\0\0\0{}", 18)));
  ASSERT_FALSE(trace.ok());
  EXPECT_NE(trace.error().message.find("binary trace"), std::string::npos) << trace.error().message;
}

}  // namespace
}  // namespace gpubridge::dmc1
