// The session's parts on their own (issue 16 item 3: the bounded outgoing queue, the frame
// subscription, the lease, the socket directory check, the daemon-owner check), and the session's
// per-message bound on a stream whose client never reads.
#include <gtest/gtest.h>

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <random>
#include <thread>

#include "gpubridge/client/client.hpp"
#include "gpubridge/client/daemon_owner.hpp"
#include "gpubridge/daemon/frame_subscription.hpp"
#include "gpubridge/daemon/hub.hpp"
#include "gpubridge/daemon/lease.hpp"
#include "gpubridge/daemon/outgoing_queue.hpp"
#include "gpubridge/daemon/session.hpp"
#include "gpubridge/daemon/socket_dir.hpp"
#include "gpubridge/daemon/test_backends.hpp"

namespace gpubridge::daemon {
namespace {

using namespace std::chrono_literals;
using protocol::Message;
namespace fs = std::filesystem;

OutgoingQueue::Buffer bytes_of(std::size_t n) { return std::make_shared<std::vector<std::uint8_t>>(n, 0); }

TEST(OutgoingQueue, CountsBytesUntilTheirWriteCompletes) {
  OutgoingQueue q(1000);
  q.push(bytes_of(600));
  EXPECT_FALSE(q.full());
  EXPECT_TRUE(q.has_room(400));
  EXPECT_FALSE(q.has_room(401));
  q.push(bytes_of(600));  // a reply is never refused: the bound stops the next message instead
  EXPECT_TRUE(q.full());
  std::vector<OutgoingQueue::Buffer> batch;
  EXPECT_EQ(q.take(batch, 64, 700), 600u);  // the second would pass max_bytes
  EXPECT_EQ(batch.size(), 1u);
  EXPECT_TRUE(q.full()) << "taken bytes count until written";
  q.written(600);
  EXPECT_FALSE(q.full());
  EXPECT_EQ(q.bytes(), 600u);
  batch.clear();
  EXPECT_EQ(q.take(batch, 64, 10), 600u) << "the first message goes even when larger than max_bytes";
  EXPECT_TRUE(q.empty());
}

// A FrameFanout of a 4x2 RGBA8888 frame.
std::shared_ptr<FrameFanout> swap(std::uint32_t number) {
  auto f = std::make_shared<backends::ScanoutFrame>();
  f->number = number;
  f->width = 4;
  f->height = 2;
  f->pixels.assign(32, static_cast<std::uint8_t>(number));
  return std::make_shared<FrameFanout>(std::move(f));
}

std::uint32_t frame_number(const FrameFanout::Buffer& message) {
  protocol::MessageParser p;
  p.feed(*message);
  Message m;
  EXPECT_EQ(p.next(m), protocol::MessageParser::Status::Ok);
  return std::get<protocol::FrameData>(m.payload).number;
}

TEST(FrameSubscription, HoldsOnlyTheNewestSwapAndEncodesItWhenTaken) {
  FrameSubscription s;
  const auto t0 = FrameSubscription::Clock::now();
  std::optional<FrameSubscription::Clock::time_point> due;
  s.offer(swap(1));
  EXPECT_EQ(s.take(t0, due), nullptr) << "not subscribed yet: swaps are not kept";
  s.subscribe(protocol::FrameFormat::RGB565, protocol::FrameSource::Board, 0);
  auto first = swap(2), second = swap(3);
  s.offer(first);
  s.offer(second);
  auto m = s.take(t0, due);
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(frame_number(m), 3u) << "latest wins";
  EXPECT_EQ(second->message(protocol::FrameSource::Board, protocol::FrameFormat::RGB565), m)
      << "the encoding is made once and shared";
  EXPECT_EQ(s.take(t0, due), nullptr);
  EXPECT_FALSE(due);
}

TEST(FrameSubscription, RateLimitKeepsTheNewestUntilTheIntervalEnds) {
  FrameSubscription s;
  s.subscribe(protocol::FrameFormat::Native, protocol::FrameSource::Board, 10);  // 100 ms
  const auto t0 = FrameSubscription::Clock::now();
  std::optional<FrameSubscription::Clock::time_point> due;
  s.offer(swap(1));
  ASSERT_NE(s.take(t0, due), nullptr);
  s.offer(swap(2));
  s.offer(swap(3));
  EXPECT_EQ(s.take(t0 + 50ms, due), nullptr);
  ASSERT_TRUE(due);
  EXPECT_EQ(*due, t0 + 100ms);
  auto m = s.take(*due, due);
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(frame_number(m), 3u);
}

struct LeaseLog {
  std::vector<std::function<void()>> resets;  // pending device resets, finished by the test
  std::vector<std::uint32_t> granted;
  Lease lease{[this](std::function<void()> done) { resets.push_back(std::move(done)); },
              [this](std::uint32_t id) {
                granted.push_back(id);
                return true;
              }};
};

TEST(Lease, AReleasedOrTouchedLeaseIsHandedOnOnlyAfterAReset) {
  LeaseLog l;
  EXPECT_EQ(l.lease.acquire(1, protocol::LeaseMode::Wait), Lease::Outcome::Granted);
  EXPECT_EQ(l.lease.acquire(2, protocol::LeaseMode::FailIfBusy), Lease::Outcome::Busy);
  EXPECT_EQ(l.lease.acquire(2, protocol::LeaseMode::Wait), Lease::Outcome::Queued);
  EXPECT_FALSE(l.lease.release(3)) << "a client without the lease releases nothing";
  EXPECT_TRUE(l.lease.held_by(1));
  EXPECT_TRUE(l.lease.release(1));
  ASSERT_EQ(l.resets.size(), 1u);
  EXPECT_TRUE(l.granted.empty()) << "granted before the reset finished";
  l.resets[0]();
  EXPECT_EQ(l.granted, std::vector<std::uint32_t>{2});
  EXPECT_TRUE(l.lease.release(2));
  l.resets[1]();
  EXPECT_TRUE(l.lease.idle());
  // A reader without the lease went through the device while it was idle: the next holder waits
  // for a reset, even with FailIfBusy (nobody holds it).
  l.lease.touched();
  EXPECT_EQ(l.lease.acquire(4, protocol::LeaseMode::FailIfBusy), Lease::Outcome::Queued);
  ASSERT_EQ(l.resets.size(), 3u);
  l.resets[2]();
  EXPECT_EQ(l.granted.back(), 4u);
}

fs::path temp_dir(const std::string& tag) {
  std::random_device rd;
  const fs::path dir = fs::temp_directory_path() / ("gbd-" + tag + "-" + std::to_string(rd() % 1000000));
  fs::create_directories(dir);
  return dir;
}

TEST(SocketDirectory, OnlyAPrivateDirectoryOfOursIsAccepted) {
  const auto dir = temp_dir("sockdir");
  const uid_t me = ::geteuid();
  auto fresh = open_socket_directory(dir / "run", true, me);
  ASSERT_TRUE(fresh) << fresh.error().message;
  ::close(*fresh);
  struct stat st{};
  ASSERT_EQ(::stat((dir / "run").c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0700u);
  auto theirs = open_socket_directory(dir / "run", true, me + 1);
  ASSERT_FALSE(theirs);
  EXPECT_NE(theirs.error().message.find("is owned by uid " + std::to_string(me) + ", not by you"), std::string::npos)
      << theirs.error().message;
  ::chmod((dir / "run").c_str(), 0750);
  auto wide = open_socket_directory(dir / "run", true, me);
  ASSERT_FALSE(wide);
  EXPECT_NE(wide.error().message.find("has mode 0750"), std::string::npos) << wide.error().message;
  // A directory named with --listen: group-readable is fine, writable by others is not unless sticky.
  EXPECT_TRUE(open_socket_directory(dir / "run", false, me));
  ::chmod((dir / "run").c_str(), 0777);
  EXPECT_FALSE(open_socket_directory(dir / "run", false, me));
  ::chmod((dir / "run").c_str(), 01777);
  EXPECT_TRUE(open_socket_directory(dir / "run", false, me));
  fs::remove_all(dir);
}

TEST(DaemonOwner, APeerOfAnotherUidIsRefusedUnlessTrusted) {
  int fds[2];
  ASSERT_EQ(::socketpair(AF_UNIX, SOCK_STREAM, 0, fds), 0);
  const unsigned me = ::geteuid();
  EXPECT_TRUE(client::check_daemon_owner(fds[0], "unix:x", me, -1));
  if (me != 0) {
    // Pretending to be someone else: our own peer is then "another user" (root is always trusted).
    auto r = client::check_daemon_owner(fds[0], "unix:x", me + 1, -1);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().message.find("GPUBRIDGE_DAEMON_UID=" + std::to_string(me)), std::string::npos) << r.error().message;
    EXPECT_TRUE(client::check_daemon_owner(fds[0], "unix:x", me + 1, me));
  }
  ::close(fds[0]);
  ::close(fds[1]);
}

// A daemon whose listen queue is full (busy, or flooded) makes a Unix connect fail with EAGAIN: the
// client waits for room until its timeout instead of taking the unconnected socket for a connection
// (it then reported a daemon of uid 4294967295, or failed its first send).
TEST(ClientConnect, AFullListenQueueIsWaitedForNotMistakenForAConnection) {
  const auto dir = temp_dir("backlog");
  const auto path = (dir / "q.sock").string();
  const int listener = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_un sa{};
  sa.sun_family = AF_UNIX;
  std::strncpy(sa.sun_path, path.c_str(), sizeof sa.sun_path - 1);
  ASSERT_EQ(::bind(listener, reinterpret_cast<sockaddr*>(&sa), sizeof sa), 0);
  ASSERT_EQ(::listen(listener, 0), 0);
  std::vector<int> queued;  // fill the queue
  for (int i = 0; i < 4; ++i) {
    const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&sa), sizeof sa) != 0) {
      ::close(fd);
      break;
    }
    queued.push_back(fd);
  }
  ASSERT_FALSE(queued.empty());
  auto c = client::Client::connect("unix:" + path, 200ms);
  ASSERT_FALSE(c) << "connected through a full listen queue";
  EXPECT_EQ(c.error().code, client::kTimeoutError) << c.error().message;
  // Room appears while the client waits: it connects.
  std::thread accept_later([listener] {
    std::this_thread::sleep_for(100ms);
    ::close(::accept(listener, nullptr, nullptr));
  });
  auto later = client::Client::connect("unix:" + path, 2000ms);
  accept_later.join();
  EXPECT_TRUE(later) << later.error().message;
  for (int fd : queued) ::close(fd);
  ::close(listener);
  fs::remove_all(dir);
}

// A stream whose client never reads: writes never complete.
class StalledStream final : public Stream {
 public:
  StalledStream(boost::asio::any_io_executor ex, std::vector<std::uint8_t> input) : ex_(std::move(ex)), input_(std::move(input)) {}
  void async_read_some(boost::asio::mutable_buffer buf, Handler handler) override {
    const std::size_t n = std::min(buf.size(), input_.size() - pos_);
    std::memcpy(buf.data(), input_.data() + pos_, n);
    pos_ += n;
    if (n) boost::asio::post(ex_, [handler = std::move(handler), n] { handler({}, n); });
    else pending_read_ = std::move(handler);  // then silence: the client waits for its replies
  }
  void async_write(const std::vector<boost::asio::const_buffer>& bufs, Handler handler) override {
    for (const auto& b : bufs) written_ += b.size();
    pending_write_ = std::move(handler);  // never completes
  }
  void close() override {}
  std::string transport() const override { return "memory"; }
  std::string peer() const override { return "stalled"; }
  std::size_t written_ = 0;

 private:
  boost::asio::any_io_executor ex_;
  std::vector<std::uint8_t> input_;
  std::size_t pos_ = 0;
  Handler pending_read_, pending_write_;
};

// 64 pipelined READBACKs of 1 MiB and 5,000 STATUS requests from a client that reads nothing:
// replies stay within queue_bytes, because the bound is checked per message and READBACK is streamed.
TEST(DaemonSession, PipelinedRepliesStayWithinQueueBytes) {
  boost::asio::io_context io;
  HubOptions opts;
  opts.limits.queue_bytes = 1u << 20;
  Hub hub(io.get_executor(), io.get_executor(), std::make_unique<FakeScanoutBackend>(8, 8, 1u << 20), opts);
  std::vector<std::uint8_t> in;
  protocol::encode(Message{1, protocol::Hello{protocol::kSocketVersion, "flood", ""}}, in);
  protocol::encode(Message{2, protocol::LeaseAcquire{protocol::LeaseMode::FailIfBusy}}, in);
  for (std::uint32_t i = 0; i < 64; ++i) protocol::encode(Message{3 + i, protocol::Readback{0, 1u << 20}}, in);
  for (std::uint32_t i = 0; i < 5000; ++i) protocol::encode(Message{100 + i, protocol::StatusReq{}}, in);
  auto stream = std::make_unique<StalledStream>(io.get_executor(), in);
  auto* raw = stream.get();
  auto session = std::make_shared<Session>(hub, std::move(stream), io.get_executor());
  session->start();
  io.run_for(1s);
  // Steps of half of queue_bytes, each started only when it fits: one step is queued, the second
  // waits for room that never comes, and nothing after the first READBACK is executed meanwhile.
  const std::uint64_t step = 512u << 10;
  EXPECT_GE(session->outgoing().bytes(), step);
  EXPECT_LE(session->outgoing().bytes(), 1u << 20) << "queued beyond the bound";
  EXPECT_LE(raw->written_, 1u << 20);
}

// A client that reads its replies, but slowly: every write completes after `delay`.
class SlowReaderStream final : public Stream {
 public:
  SlowReaderStream(boost::asio::any_io_executor ex, std::vector<std::uint8_t> input, std::chrono::milliseconds delay)
      : ex_(ex), timer_(ex), input_(std::move(input)), delay_(delay) {}
  void async_read_some(boost::asio::mutable_buffer buf, Handler handler) override {
    const std::size_t n = std::min(buf.size(), input_.size() - pos_);
    std::memcpy(buf.data(), input_.data() + pos_, n);
    pos_ += n;
    if (n) boost::asio::post(ex_, [handler = std::move(handler), n] { handler({}, n); });
    else pending_read_ = std::move(handler);  // everything sent: the client waits for its replies
  }
  void async_write(const std::vector<boost::asio::const_buffer>& bufs, Handler handler) override {
    std::size_t n = 0;
    for (const auto& b : bufs) {
      const auto* p = static_cast<const std::uint8_t*>(b.data());
      written_.insert(written_.end(), p, p + b.size());
      n += b.size();
    }
    timer_.expires_after(delay_);
    timer_.async_wait([handler = std::move(handler), n](const boost::system::error_code&) { handler({}, n); });
  }
  void close() override { timer_.cancel(); }
  std::string transport() const override { return "memory"; }
  std::string peer() const override { return "slow reader"; }
  std::vector<std::uint8_t> written_;

 private:
  boost::asio::any_io_executor ex_;
  boost::asio::steady_timer timer_;
  std::vector<std::uint8_t> input_;
  std::size_t pos_ = 0;
  std::chrono::milliseconds delay_;
  Handler pending_read_;
};

// While the replies are over queue_bytes the daemon does not read: the client's silence and the
// rate of its unread messages then say nothing about it. A client that pipelines more replies than
// the bound and reads them slowly gets every one, instead of "message arriving too slowly" or "idle"
// after two trickle windows of the daemon's own not reading.
TEST(DaemonSession, AClientThrottledByQueueBytesIsNotTakenForATrickleOrIdle) {
  boost::asio::io_context io;
  HubOptions opts;
  opts.limits.queue_bytes = 64u << 10;
  opts.limits.trickle_window_ms = 50;
  opts.limits.idle_timeout_ms = 200;
  Hub hub(io.get_executor(), io.get_executor(), std::make_unique<FakeScanoutBackend>(8, 8, 1u << 20), opts);
  constexpr std::uint32_t kPings = 4000;  // 300 KB of PONGs: about 60 writes of 5 ms each
  std::vector<std::uint8_t> in;
  protocol::encode(Message{1, protocol::Hello{protocol::kSocketVersion, "slow reader", ""}}, in);
  for (std::uint32_t i = 0; i < kPings; ++i)
    protocol::encode(Message{2 + i, protocol::Ping{std::vector<std::uint8_t>(64, 0x5A)}}, in);
  auto stream = std::make_unique<SlowReaderStream>(io.get_executor(), in, 5ms);
  auto* raw = stream.get();
  auto session = std::make_shared<Session>(hub, std::move(stream), io.get_executor());  // keeps `raw` alive
  session->start();
  io.run_for(3s);
  protocol::MessageParser p;
  p.feed(raw->written_);
  std::vector<Message> out;
  for (Message m; p.next(m) == protocol::MessageParser::Status::Ok;) out.push_back(std::move(m));
  ASSERT_GE(out.size(), 1u + kPings);
  std::uint32_t pongs = 0;
  for (std::size_t i = 1; i <= kPings; ++i) {
    if (const auto* e = std::get_if<protocol::ErrorMsg>(&out[i].payload)) FAIL() << "after " << pongs << " PONGs: " << e->text;
    pongs += std::holds_alternative<protocol::Pong>(out[i].payload);
  }
  EXPECT_EQ(pongs, kPings);
}

}  // namespace
}  // namespace gpubridge::daemon
