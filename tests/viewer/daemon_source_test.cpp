// DaemonFrameSource pieces that need no daemon: the WELCOME description and the failure paths.
#include <gtest/gtest.h>

#include <cstdlib>

#include "gpubridge/viewer/daemon_frame_source.hpp"

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
