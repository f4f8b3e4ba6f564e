#pragma once
// A pseudo-terminal pair standing in for a USB-UART's tty (the board path's tests): the code under
// test opens the slave by its path, the test reads the master. The test keeps a slave descriptor
// open so the master never reads EIO between the link's open and close.
#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <stdexcept>
#include <string>

namespace gpubridge::dmc1::test {

class Pty {
 public:
  Pty() {
    master_ = ::posix_openpt(O_RDWR | O_NOCTTY);
    if (master_ < 0 || ::grantpt(master_) != 0 || ::unlockpt(master_) != 0) throw std::runtime_error("no pseudo-terminal");
    slave_path_ = ::ptsname(master_);
    slave_ = ::open(slave_path_.c_str(), O_RDWR | O_NOCTTY);
    if (slave_ < 0) throw std::runtime_error("cannot open " + slave_path_);
  }
  ~Pty() {
    ::close(slave_);
    ::close(master_);
  }
  Pty(const Pty&) = delete;
  Pty& operator=(const Pty&) = delete;
  const std::string& slave_path() const { return slave_path_; }
  int slave_fd() const { return slave_; }

  // Reads the master side until `done` is set and nothing more arrives for 200 ms, handing each
  // chunk to `sink`.
  template <class Sink>
  void read_until(const std::atomic<bool>& done, Sink sink) {
    std::uint8_t buf[4096];
    for (;;) {
      pollfd p{master_, POLLIN, 0};
      const int ready = ::poll(&p, 1, 200);
      if (ready > 0 && (p.revents & POLLIN)) {
        const ssize_t n = ::read(master_, buf, sizeof buf);
        if (n > 0) {
          sink(std::span<const std::uint8_t>(buf, static_cast<std::size_t>(n)));
          continue;
        }
      }
      if (done.load()) return;
    }
  }

 private:
  int master_ = -1, slave_ = -1;
  std::string slave_path_;
};

}  // namespace gpubridge::dmc1::test
