// The viewer's side of mirror mode without a window: --source, the overlay's picture line, the
// window title, the help, and reading the daemon's WELCOME/STATUS mirror fields.
#include <gtest/gtest.h>

#include <vector>

#include "gpubridge/viewer/options.hpp"
#include "gpubridge/viewer/overlay.hpp"
#include "gpubridge/viewer/daemon_frame_source.hpp"

namespace gpubridge::viewer {
namespace {

using protocol::FrameSource;

Result<ParsedCommandLine> parse(std::vector<const char*> args) {
  args.insert(args.begin(), "gpubridge-view");
  return parse_command_line(static_cast<int>(args.size()), args.data());
}

TEST(MirrorView, SourceOptionDefaultsToBoardAndAcceptsSimAndDiff) {
  auto p = parse({});
  ASSERT_TRUE(p.ok());
  EXPECT_EQ(p->options.source, FrameSource::Board);
  for (auto [text, want] : {std::pair{"board", FrameSource::Board}, std::pair{"sim", FrameSource::Sim},
                            std::pair{"diff", FrameSource::Diff}}) {
    auto q = parse({"--source", text});
    ASSERT_TRUE(q.ok()) << q.error().message;
    EXPECT_EQ(q->options.source, want) << text;
  }
  auto bad = parse({"--source", "model"});
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code, 2);
  EXPECT_NE(bad.error().message.find("--source model: expected board, sim or diff"), std::string::npos)
      << bad.error().message;
}

ViewState mirror_state(FrameSource asked, std::optional<FrameSource> shown) {
  ViewState v;
  v.status.state = SourceStatus::State::Streaming;
  v.status.address = "unix:/tmp/g.sock";
  v.status.backend = "board";
  v.status.board = "icebreaker";
  v.status.mirror = true;
  v.status.picture = asked;
  v.status.compared = 40;
  v.status.mismatches = 2;
  if (shown) v.frame = ShownFrame{12, 64, 48, protocol::PixelFormat::RGBA8888, true, *shown};
  return v;
}

TEST(MirrorView, OverlayAndTitleSayWhichPictureAndHowManyMismatches) {
  auto v = mirror_state(FrameSource::Diff, FrameSource::Diff);
  EXPECT_EQ(picture_line(v), "showing diff board vs simulator  mismatches 2 of 40 frames");
  std::string all;
  for (const auto& line : overlay_lines(v)) all += line + "\n";
  EXPECT_NE(all.find("mismatches 2 of 40 frames"), std::string::npos) << all;
  EXPECT_EQ(window_title(v),
            "gpubridge-view - unix:/tmp/g.sock - board/icebreaker - diff board vs simulator - 64x48 RGBA8888");
  // The frame on screen decides; a pending switch is named.
  auto switching = mirror_state(FrameSource::Sim, FrameSource::Board);
  EXPECT_EQ(picture_line(switching), "showing board (switching to simulator)  mismatches 2 of 40 frames");
  EXPECT_NE(window_title(switching).find(" - board - "), std::string::npos) << window_title(switching);
  // Before the first frame: the picture asked for.
  EXPECT_EQ(picture_line(mirror_state(FrameSource::Sim, std::nullopt)).rfind("showing simulator", 0), 0u);
}

TEST(MirrorView, WithoutMirrorModeNothingChanges) {
  auto v = mirror_state(FrameSource::Board, FrameSource::Board);
  v.status.mirror = false;
  EXPECT_EQ(picture_line(v), "");
  EXPECT_EQ(window_title(v), "gpubridge-view - unix:/tmp/g.sock - board/icebreaker - 64x48 RGBA8888");
  v.status.picture_problem = "cannot show the diff board vs simulator: UNAVAILABLE: ...";
  std::string all;
  for (const auto& line : overlay_lines(v)) all += line + "\n";
  EXPECT_NE(all.find("cannot show the diff"), std::string::npos) << all;
}

TEST(MirrorView, HelpListsThePictureKeys) {
  std::string all;
  for (const auto& line : help_lines()) all += line + "\n";
  for (const char* key : {"  B ", "  M ", "  D "}) EXPECT_NE(all.find(key), std::string::npos) << key << "\n" << all;
  EXPECT_NE(all.find("magenta"), std::string::npos);
}

TEST(MirrorView, ReadsTheDaemonsMirrorFields) {
  EXPECT_TRUE(mirror_enabled(R"({"backend":"board","mirror":true})"));
  EXPECT_FALSE(mirror_enabled(R"({"backend":"sim","mirror":false})"));
  EXPECT_FALSE(mirror_enabled(R"({"backend":"sim"})"));
  EXPECT_FALSE(mirror_enabled("not json"));
  auto counts = mirror_counts(R"({"mirror":{"enabled":true,"compared":9,"mismatches":3}})");
  ASSERT_TRUE(counts);
  EXPECT_EQ(counts->first, 9u);
  EXPECT_EQ(counts->second, 3u);
  EXPECT_FALSE(mirror_counts(R"({"frames":{}})"));
  EXPECT_FALSE(mirror_counts(R"({"mirror":{"compared":-1,"mismatches":0}})"));
  EXPECT_FALSE(mirror_counts("["));
}

}  // namespace
}  // namespace gpubridge::viewer
