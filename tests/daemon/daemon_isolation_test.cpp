// Issue 14, "nobody else in": the socket's directory and lock cannot be planted by another local
// user, clients refuse a daemon of another user, and a client without the lease cannot change
// anything the lease holder sees.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include "daemon_process.hpp"
#include "gpubridge/client/client.hpp"
#include "gpubridge/protocol/crc32.hpp"
#include "hostile_clients.hpp"

namespace gpubridge::test {
namespace {

using namespace std::chrono_literals;
using protocol::LeaseMode;
using protocol::Reg;

constexpr int kNobody = 65534;

class DaemonIsolation : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = make_temp_dir(::testing::UnitTest::GetInstance()->current_test_info()->name()); }
  void TearDown() override {
    daemon_.stop();
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  // gpubridged on the default socket with XDG_RUNTIME_DIR=xdg: its result when it does not start.
  ProcessResult start_default(const fs::path& xdg) {
    return run_process({GPUBRIDGED_PATH, "--backend", "fake", "--log-level", "warn"}, 5s, {"XDG_RUNTIME_DIR=" + xdg.string()});
  }
  fs::path dir_;
  Daemon daemon_;
};

// Item 6: the runtime directory of the default socket must be ours, 0700 and not a symlink, as
// OpenSSH and systemd require; otherwise another local user could move our socket away and serve
// our clients.
TEST_F(DaemonIsolation, ARuntimeDirectoryThatIsNotPrivatelyOursIsRefused) {
  {
    const auto xdg = dir_ / "wide";
    fs::create_directories(xdg / "gpubridge");
    ::chmod((xdg / "gpubridge").c_str(), 0755);
    const auto r = start_default(xdg);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find((xdg / "gpubridge").string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("0755"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(xdg / "gpubridge" / "gpubridge.sock"));
  }
  {
    const auto xdg = dir_ / "link";
    fs::create_directories(xdg);
    fs::create_directories(dir_ / "elsewhere");
    ::chmod((dir_ / "elsewhere").c_str(), 0700);
    fs::create_directory_symlink(dir_ / "elsewhere", xdg / "gpubridge");
    const auto r = start_default(xdg);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find("symbolic link"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "elsewhere" / "gpubridge.sock"));
  }
  if (::geteuid() == 0) {  // only root can give a directory to another user
    const auto xdg = dir_ / "theirs";
    fs::create_directories(xdg / "gpubridge");
    ::chmod((xdg / "gpubridge").c_str(), 0700);
    ASSERT_EQ(::chown((xdg / "gpubridge").c_str(), kNobody, kNobody), 0);
    const auto r = start_default(xdg);
    EXPECT_EQ(r.exit_code, 1) << r.err;
    EXPECT_NE(r.err.find("owned by uid " + std::to_string(kNobody)), std::string::npos) << r.err;
  }
  // Absent: created 0700 and served.
  const auto xdg = dir_ / "fresh";
  fs::create_directories(xdg);
  ASSERT_TRUE(daemon_.start({"--backend", "fake", "--log-level", "warn"}, {"XDG_RUNTIME_DIR=" + xdg.string()}))
      << daemon_.error();
  struct stat st{};
  ASSERT_EQ(::lstat((xdg / "gpubridge").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0700u);
}

// Item 6: a symlink planted as the lock file is not followed (the daemon would create or lock a
// file wherever it points).
TEST_F(DaemonIsolation, APlantedLockSymlinkIsNotFollowed) {
  const auto socket = dir_ / "d.sock";
  fs::create_symlink(dir_ / "victim", socket.string() + ".lock");
  const auto r = run_process({GPUBRIDGED_PATH, "--listen", "unix:" + socket.string(), "--backend", "fake"}, 5s);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find(socket.string() + ".lock"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "victim")) << "the daemon created the symlink's target";
}

// Item 6, the hijack: another user owns the runtime directory and serves a daemon there. Our daemon
// refuses the directory, and our clients refuse to talk to the other user's daemon (SO_PEERCRED)
// unless told to trust that uid with GPUBRIDGE_DAEMON_UID.
TEST_F(DaemonIsolation, ClientsRefuseADaemonOfAnotherUser) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to run a daemon as another user";
  const auto xdg = dir_ / "xdg";
  fs::create_directories(xdg / "gpubridge");
  ::chmod(dir_.c_str(), 0755);
  ::chmod(xdg.c_str(), 0755);
  ::chmod((xdg / "gpubridge").c_str(), 0700);
  ASSERT_EQ(::chown((xdg / "gpubridge").c_str(), kNobody, kNobody), 0);
  // The other user's daemon, on what is our default socket path.
  ASSERT_TRUE(daemon_.start({"--backend", "fake", "--log-level", "warn"}, {"XDG_RUNTIME_DIR=" + xdg.string()}, kNobody))
      << daemon_.error();
  const std::vector<std::string> env{"XDG_RUNTIME_DIR=" + xdg.string(), "GPUBRIDGE_DAEMON_UID="};
  const auto refused = run_process({GPUBRIDGE_CLI_PATH, "status"}, 10s, env);
  EXPECT_EQ(refused.exit_code, 1) << refused.out << refused.err;
  EXPECT_NE(refused.err.find("uid " + std::to_string(kNobody)), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("GPUBRIDGE_DAEMON_UID"), std::string::npos) << refused.err;
  const auto trusted =
      run_process({GPUBRIDGE_CLI_PATH, "status"}, 10s, {"XDG_RUNTIME_DIR=" + xdg.string(), "GPUBRIDGE_DAEMON_UID=65534"});
  EXPECT_EQ(trusted.exit_code, 0) << trusted.err;
  // And our own daemon does not start in their directory.
  const auto ours = start_default(xdg);
  EXPECT_EQ(ours.exit_code, 1) << ours.err;
}

// Item 7: reads, releases and fences of a client without the lease change nothing the holder sees:
// no error flag from an undefined register, no frame folded into the holder's strict link group,
// no release of someone else's lease.
TEST_F(DaemonIsolation, AClientWithoutTheLeaseCannotChangeWhatTheHolderSees) {
  const auto socket = dir_ / "d.sock";
  ASSERT_TRUE(daemon_.start({"--listen", "unix:" + socket.string(), "--backend", "sim", "--log-level", "warn"}))
      << daemon_.error();
  auto holder = client::Client::connect("unix:" + socket.string(), 2000ms);
  ASSERT_TRUE(holder);
  ASSERT_TRUE(holder->handshake("holder", "", 2000ms));
  ASSERT_TRUE(holder->acquire_lease(LeaseMode::Wait, 2000ms));
  auto other = client::Client::connect("unix:" + socket.string(), 2000ms);
  ASSERT_TRUE(other);
  ASSERT_TRUE(other->handshake("other", "", 2000ms));

  // An undefined register (0x7C; 0x7D was one until protocol 1.4 made it CAPS2): refused for the
  // non-holder, and no ERR_BAD_REGISTER for the holder.
  EXPECT_FALSE(other->read_register(0x7C, 2000ms));
  // CAPS2 is a constant like ID and CAPS: answered without the lease (the simulator has a depth buffer)
  auto caps2 = other->read_register(protocol::index_of(Reg::CAPS2), 2000ms);
  ASSERT_TRUE(caps2);
  EXPECT_EQ(*caps2, 1u);
  auto status = holder->read_register(protocol::index_of(Reg::STATUS), 2000ms);
  ASSERT_TRUE(status);
  EXPECT_EQ(*status >> 48, 0u) << "the holder's STATUS.ERRORS changed";

  // A strict link group of the holder with the other client reading in the middle of it.
  std::vector<std::uint8_t> group;
  protocol::append(group, protocol::write_frame(Reg::CLEAR_COLOR, 0x11223344));
  protocol::append(group, protocol::write_frame(Reg::CLEAR_DEPTH, 0x123));
  std::vector<std::uint8_t> strict;
  protocol::append(strict, protocol::write_frame(Reg::LINK_CTRL, 1));
  ASSERT_TRUE(holder->write_frames(protocol::FrameView{strict}, 2000ms));
  ASSERT_TRUE(holder->write_frames(protocol::FrameView{group}, 2000ms));
  ASSERT_TRUE(holder->fence(2000ms));
  auto id = other->read_register(protocol::index_of(Reg::ID), 2000ms);  // ID is readable by anyone
  ASSERT_TRUE(id) << id.error().message;
  EXPECT_EQ(*id >> 32, 0x53504755u);  // "SPGU"
  (void)other->read_register(protocol::index_of(Reg::STATUS), 2000ms);
  (void)other->read_register(protocol::index_of(Reg::LINK_STATUS), 2000ms);
  std::vector<std::uint8_t> check;
  protocol::append(check, protocol::write_frame(Reg::LINK_CHECK, protocol::crc32(group)));
  ASSERT_TRUE(holder->write_frames(protocol::FrameView{check}, 2000ms));
  auto link = holder->read_register(protocol::index_of(Reg::LINK_STATUS), 2000ms);
  ASSERT_TRUE(link);
  EXPECT_EQ((*link >> 32) & 0xFFFF, 1u) << "GROUPS_OK: the holder's group did not match";
  EXPECT_EQ(*link >> 48, 0u) << "GROUPS_BAD: another client's read was folded into the holder's group";
  auto color = holder->read_register(protocol::index_of(Reg::CLEAR_COLOR), 2000ms);
  ASSERT_TRUE(color);
  EXPECT_EQ(*color, 0x11223344u) << "the held writes were not released";

  // LEASE_RELEASE and FENCE of the other client.
  auto release = other->release_lease(2000ms);
  ASSERT_FALSE(release) << "a client without the lease was told it released it";
  EXPECT_TRUE(client::is_protocol_error(release.error(), protocol::ErrorCode::NoLease)) << release.error().message;
  EXPECT_TRUE(other->fence(2000ms));
  auto s = other->status(2000ms);
  ASSERT_TRUE(s);
  EXPECT_EQ(nlohmann::json::parse(*s)["lease"]["name"], "holder");
  status = holder->read_register(protocol::index_of(Reg::STATUS), 2000ms);
  ASSERT_TRUE(status);
  EXPECT_EQ(*status >> 48, 0u);
}

}  // namespace
}  // namespace gpubridge::test
