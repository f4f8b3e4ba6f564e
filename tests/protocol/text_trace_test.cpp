// Text traces: grammar, directives, exact FILE:LINE:COL errors, canonical round trips.
#include <gtest/gtest.h>

#include "gpubridge/protocol/text_trace.hpp"
#include "gpubridge/protocol/trace.hpp"
#include "trace_samples.hpp"

namespace gpubridge::protocol {
namespace {

Result<CommandStream> parse(std::string_view text, const AssetLoader& loader = {}) {
  return parse_text_trace(text, "scene.trace", loader);
}

std::string error_of(std::string_view text, const AssetLoader& loader = {}) {
  auto r = parse(text, loader);
  return r.ok() ? std::string("(no error)") : r.error().message;
}

std::vector<Frame> frames_of(const CommandStream& s) {
  std::vector<Frame> out;
  for (const auto& c : s.commands)
    if (const auto* f = std::get_if<FramesCmd>(&c.command))
      for (std::size_t i = 0; i < f->size(); ++i) out.push_back(f->view()[i]);
  return out;
}

TEST(TextTrace, FormsCommentsAndBlankLines) {
  auto s = parse(
      "# a comment\n"
      "\n"
      "   VERTEX X=1.5 Y=-2   # trailing comment\r\n"
      "vertex z=0x10\n"
      "0x42 0xDEAD\n"
      "CLEAR\n"
      "PRIM TYPE=strip\n"
      "TEX_BASE 0x1000\n"
      "HOST_TAG 18446744073709551615\n"
      "FENCE 0xFFFF_FFFF\n");
  ASSERT_TRUE(s.ok()) << s.error().message;
  const auto f = frames_of(*s);
  ASSERT_EQ(f.size(), 8u);
  ASSERT_EQ(s->commands.size(), 1u);  // consecutive register lines form one batch
  EXPECT_EQ(f[0], write_frame(Reg::VERTEX, ((0xFFE0ull) << 16) | 24));
  EXPECT_EQ(f[1], write_frame(Reg::VERTEX, 0x10ull << 32));  // omitted fields are 0
  EXPECT_EQ(f[2], (Frame{false, 0x42, 0xDEAD}));
  EXPECT_EQ(f[3], write_frame(Reg::CLEAR, 0));
  EXPECT_EQ(f[4], write_frame(Reg::PRIM, 1));
  EXPECT_EQ(f[5], write_frame(Reg::TEX_BASE, 0x1000));
  EXPECT_EQ(f[6], write_frame(Reg::HOST_TAG, ~0ull));
  EXPECT_EQ(f[7], write_frame(Reg::FENCE, 0xFFFFFFFFull));
}

TEST(TextTrace, Directives) {
  auto s = parse(
      ".meta {\"created_by\": \"a # not a comment\"}\n"
      "CLEAR\n"
      ".batch\n"
      "CLEAR\n"
      ".mem 0x100 0102 ff\n"
      ".fence 7\n"
      ".read status\n"
      ".read 0x55\n"
      ".readback 16 32\n");
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(s->metadata_json, "{\"created_by\": \"a # not a comment\"}");
  ASSERT_EQ(s->commands.size(), 7u);
  EXPECT_EQ(std::get<FramesCmd>(s->commands[0].command).size(), 1u);
  EXPECT_EQ(std::get<FramesCmd>(s->commands[1].command).size(), 1u);
  EXPECT_EQ(std::get<UploadCmd>(s->commands[2].command), (UploadCmd{0x100, {1, 2, 0xFF}}));
  EXPECT_EQ(std::get<FenceCmd>(s->commands[3].command).id, 7u);
  EXPECT_EQ(std::get<ReadRegCmd>(s->commands[4].command).index, index_of(Reg::STATUS));
  EXPECT_EQ(std::get<ReadRegCmd>(s->commands[5].command).index, 0x55);
  EXPECT_EQ(std::get<ReadbackCmd>(s->commands[6].command), (ReadbackCmd{16, 32}));
}

TEST(TextTrace, Caps2IsReadByNameAndNotWritable) {
  // protocol 1.4's CAPS2 (0x7D) comes from the register table like every other name
  auto s = parse(".read caps2\n.read CAPS2\n");
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_EQ(s->commands.size(), 2u);
  EXPECT_EQ(std::get<ReadRegCmd>(s->commands[0].command).index, 0x7D);
  EXPECT_EQ(std::get<ReadRegCmd>(s->commands[1].command).index, index_of(Reg::CAPS2));
  EXPECT_EQ(error_of("CAPS2 1\n"),
            "scene.trace:1:1: CAPS2 is read-only; use `.read CAPS2` to read it (the raw form 0xIDX 0xDATA sends a write anyway)");
}

TEST(TextTrace, UploadDirectivesUseTheLoader) {
  std::vector<TraceAsset> seen;
  AssetLoader loader = [&](const TraceAsset& a) -> Result<std::vector<std::uint8_t>> {
    seen.push_back(a);
    if (a.path == "missing.png") return make_error("missing.png: no such file");
    return std::vector<std::uint8_t>{7, 7};
  };
  auto s = parse(".upload 0x40 png tex.png RGB565\n.upload 64 png tex.png\n.upload 0 hex data.hex\n", loader);
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_EQ(seen.size(), 3u);
  EXPECT_EQ(seen[0].kind, TraceAsset::Kind::Png);
  EXPECT_EQ(seen[0].format, PixelFormat::RGB565);
  EXPECT_EQ(seen[1].format, PixelFormat::RGBA8888);  // default
  EXPECT_EQ(seen[2].kind, TraceAsset::Kind::Hex);
  EXPECT_EQ(seen[2].path, "data.hex");
  EXPECT_EQ(std::get<UploadCmd>(s->commands[0].command), (UploadCmd{0x40, {7, 7}}));
  EXPECT_EQ(error_of("CLEAR\n.upload 0 png missing.png\n", loader), "scene.trace:2:15: missing.png: no such file");
  EXPECT_EQ(error_of(".upload 0 png a.png\n"),
            "scene.trace:1:15: this reader cannot open files (no loader); convert with `gpubridge trace`");
}

struct BadLine {
  const char* text;
  const char* expect;  // full message after "scene.trace:"
};

TEST(TextTrace, BadLinesReportLineAndColumn) {
  const BadLine cases[] = {
      {"VERTEX X=100.3", "3:8: X=100.3 is not a multiple of 1/16 (X is signed 12.4)"},
      {"VERTX X=1", "3:1: unknown register 'VERTX'"},
      {"VERTEX W=1", "3:8: unknown field 'W' of VERTEX; its fields are Z, Y, X"},
      {"VERTEX X=2048", "3:8: X=2048 is out of range -2048..2047.9375 (X is signed 12.4)"},
      {"VERTEX X=1 X=2", "3:12: field X is set twice"},
      {"VERTEX Z=0x1000000", "3:8: Z=0x1000000 does not fit the 24-bit field Z"},
      {"VERTEX Z=1.5", "3:8: Z=1.5 is not an integer (Z is unsigned 24-bit integer)"},
      {"VERTEX Z=-1", "3:8: Z=-1 is out of range 0..16777215"},
      {"VERTEX Z=abc", "3:8: Z=abc is not a number"},
      {"VERTEX X=", "3:8: X= has no value"},
      {"VERTEX 1 2", "3:10: unexpected '2'"},
      {"VERTEX 1.5", "3:8: a fractional or negative value needs a single-field register"},
      {"TRI_MODE Z_FUNC=SOMETIMES", "3:10: Z_FUNC=SOMETIMES is not a Z_FUNC value; use one of NEVER, LESS"},
      {"TRI_MODE GOURAUD=2", "3:10: GOURAUD=2 is not a flag value; use 0 or 1"},
      {"TRI_MODE GOURAUD", "3:10: 'GOURAUD' is not a value for TRI_MODE"},
      {"TRI_MODE GOURAUD=1 Z_TEST", "3:20: expected FIELD=value, found 'Z_TEST'"},
      {"TRI_MODE DITHER_PHASE=16", "3:10: DITHER_PHASE=16 is out of range 0..15"},
      {"PRIM 3", "3:6: value 0x3 is not valid for PRIM"},
      {"CLEAR 1", "3:7: value 0x1 is not valid for CLEAR"},
      {"STATUS 0", "3:1: STATUS is read-only"},
      {"COLOR Q=1", "3:7: Q=1 is out of range 0..0.99999999976716935634613037109375 (Q is unsigned 0.32)"},
      {"COLOR Q=0.1", "3:7: Q=0.1 is not a multiple of 1/4294967296 (Q is unsigned 0.32)"},
      {"HOST_TAG 0x1_0000_0000_0000_0000", "3:10: '0x1_0000_0000_0000_0000' is not a value for HOST_TAG"},
      {"0x80 0", "3:1: '0x80' is not a register index"},
      {"0x10", "3:5: a raw frame is exactly `0xIDX 0xDATA`"},
      {"0x10 0x1 0x2", "3:10: a raw frame is exactly `0xIDX 0xDATA`"},
      {"0x10 zz", "3:6: 'zz' is not a 64-bit value"},
      {".fence", "3:7: usage: .fence ID"},
      {".fence 1 2", "3:10: usage: .fence ID"},
      {".fence -1", "3:8: '-1' is not a fence id"},
      {".read NOPE", "3:7: unknown register 'NOPE'"},
      {".readback 0 0", "3:13: readback length 0"},
      {".readback 0 67108865", "3:13: readback length 67108865 exceeds 67108864"},
      {".mem 0x10 abc", "3:11: 'abc' is not hex bytes"},
      {".mem 0xFFFFFFFF 0102", "3:6: an upload of 2 bytes at address 4294967295 runs past the 4 GiB address space"},
      {".mem 0x100000000 01", "3:6: address 0x100000000 exceeds 4294967295"},
      {".upload 0 gif x.gif", "3:11: 'gif' is not an upload kind; use png or hex"},
      {".upload 0 png x.png RGB888", "3:21: 'RGB888' is not a pixel format"},
      {".upload 0 hex x.hex RGB565", "3:21: a hex upload takes no format"},
      {".meta [1]", "3:1: .meta value is JSON but not an object"},
      {".frobnicate", "3:1: unknown directive '.frobnicate'"},
  };
  for (const auto& c : cases) {
    const std::string text = std::string("# header\nCLEAR\n") + c.text + "\nCLEAR\n";
    const std::string got = error_of(text);
    EXPECT_EQ(got.rfind(std::string("scene.trace:") + c.expect, 0), 0u) << c.text << "\n  got: " << got;
  }
}

// A token is shown at most 40 bytes long, control bytes escaped: a 20 MB token used to be echoed
// whole (and a NUL in it cut the message where it was printed).
TEST(TextTrace, LongAndBinaryTokensAreShownShortened) {
  std::string token(1u << 20, '7');
  token[3] = '\0';
  token[5] = '\x1b';
  const auto e = error_of("CLEAR_COLOR " + token);
  const std::string shown = "777\\07\\x1B" + std::string(34, '7') + "... (1048576 bytes)";
  EXPECT_EQ(e.rfind("scene.trace:1:13: '" + shown + "' is not a value for CLEAR_COLOR; ", 0), 0u) << e.substr(0, 300);
  EXPECT_LT(e.size(), 300u);
  const auto unknown = error_of(std::string(100, 'Q') + " 1");
  EXPECT_LT(unknown.size(), 200u) << unknown.substr(0, 300);
  EXPECT_NE(unknown.find("... (100 bytes)"), std::string::npos) << unknown;
}

// Text traces hold spigpu register writes, so their metadata may name only that kind: a text trace
// saying "dmc1" (or naming no kind at all) used to be accepted and then produce a binary trace that
// every reader refused (found by fuzz_text_trace).
TEST(TextTrace, MetaNamesOnlyTheSpigpuKind) {
  const auto dmc1 = error_of("CLEAR\n.meta {\"device_kind\": \"dmc1\"}\n");
  EXPECT_EQ(dmc1.rfind("scene.trace:2:1: .meta says device_kind \"dmc1\", but a text trace holds spigpu register "
                       "writes (DMC-1 traces are binary only); remove \"device_kind\" or write \"spigpu\"",
                       0),
            0u)
      << dmc1;
  for (const char* bad : {R"(5)", R"("vga")", R"(null)", R"(["spigpu"])"}) {
    const auto e = error_of(std::string(".meta {\"a\": 1, \"device_kind\": ") + bad + "}\n");
    EXPECT_EQ(e.rfind(std::string("scene.trace:1:1: .meta device_kind ") + bad +
                          " is not a device kind (spigpu, dmc1); remove it or write \"spigpu\"",
                      0),
              0u)
        << e;
  }
  // "spigpu" is the default said aloud: accepted, kept, and the binary form reads back.
  auto s = parse(".meta {\"device_kind\": \"spigpu\"}\nCLEAR\n");
  ASSERT_TRUE(s.ok()) << s.error().message;
  auto bytes = write_binary_trace(*s);
  ASSERT_TRUE(bytes.ok()) << bytes.error().message;
  auto back = read_binary_trace(*bytes, "b");
  ASSERT_TRUE(back.ok()) << back.error().message;
  EXPECT_EQ(back->commands, s->commands);
  EXPECT_EQ(back->metadata_json, "{\"device_kind\": \"spigpu\"}");
}

TEST(TextTrace, SecondMetaIsAnError) {
  EXPECT_EQ(error_of(".meta {}\n.meta {}\n").rfind("scene.trace:2:1: .meta appears twice", 0), 0u);
}

TEST(TextTrace, CanonicalTextIsStable) {
  const std::string text =
      "VERTEX X=1.5 Y=-2 Z=0x10\n"
      "TRI_MODE GOURAUD=1 Z_FUNC=lequal Z_TEST=1\n"
      "TRI_MODE DITHER=1 TEMPORAL=1 DITHER_PHASE=9\n"
      ".upload 0 hex x.hex\n"
      "COLOR R=1 Q=0.25\n";
  AssetLoader loader = [](const TraceAsset&) -> Result<std::vector<std::uint8_t>> {
    return std::vector<std::uint8_t>{1, 2, 3};
  };
  auto s = parse(text, loader);
  ASSERT_TRUE(s.ok()) << s.error().message;
  const std::string canonical = write_text_trace(*s);
  auto bytes = write_binary_trace(*s);
  ASSERT_TRUE(bytes.ok());
  auto back = read_binary_trace(*bytes, "x");
  ASSERT_TRUE(back.ok());
  EXPECT_EQ(write_text_trace(*back), canonical);
  EXPECT_NE(canonical.find("VERTEX Z=0x10 Y=-2 X=1.5\n"), std::string::npos) << canonical;
  EXPECT_NE(canonical.find("TRI_MODE Z_FUNC=LEQUAL Z_TEST=1 GOURAUD=1\n"), std::string::npos) << canonical;
  EXPECT_NE(canonical.find("TRI_MODE DITHER_PHASE=9 TEMPORAL=1 DITHER=1\n"), std::string::npos) << canonical;
  EXPECT_NE(canonical.find(".mem 0x00000000 010203\n"), std::string::npos) << canonical;
}

TEST(TextTrace, PseudoRandomFramesRoundTrip) {
  // Arbitrary register writes (defined or not, reserved bits or not) survive text form exactly.
  std::uint64_t x = 0x9E3779B97F4A7C15ull;
  const auto next = [&x] {
    x ^= x << 13, x ^= x >> 7, x ^= x << 17;
    return x;
  };
  CommandStream s;
  FramesCmd f;
  for (int i = 0; i < 5000; ++i) {
    const auto idx = static_cast<std::uint8_t>(next() % 128);
    std::uint64_t data = next();
    if (i % 2 == 0) data &= ~(find_register(idx) ? find_register(idx)->reserved_mask() : 0);  // mostly clean
    f.push(Frame{false, idx, data});
  }
  s.commands.push_back({0, f});
  auto back = parse_text_trace(write_text_trace(s), "r.trace", {});
  ASSERT_TRUE(back.ok()) << back.error().message;
  ASSERT_EQ(back->commands.size(), 1u);
  EXPECT_EQ(std::get<FramesCmd>(back->commands[0].command).bytes, f.bytes);
}

TEST(TextTrace, HexBytes) {
  auto b = parse_hex_bytes("01 0x0203\n# comment ff\n\tAb");
  ASSERT_TRUE(b.ok()) << b.error().message;
  EXPECT_EQ(*b, (std::vector<std::uint8_t>{1, 2, 3, 0xAB}));
  EXPECT_EQ(parse_hex_bytes("01\n 123").error().message.rfind("2:2: '123' has an odd number of hex digits", 0), 0u);
  EXPECT_EQ(parse_hex_bytes("zz").error().message.rfind("1:1: 'zz' is not hex bytes", 0), 0u);
}

}  // namespace
}  // namespace gpubridge::protocol
