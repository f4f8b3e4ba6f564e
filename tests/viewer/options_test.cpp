// gpubridge-view's command line: defaults, validation, and the help/version exits.
#include <gtest/gtest.h>

#include <vector>

#include "gpubridge/viewer/options.hpp"

namespace gpubridge::viewer {
namespace {

Result<ParsedCommandLine> parse(std::vector<const char*> args) {
  args.insert(args.begin(), "gpubridge-view");
  return parse_command_line(static_cast<int>(args.size()), args.data());
}

TEST(Options, DefaultsShowTheDefaultSocketInteractively) {
  auto p = parse({});
  ASSERT_TRUE(p.ok()) << p.error().message;
  EXPECT_EQ(p->action, ParsedCommandLine::Action::Run);
  EXPECT_EQ(p->options.connect, "");
  EXPECT_FALSE(p->options.frames.has_value());
  EXPECT_FALSE(p->options.max_fps.has_value());
  EXPECT_TRUE(p->options.overlay);
  EXPECT_EQ(p->options.scale, ScaleMode::Fit);
}

TEST(Options, HeadlessCapture) {
  auto p = parse({"--connect", "unix:/tmp/x.sock", "--frames", "3", "--screenshot", "out.png", "--offscreen",
                  "--json", "--max-fps", "0", "--scale", "integer", "--size", "800x600", "--no-overlay"});
  ASSERT_TRUE(p.ok()) << p.error().message;
  const Options& o = p->options;
  EXPECT_EQ(o.connect, "unix:/tmp/x.sock");
  EXPECT_EQ(o.frames, 3u);
  EXPECT_EQ(o.screenshot, "out.png");
  EXPECT_TRUE(o.offscreen);
  EXPECT_TRUE(o.json);
  EXPECT_EQ(o.max_fps, 0u);
  EXPECT_EQ(o.scale, ScaleMode::Integer);
  EXPECT_EQ(o.window_size, (std::pair{800, 600}));
  EXPECT_FALSE(o.overlay);
}

TEST(Options, ScreenshotAloneMeansTheFirstFrame) {
  auto p = parse({"--screenshot", "a.png"});
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p->options.frames, 1u);
}

TEST(Options, RefusesBadValuesWithAUsageError) {
  const std::vector<std::vector<const char*>> bad = {
      {"--frames", "0"},           {"--frames", "abc"},        {"--frames", "2"},  // nothing to do with it
      {"--scale", "4"},            {"--size", "10x10"},        {"--size", "800"},
      {"--size", "800x600x2"},     {"--max-fps", "100000"},    {"--timeout", "0"},
      {"--timeout", "nan"},        {"--log-level", "loud"},    {"--no-such-option"},
  };
  for (const auto& args : bad) {
    auto p = parse(args);
    std::string joined;
    for (auto a : args) joined += std::string(a) + " ";
    ASSERT_FALSE(p.ok()) << joined;
    EXPECT_EQ(p.error().code, 2) << joined;
    EXPECT_FALSE(p.error().message.empty());
  }
}

TEST(Options, HelpAndVersionExitCleanly) {
  auto h = parse({"--help"});
  ASSERT_TRUE(h.ok());
  EXPECT_EQ(h->action, ParsedCommandLine::Action::Exit);
  EXPECT_EQ(h->exit_code, 0);
  for (const char* opt : {"--connect", "--token", "--frames", "--screenshot", "--offscreen", "--json", "--grab-window"})
    EXPECT_NE(h->output.find(opt), std::string::npos) << opt;
  EXPECT_EQ(h->output.find("--test-source"), std::string::npos);  // hidden
  auto v = parse({"--version"});
  ASSERT_TRUE(v.ok());
  EXPECT_EQ(v->action, ParsedCommandLine::Action::Exit);
  EXPECT_NE(v->output.find("gpubridge-view "), std::string::npos);
}

}  // namespace
}  // namespace gpubridge::viewer
