// Hostile soak of gpubridged (issue 14), run by hand: scripts/soak-daemon.sh [--minutes N].
//
// One gpubridged on the simulator, started as the README starts it (the default socket, here under a
// private XDG_RUNTIME_DIR) plus a loopback TCP listener with a token. For the whole run, every hostile
// and careless client of issue 14 works at once: RGBA8888 subscribers that never read, pipelined
// STATUS and READBACK floods, clients that hand the device a 16 MiB batch and hang up, silent TCP
// squatters, wrong tokens, garbage, slowloris, connection churn, subscribers that ignore keepalives,
// and clients without the lease reading undefined registers and releasing someone else's lease.
// Beside them one good client loops: `gpubridge play` of an animation (frames flow for the hostile
// subscribers), then `gpubridge screenshot` while `gpubridge play TRACE` draws one frame; every
// screenshot must equal `gpubridge render TRACE` bit for bit. The daemon's RSS and open descriptors are
// sampled throughout; the run ends with SIGTERM, which must exit 0 within 2 s.
//
// Exit 0 when every check held; the figures are printed either way.
#include <signal.h>
#include <sys/stat.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "daemon_process.hpp"
#include "gpubridge/client/client.hpp"
#include "gpubridge/common/image.hpp"
#include "hostile_clients.hpp"

namespace gpubridge::test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

struct Options {
  double minutes = 10;
  std::string trace;  // the good client's single-frame trace
};

// The 1-minute load average, to read the latency figures against.
std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string first;
  in >> first;
  return first.empty() ? "unknown" : first;
}

struct Sample {
  double t;
  long rss_kib, fds;
};

class Soak {
 public:
  explicit Soak(Options o) : o_(std::move(o)) {}
  int run();

 private:
  // Runs `body` in a loop on its own thread until the end of the soak, counting rounds.
  void hostile(const char* name, std::function<void(std::mt19937&)> body) {
    threads_.emplace_back([this, name, body = std::move(body)] {
      std::mt19937 rng(static_cast<unsigned>(std::hash<std::string>{}(name)));
      std::uint64_t rounds = 0;
      while (!stop_) {
        body(rng);
        ++rounds;
      }
      std::lock_guard lock(mu_);
      rounds_.emplace_back(name, rounds);
    });
  }
  void sleep_for(std::chrono::milliseconds d) {
    const auto end = Clock::now() + d;
    while (!stop_ && Clock::now() < end) std::this_thread::sleep_for(std::min<Clock::duration>(end - Clock::now(), 50ms));
  }
  RawSocket unix_socket() { return RawSocket(socket_); }
  RawSocket tcp_socket() { return RawSocket("127.0.0.1", port_); }
  void start_hostiles();
  bool good_round(std::string& why);
  std::vector<std::string> cli(std::vector<std::string> args) const {
    args.insert(args.begin(), GPUBRIDGE_CLI_PATH);
    return args;
  }

  Options o_;
  fs::path dir_;
  std::string socket_, tcp_;
  std::uint16_t port_ = 0;
  std::vector<std::string> env_;
  Daemon daemon_;
  std::atomic<bool> stop_{false};
  std::vector<std::thread> threads_;
  std::mutex mu_;
  std::vector<std::pair<std::string, std::uint64_t>> rounds_;
  std::vector<std::uint8_t> expected_rgba_;
  unsigned expected_w_ = 0, expected_h_ = 0;
  double hello_ms_max_ = 0;  // the good observer's slowest HELLO -> WELCOME
};

void Soak::start_hostiles() {
  const std::string token = "soak-token";
  // Item 1: subscribers asking for a converted format that never read a byte.
  hostile("lazy RGBA8888 subscribers", [this](std::mt19937&) {
    std::vector<RawSocket> lazy;
    for (int i = 0; i < 4; ++i) {
      lazy.push_back(unix_socket());
      auto bytes = hello_message("lazy");
      add_message(bytes, 2, protocol::Subscribe{protocol::FrameFormat::RGBA8888, 0});
      lazy.back().send_some(bytes);
    }
    sleep_for(330s);  // past idle_timeout_ms (300 s): the daemon closes them once their writes stall
  });
  // Item 3: pipelined STATUS requests, never reading the replies.
  hostile("STATUS flood", [this](std::mt19937&) {
    auto s = unix_socket();
    auto bytes = hello_message("status-flood");
    const auto reqs = repeated(200000, protocol::StatusReq{});
    bytes.insert(bytes.end(), reqs.begin(), reqs.end());
    std::size_t sent = 0;
    const auto end = Clock::now() + 4s;
    while (!stop_ && Clock::now() < end && sent < bytes.size()) {
      sent += s.send_some(bytes, sent);
      std::this_thread::sleep_for(20ms);
    }
  });
  // Item 3: 100 pipelined 8 MiB READBACKs, never reading; holds the lease until it hangs up.
  hostile("READBACK flood", [this](std::mt19937&) {
    auto s = unix_socket();
    auto bytes = hello_message("readback-flood");
    add_message(bytes, 2, protocol::LeaseAcquire{protocol::LeaseMode::Wait});
    const auto reads = repeated(100, protocol::Readback{0, 8u << 20});
    bytes.insert(bytes.end(), reads.begin(), reads.end());
    s.send_some(bytes);
    sleep_for(3s);
    s.close();
    sleep_for(5s);
  });
  // Items 2 and 4: a 16 MiB batch (minutes of full-screen clears) and a client that hangs up.
  const auto batch = std::make_shared<Bytes>([] {
    Bytes b = long_batch(16u << 20);
    // No swaps: only the good client's frames reach subscribers, so its screenshots are its own.
    for (std::size_t i = 0; i < b.size(); i += protocol::kFrameBytes)
      if ((b[i] & 0x7F) == protocol::index_of(protocol::Reg::FB_DISPLAY)) b[i] = protocol::index_of(protocol::Reg::CLEAR);
    return b;
  }());
  hostile("batch and hang up", [this, batch](std::mt19937& rng) {
    auto c = client::Client::connect(rng() % 2 ? "unix:" + socket_ : tcp_, 2000ms);
    if (!c || !c->handshake("quitter", "soak-token", 2000ms)) return sleep_for(1s);
    if (!c->acquire_lease(protocol::LeaseMode::Wait, 30000ms)) return;
    (void)c->write_frames(protocol::FrameView{*batch}, 10000ms);
    sleep_for(300ms);
  });
  // Item 5: silent TCP peers squatting connection slots.
  hostile("silent TCP squatters", [this](std::mt19937&) {
    std::vector<RawSocket> squatters;
    for (int i = 0; i < 40; ++i) squatters.push_back(tcp_socket());
    sleep_for(5s);
  });
  // Item 5: subscribers that never answer the keepalive.
  hostile("deaf subscribers", [this, token](std::mt19937&) {
    std::vector<RawSocket> deaf;
    for (int i = 0; i < 3; ++i) {
      deaf.push_back(tcp_socket());
      auto bytes = hello_message("deaf", token);
      add_message(bytes, 2, protocol::Subscribe{protocol::FrameFormat::Native, 0});
      deaf.back().send_some(bytes);
    }
    sleep_for(330s);  // past idle_timeout_ms: the daemon's keepalive closes them first
  });
  hostile("wrong tokens", [this](std::mt19937&) {
    auto s = tcp_socket();
    s.send_some(hello_message("guess", "not-the-token"));
    (void)s.read_until_closed(2000ms);
    sleep_for(20ms);
  });
  hostile("garbage", [this](std::mt19937& rng) {
    auto s = rng() % 2 ? unix_socket() : tcp_socket();
    Bytes junk(1 + rng() % 2048);
    for (auto& b : junk) b = static_cast<std::uint8_t>(rng());
    s.send_some(junk);
    (void)s.read_until_closed(1000ms);
  });
  hostile("slowloris", [this](std::mt19937&) {
    auto s = unix_socket();
    const auto h = hello_message("slow");
    for (std::size_t i = 0; i < h.size() && !stop_; ++i) {
      if (s.send_some(Bytes{h[i]}) != 1) break;
      sleep_for(1000ms);
    }
  });
  hostile("connection churn", [this](std::mt19937& rng) {
    for (int i = 0; i < 200 && !stop_; ++i) {
      auto s = rng() % 2 ? unix_socket() : tcp_socket();
      if (i % 2) s.send_some(hello_message("churn", "soak-token"));
    }
    sleep_for(100ms);
  });
  // Item 7: clients without the lease poking at the holder's device.
  hostile("non-holders", [this](std::mt19937&) {
    auto c = client::Client::connect("unix:" + socket_, 2000ms);
    if (!c || !c->handshake("nosy", "", 2000ms)) return sleep_for(1s);
    for (int i = 0; i < 50 && !stop_; ++i) {
      (void)c->read_register(0x7C, 2000ms);  // undefined (0x7D is CAPS2 since protocol 1.4)
      (void)c->read_register(protocol::index_of(protocol::Reg::STATUS), 2000ms);
      (void)c->read_register(protocol::index_of(protocol::Reg::LINK_STATUS), 2000ms);
      (void)c->release_lease(2000ms);
      (void)c->fence(2000ms);
      sleep_for(20ms);
    }
  });
}

// One round of the good client: an animation, then a screenshot of one frame of TRACE.
bool Soak::good_round(std::string& why) {
  const auto anim = run_process(cli({"play", (dir_ / "anim.trace").string(), "--repeat", "20"}), 300s, env_);
  if (anim.exit_code != 0) return (why = "play anim.trace: " + anim.err, false);
  const auto shot_path = dir_ / "shot.png";
  fs::remove(shot_path);
  Child shot;
  if (!shot.start(cli({"screenshot", "--out", shot_path.string(), "--timeout", "120000"}), env_))
    return (why = "cannot start screenshot", false);
  // The screenshot client has subscribed once the daemon lists a "gpubridge screenshot" subscriber.
  auto c = client::Client::connect("", 2000ms);
  if (!c) return (why = "observer cannot connect: " + c.error().message, false);
  // The library's default timeout, as the CLI uses: on a loaded machine a HELLO under this flood takes
  // seconds (the daemon's thread waits for a core), which the summary reports.
  const auto t0 = Clock::now();
  if (auto hs = c->handshake("good-observer"); !hs)
    return (why = "observer's HELLO refused: " + hs.error().message, false);
  hello_ms_max_ = std::max(hello_ms_max_, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  bool subscribed = false;
  const auto give_up = Clock::now() + 60s;
  while (!subscribed && Clock::now() < give_up) {
    auto s = c->status(5000ms);
    if (!s) return (why = "status: " + s.error().message, false);
    const auto status = nlohmann::json::parse(*s);  // named: range-for over a temporary's member dangles
    for (const auto& cl : status["clients"])
      subscribed |= cl["name"] == "gpubridge screenshot" && cl["subscribed"].get<bool>();
    if (!subscribed) std::this_thread::sleep_for(10ms);
  }
  if (!subscribed) return (why = "the screenshot did not subscribe within 60 s: " + shot.err(), false);
  const auto play = run_process(cli({"play", o_.trace}), 300s, env_);
  if (play.exit_code != 0) return (why = "play: " + play.err, false);
  if (const int code = shot.wait(130s); code != 0) return (why = "screenshot: " + shot.err(), false);
  auto img = load_png(shot_path);
  if (!img) return (why = img.error().message, false);
  if (img->width != expected_w_ || img->height != expected_h_ || img->rgba != expected_rgba_)
    return (why = "screenshot differs from `gpubridge render` of the trace", false);
  return true;
}

int Soak::run() {
  dir_ = make_temp_dir("soak");
  ::chmod(dir_.c_str(), 0700);
  fs::create_directories(dir_ / "xdg");
  ::chmod((dir_ / "xdg").c_str(), 0700);
  env_ = {"XDG_RUNTIME_DIR=" + (dir_ / "xdg").string(), "GPUBRIDGE_TOKEN=soak-token"};
  ::setenv("XDG_RUNTIME_DIR", (dir_ / "xdg").c_str(), 1);
  socket_ = (dir_ / "xdg" / "gpubridge" / "gpubridge.sock").string();
  write_animation_trace(dir_ / "anim.trace");

  // The reference: the trace rendered in-process by the CLI.
  const auto rendered = run_process(cli({"render", o_.trace, "--out", (dir_ / "render.png").string()}), 120s);
  auto ref = load_png(dir_ / "render.png");
  if (rendered.exit_code != 0 || !ref) {
    std::fprintf(stderr, "soak: gpubridge render %s failed: %s\n", o_.trace.c_str(), rendered.err.c_str());
    return 2;
  }
  expected_rgba_ = ref->rgba;
  expected_w_ = ref->width;
  expected_h_ = ref->height;

  if (!daemon_.start({"--backend", "sim", "--listen", "unix:", "--listen", "tcp:127.0.0.1:0", "--token", "soak-token",
                      "--log-level", "warn"},
                     {env_[0]})) {
    std::fprintf(stderr, "soak: gpubridged did not start: %s\n", daemon_.error().c_str());
    return 2;
  }
  for (const auto& e : daemon_.endpoints())
    if (e.rfind("tcp:", 0) == 0) tcp_ = e;
  port_ = static_cast<std::uint16_t>(std::stoi(tcp_.substr(tcp_.rfind(':') + 1)));
  std::printf("soak: gpubridged pid %d on %s and %s, %.1f minutes\n", daemon_.pid(), socket_.c_str(), tcp_.c_str(),
              o_.minutes);
  std::fflush(stdout);

  const auto t0 = Clock::now();
  const auto end = t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o_.minutes * 60));
  std::vector<Sample> samples;
  auto sample = [&] {
    samples.push_back({std::chrono::duration<double>(Clock::now() - t0).count(), daemon_.rss_kib(), daemon_.fd_count()});
  };
  sample();
  start_hostiles();
  std::thread sampler([&] {
    while (!stop_) {
      std::this_thread::sleep_for(1s);
      std::lock_guard lock(mu_);
      sample();
    }
  });

  std::uint64_t rounds = 0, failures = 0;
  std::string first_failure;
  while (Clock::now() < end) {
    std::string why;
    if (good_round(why)) {
      ++rounds;
    } else {
      ++failures;
      if (first_failure.empty()) first_failure = why;
      std::fprintf(stderr, "soak: good client round failed: %s\n", why.c_str());
    }
    if (daemon_.has_exited()) break;
  }
  const bool alive = !daemon_.has_exited();

  // SIGTERM with every hostile client still connected.
  const auto term0 = Clock::now();
  const int code = alive ? daemon_.terminate(10s) : -1;
  const double term_ms = std::chrono::duration<double, std::milli>(Clock::now() - term0).count();
  stop_ = true;
  sampler.join();
  for (auto& t : threads_) t.join();

  // Figures: the first minute's peak against the last minute's (the daemon warms up its allocator
  // and framebuffers in the first seconds).
  auto window = [&](double from, double to) {
    Sample peak{0, 0, 0};
    for (const auto& s : samples)
      if (s.t >= from && s.t < to) peak = {s.t, std::max(peak.rss_kib, s.rss_kib), std::max(peak.fds, s.fds)};
    return peak;
  };
  const double total = samples.empty() ? 0 : samples.back().t;
  const Sample start = samples.front();
  const Sample first = window(0, std::min(60.0, total / 2));
  const Sample last = window(std::max(total - 60.0, total / 2), total + 1);
  long rss_max = 0, fds_max = 0;
  for (const auto& s : samples) {
    rss_max = std::max(rss_max, s.rss_kib);
    fds_max = std::max(fds_max, s.fds);
  }
  std::printf("soak: %.1f s, %llu good rounds (play + screenshot == render), %llu failed\n", total,
              static_cast<unsigned long long>(rounds), static_cast<unsigned long long>(failures));
  std::printf("soak: the good client's slowest HELLO -> WELCOME: %.0f ms (load average %s)\n", hello_ms_max_,
              load_average().c_str());
  std::printf("soak: RSS at start %ld KiB, peak of the first minute %ld KiB, peak of the last minute %ld KiB, "
              "overall peak %ld KiB\n",
              start.rss_kib, first.rss_kib, last.rss_kib, rss_max);
  std::printf("soak: open fds at start %ld, peak of the first minute %ld, peak of the last minute %ld, overall peak %ld\n",
              start.fds, first.fds, last.fds, fds_max);
  std::printf("soak: SIGTERM -> exit %d after %.0f ms\n", code, term_ms);
  for (const auto& [name, n] : rounds_) std::printf("soak:   hostile %-28s %llu rounds\n", name.c_str(), static_cast<unsigned long long>(n));
  if (!first_failure.empty()) std::printf("soak: first failure: %s\n", first_failure.c_str());

  // Pass: every round of the good client held, memory and descriptors did not grow from the first
  // minute to the last (16 MiB and 16 fds of slack for allocator and timing noise), clean SIGTERM.
  const bool flat = last.rss_kib <= first.rss_kib + 16 * 1024 && last.fds <= first.fds + 16;
  const bool ok = alive && failures == 0 && rounds > 0 && flat && code == 0 && term_ms < 2000;
  std::printf("soak: %s\n", ok ? "PASS" : "FAIL");
  std::error_code ec;
  if (ok) fs::remove_all(dir_, ec);
  return ok ? 0 : 1;
}

}  // namespace
}  // namespace gpubridge::test

int main(int argc, char** argv) {
  gpubridge::test::Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--minutes" && i + 1 < argc) o.minutes = std::atof(argv[++i]);
    else if (a == "--trace" && i + 1 < argc) o.trace = argv[++i];
    else {
      std::fprintf(stderr, "usage: daemon_soak --trace TRACE [--minutes N]\n");
      return 2;
    }
  }
  if (o.trace.empty() || !(o.minutes > 0)) {
    std::fprintf(stderr, "usage: daemon_soak --trace TRACE [--minutes N]\n");
    return 2;
  }
  ::signal(SIGPIPE, SIG_IGN);
  return gpubridge::test::Soak(o).run();
}
