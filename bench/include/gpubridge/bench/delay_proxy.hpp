#pragma once
// DelayProxy: a TCP proxy on 127.0.0.1 that makes loopback behave like a real network link, for
// tests (tests/daemon/daemon_remote_test.cpp) and `gpubridge bench remote`. Each direction of each
// connection delays every chunk it reads by `one_way` before passing it on, and passes at most
// `bytes_per_sec` (a token bucket; 0 = unlimited). A round trip through it takes 2 × one_way more.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <list>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace gpubridge::bench {

class DelayProxy {
 public:
  using Clock = std::chrono::steady_clock;
  DelayProxy(std::uint16_t target_port, std::chrono::microseconds one_way, std::uint64_t bytes_per_sec = 0)
      : target_(target_port), delay_(one_way), rate_(bytes_per_sec) {
    listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a = loopback(0);
    ::bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a);
    ::listen(listen_fd_, 16);
    socklen_t len = sizeof a;
    ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port_ = ntohs(a.sin_port);
    acceptor_ = std::thread([this] { accept_loop(); });
  }
  ~DelayProxy() {
    stop_ = true;
    ::shutdown(listen_fd_, SHUT_RDWR);
    acceptor_.join();
    ::close(listen_fd_);
    for (auto& p : pipes_) p->shutdown();
    for (auto& p : pipes_) p->join();
  }
  std::uint16_t port() const { return port_; }

 private:
  static sockaddr_in loopback(std::uint16_t port) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return a;
  }
  // One direction: a reader queues timestamped chunks, a writer sends each when it is due.
  struct Pipe {
    int from, to;
    std::chrono::microseconds delay;
    std::uint64_t rate;
    std::mutex m;
    std::condition_variable cv;
    std::deque<std::pair<Clock::time_point, std::vector<char>>> q;
    bool eof = false;
    std::thread reader, writer;
    void start() {
      reader = std::thread([this] {
        std::vector<char> buf(64 * 1024);
        for (;;) {
          const ssize_t n = ::recv(from, buf.data(), buf.size(), 0);
          std::lock_guard lk(m);
          if (n <= 0) { eof = true; cv.notify_all(); return; }
          q.emplace_back(Clock::now() + delay, std::vector<char>(buf.begin(), buf.begin() + n));
          cv.notify_all();
        }
      });
      writer = std::thread([this] {
        double tokens = 0;  // token bucket: bytes we may send now
        auto refilled = Clock::now();
        for (;;) {
          std::unique_lock lk(m);
          cv.wait(lk, [&] { return eof || !q.empty(); });
          if (q.empty()) break;
          auto [due, chunk] = std::move(q.front());
          q.pop_front();
          lk.unlock();
          std::this_thread::sleep_until(due);
          for (std::size_t off = 0; off < chunk.size();) {
            std::size_t n = chunk.size() - off;
            if (rate) {
              const auto now = Clock::now();
              tokens = std::min<double>(tokens + std::chrono::duration<double>(now - refilled).count() * rate, rate / 50.0 + 1);
              refilled = now;
              if (tokens < 1) { std::this_thread::sleep_for(std::chrono::microseconds(500)); continue; }
              n = std::min<std::size_t>(n, static_cast<std::size_t>(tokens));
            }
            const ssize_t w = ::send(to, chunk.data() + off, n, MSG_NOSIGNAL);
            if (w <= 0) { ::shutdown(from, SHUT_RDWR); return; }
            off += static_cast<std::size_t>(w);
            tokens -= static_cast<double>(w);
          }
        }
        ::shutdown(to, SHUT_WR);  // pass the end of stream on, after everything before it
      });
    }
    void shutdown() { ::shutdown(from, SHUT_RDWR); ::shutdown(to, SHUT_RDWR); }
    void join() {
      reader.join();
      writer.join();
      ::close(from);  // each socket is the "from" of exactly one pipe
    }
  };
  void accept_loop() {
    while (!stop_) {
      const int client = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (client < 0) return;
      const int server = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
      sockaddr_in a = loopback(target_);
      if (::connect(server, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) { ::close(client); ::close(server); continue; }
      const int one = 1;
      for (int fd : {client, server}) ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
      for (auto [from, to] : {std::pair{client, server}, std::pair{server, client}}) {
        auto p = std::make_unique<Pipe>();
        p->from = from, p->to = to, p->delay = delay_, p->rate = rate_;
        p->start();
        pipes_.push_back(std::move(p));
      }
    }
  }
  std::uint16_t target_;
  std::chrono::microseconds delay_;
  std::uint64_t rate_;
  int listen_fd_ = -1;
  std::uint16_t port_ = 0;
  std::atomic<bool> stop_{false};
  std::thread acceptor_;
  std::list<std::unique_ptr<Pipe>> pipes_;  // joined and closed at destruction
};

}  // namespace gpubridge::bench
