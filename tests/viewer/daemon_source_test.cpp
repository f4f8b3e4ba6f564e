// DaemonFrameSource pieces that need no daemon: the WELCOME description and the failure paths.
#include <gtest/gtest.h>

#include <cstdlib>

#include "gpubridge/viewer/daemon_frame_source.hpp"
#include "gpubridge/viewer/overlay.hpp"

namespace gpubridge::viewer {
namespace {

using namespace std::chrono_literals;

TEST(DaemonSource, ReadsBackendAndBoardFromTheWelcome) {
  EXPECT_EQ(backend_and_board(R"({"backend":"usb","board":"ulx3s-85f","x":1})"),
            (std::pair<std::string, std::string>{"usb", "ulx3s-85f"}));
  EXPECT_EQ(backend_and_board(R"({"backend":"sim"})"), (std::pair<std::string, std::string>{"sim", ""}));
  EXPECT_EQ(backend_and_board(R"({"backend":5})"), (std::pair<std::string, std::string>{"", ""}));
  EXPECT_EQ(backend_and_board("not json"), (std::pair<std::string, std::string>{"?", ""}));
  EXPECT_EQ(backend_and_board("[1,2]"), (std::pair<std::string, std::string>{"?", ""}));
}

// A DMC-1 board's WELCOME says whose frames it shows (docs/protocol.md 17.7); the overlay prints it
// under the device line.
TEST(DaemonSource, TheOverlaySaysWhoseFramesTheyAre) {
  EXPECT_EQ(frames_note(R"({"backend":"board","frames_note":"the simulator's frames"})"), "the simulator's frames");
  EXPECT_EQ(frames_note(R"({"backend":"sim"})"), "");
  EXPECT_EQ(frames_note(R"({"frames_note":3})"), "");
  ViewState v;
  v.status.backend = "board";
  v.status.board = "icebreaker-dmc1";
  v.status.frames_note = "the simulator's frames";
  const auto lines = overlay_lines(v);
  ASSERT_GE(lines.size(), 2u);
  EXPECT_EQ(lines[1], "frames: the simulator's frames");
  v.status.frames_note.clear();
  EXPECT_NE(overlay_lines(v)[1].rfind("frames:", 0), 0u) << "no note line for a device's own frames";
}

// A daemon serving a DMC-1 says so on the device line and in the title; spigpu, the protocol's own
// device, keeps the plain backend name.
TEST(DaemonSource, TheOverlayNamesADeviceKindOtherThanSpigpu) {
  ViewState v;
  v.status.address = "unix:/tmp/g.sock";
  v.status.backend = "sim";
  EXPECT_EQ(overlay_lines(v)[0], "unix:/tmp/g.sock  sim");
  v.status.device = "DMC-1";
  EXPECT_EQ(overlay_lines(v)[0], "unix:/tmp/g.sock  DMC-1 sim");
  EXPECT_EQ(window_title(v), "gpubridge-view - unix:/tmp/g.sock - DMC-1 sim");
  v.status.backend = "board";
  v.status.board = "icebreaker-dmc1";
  EXPECT_EQ(overlay_lines(v)[0], "unix:/tmp/g.sock  DMC-1 board/icebreaker-dmc1");
}

// WELCOME's "accuracy" (docs/protocol.md 17.7) reaches the overlay's frame line; the simulator
// picture of a mirror-mode daemon is always the exact model's.
TEST(DaemonSource, TheOverlaySaysWhichAccuracyRenderedTheFrame) {
  EXPECT_EQ(device_accuracy(R"({"backend":"sim","accuracy":"preview"})"), "preview");
  EXPECT_EQ(device_accuracy(R"({"backend":"sim"})"), "");  // an older daemon
  ViewState v;
  v.status.state = SourceStatus::State::Streaming;
  v.status.backend = "sim";
  v.status.accuracy = "preview";
  v.frame = ShownFrame{.number = 7, .width = 64, .height = 48};
  EXPECT_EQ(overlay_lines(v)[1], "frame 7  64x48 RGBA8888  accuracy preview");
  v.status.accuracy.clear();
  EXPECT_EQ(overlay_lines(v)[1], "frame 7  64x48 RGBA8888");
  v.status.mirror = true;
  v.status.accuracy = "exact";
  v.frame->source = protocol::FrameSource::Sim;
  EXPECT_EQ(accuracy_text(v), "accuracy exact");
}

SourceStatus wait_for_end(FrameSource& s) {
  for (int i = 0; i < 100; ++i) {
    const auto v = s.status_version();
    const auto st = s.status();
    if (st.state == SourceStatus::State::Failed || st.state == SourceStatus::State::Waiting) return st;
    s.wait(100ms, v);
  }
  return s.status();
}

TEST(DaemonSource, FailsWithOneClearLineWhenNothingListens) {
  DaemonFrameSource s({"unix:/nonexistent-dir-for-gpubridge-view-test/x.sock", "", 60, false});
  s.start();
  const auto st = wait_for_end(s);
  EXPECT_EQ(st.state, SourceStatus::State::Failed);
  EXPECT_EQ(st.address, "unix:/nonexistent-dir-for-gpubridge-view-test/x.sock");
  EXPECT_NE(st.message.find("--wait"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find("x.sock"), std::string::npos) << st.message;
  EXPECT_EQ(st.message.find('\n'), std::string::npos);
}

TEST(DaemonSource, WaitsInsteadWhenAskedTo) {
  DaemonFrameSource s({"unix:/nonexistent-dir-for-gpubridge-view-test/x.sock", "", 60, true});
  s.start();
  const auto st = wait_for_end(s);
  EXPECT_EQ(st.state, SourceStatus::State::Waiting);
  s.stop();
}

TEST(DaemonSource, RefusesAMalformedAddress) {
  DaemonFrameSource s({"carrier-pigeon:somewhere", "", 60, true});
  s.start();
  const auto st = wait_for_end(s);
  EXPECT_EQ(st.state, SourceStatus::State::Failed);
  EXPECT_FALSE(st.message.empty());
}

// No --connect means the default socket, as for every other client (issue 15: the viewer failed with
// `bad address "": unknown scheme` while `gpubridge status` found the daemon).
TEST(DaemonSource, NoAddressMeansTheDefaultSocket) {
  const std::string runtime = ::testing::TempDir() + "gpubridge-view-default-socket-test";
  const char* old = std::getenv("XDG_RUNTIME_DIR");
  const std::string saved = old ? old : "";
  ::setenv("XDG_RUNTIME_DIR", runtime.c_str(), 1);
  DaemonFrameSource s({"", "", 60, false});
  s.start();
  const auto st = wait_for_end(s);
  if (old) ::setenv("XDG_RUNTIME_DIR", saved.c_str(), 1);
  else ::unsetenv("XDG_RUNTIME_DIR");
  EXPECT_EQ(st.state, SourceStatus::State::Failed);  // nothing listens there
  EXPECT_EQ(st.address, "unix:" + runtime + "/gpubridge/gpubridge.sock");
  EXPECT_EQ(st.message.find("bad address"), std::string::npos) << st.message;
  EXPECT_NE(st.message.find(runtime + "/gpubridge/gpubridge.sock"), std::string::npos) << st.message;
}

}  // namespace
}  // namespace gpubridge::viewer
