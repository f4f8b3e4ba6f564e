// Trace files on disk: real PNG and hex assets resolved relative to the trace, both formats
// saved and loaded, format detection, and errors that name the file and line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "gpubridge/common/image.hpp"
#include "gpubridge/common/trace_files.hpp"
#include "trace_samples.hpp"

namespace gpubridge {
namespace {

namespace fs = std::filesystem;
using protocol::UploadCmd;

class TraceFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("gpubridge-trace-files-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "assets");
  }
  void TearDown() override { fs::remove_all(dir_); }
  void write(const fs::path& p, const std::string& text) {
    std::ofstream(dir_ / p, std::ios::binary) << text;
  }
  fs::path dir_;
};

TEST_F(TraceFiles, PngAndHexUploadsResolveAgainstTheTraceDirectory) {
  // 2x1 image: opaque red, then half-transparent green.
  Image img;
  img.width = 2;
  img.height = 1;
  img.rgba = {255, 0, 0, 255, 0, 255, 0, 128};
  ASSERT_TRUE(save_png(dir_ / "assets" / "tex.png", img).ok());
  write("assets/data.hex", "de ad\n# comment\nbeef\n");
  write("scene.trace",
        ".upload 0x100 png assets/tex.png\n"
        ".upload 0x200 png assets/tex.png RGB565\n"
        ".upload 0x300 png assets/tex.png RGBA2222\n"
        ".upload 0x400 hex assets/data.hex\n");
  // Load from a different working directory: paths must still resolve against the trace.
  auto s = load_trace(dir_ / "scene.trace");
  ASSERT_TRUE(s.ok()) << s.error().message;
  ASSERT_EQ(s->commands.size(), 4u);
  // Expected bytes written out by hand from docs/protocol.md's pixel formats (big-endian words).
  EXPECT_EQ(std::get<UploadCmd>(s->commands[0].command), (UploadCmd{0x100, {255, 0, 0, 255, 0, 255, 0, 128}}));
  EXPECT_EQ(std::get<UploadCmd>(s->commands[1].command), (UploadCmd{0x200, {0xF8, 0x00, 0x07, 0xE0}}));
  EXPECT_EQ(std::get<UploadCmd>(s->commands[2].command), (UploadCmd{0x300, {0xC3, 0x32}}));
  EXPECT_EQ(std::get<UploadCmd>(s->commands[3].command), (UploadCmd{0x400, {0xDE, 0xAD, 0xBE, 0xEF}}));
}

TEST_F(TraceFiles, AssetErrorsNameBothFiles) {
  write("bad.hex", "01 0g\n");
  write("a.trace", "CLEAR\n.upload 0 hex bad.hex\n");
  auto s = load_trace(dir_ / "a.trace");
  ASSERT_FALSE(s.ok());
  const std::string trace = (dir_ / "a.trace").string();
  const std::string hex = (dir_ / "bad.hex").string();
  EXPECT_EQ(s.error().message.rfind(trace + ":2:15: " + hex + ":1:4: '0g' is not hex bytes", 0), 0u)
      << s.error().message;
  write("b.trace", ".upload 0 png nothere.png\n");
  auto m = load_trace(dir_ / "b.trace");
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().message.find("nothere.png"), std::string::npos) << m.error().message;
  EXPECT_EQ(m.error().message.rfind((dir_ / "b.trace").string() + ":1:15: ", 0), 0u) << m.error().message;
}

TEST_F(TraceFiles, SaveAndLoadBothFormats) {
  auto s = protocol::testing::sample_stream();
  ASSERT_TRUE(save_trace(dir_ / "x.gbt", s).ok());
  ASSERT_TRUE(save_trace(dir_ / "x.trace", s).ok());
  ASSERT_TRUE(save_trace(dir_ / "x.bin", s, TraceFormat::Binary).ok());
  EXPECT_FALSE(save_trace(dir_ / "x.bin", s).ok());  // no format and no known extension
  auto a = load_trace(dir_ / "x.gbt");
  auto b = load_trace(dir_ / "x.trace");
  auto c = load_trace(dir_ / "x.bin");  // binary recognised by its magic
  ASSERT_TRUE(a.ok()) << a.error().message;
  ASSERT_TRUE(b.ok()) << b.error().message;
  ASSERT_TRUE(c.ok()) << c.error().message;
  protocol::testing::expect_same_commands(s, *a, true);
  protocol::testing::expect_same_commands(s, *b, false);
  protocol::testing::expect_same_commands(s, *c, true);
  EXPECT_EQ(b->metadata_json, s.metadata_json);
}

TEST_F(TraceFiles, FormatDetectionAndMissingFiles) {
  EXPECT_EQ(trace_format_for_path("a.GBT"), TraceFormat::Binary);
  EXPECT_EQ(trace_format_for_path("session-1.gbtrace"), TraceFormat::Binary);
  EXPECT_EQ(trace_format_for_path("a.trace"), TraceFormat::Text);
  EXPECT_EQ(trace_format_for_path("a.txt"), TraceFormat::Text);
  EXPECT_FALSE(trace_format_for_path("a.png").has_value());
  write("fake.gbt", "CLEAR\n");
  auto f = load_trace(dir_ / "fake.gbt");
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.error().message.find("not a binary trace"), std::string::npos);
  auto missing = load_trace(dir_ / "missing.trace");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("missing.trace: cannot open"), std::string::npos) << missing.error().message;
}

// Traces are sized and sniffed before reading, so they must be regular files; anything else is
// named for what it is (file_size() on a device said "Operation not supported").
TEST_F(TraceFiles, DirectoriesAndDevicesAreNamedForWhatTheyAre) {
  fs::create_directories(dir_ / "sub.trace");
  auto d = load_trace(dir_ / "sub.trace");
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.error().message.find("sub.trace: is a directory, not a trace"), std::string::npos) << d.error().message;
  auto dev = load_trace("/dev/null");
  ASSERT_FALSE(dev.ok());
  EXPECT_EQ(dev.error().message, "/dev/null: is not a regular file (a pipe or a device); save the trace to a file and pass that");
}

}  // namespace
}  // namespace gpubridge
