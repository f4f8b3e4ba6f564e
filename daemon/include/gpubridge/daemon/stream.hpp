#pragma once
// The byte stream a Session talks over. AsioStream wraps a real socket (Unix or TCP); tests and
// the fuzzer use an in-memory implementation, so the same session dispatch runs everywhere.
#include <poll.h>

#include <functional>
#include <string>
#include <vector>

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange without it
#include <boost/asio.hpp>

namespace gpubridge::daemon {

class Stream {
 public:
  using Handler = std::function<void(const boost::system::error_code&, std::size_t)>;
  virtual ~Stream() = default;
  // Reads at least one byte into buf (like socket::async_read_some).
  virtual void async_read_some(boost::asio::mutable_buffer buf, Handler handler) = 0;
  // Writes every byte of bufs (like asio::async_write).
  virtual void async_write(const std::vector<boost::asio::const_buffer>& bufs, Handler handler) = 0;
  virtual void close() = 0;
  // Whether the client is still there, without reading: Gone when its socket is closed or reset,
  // HalfClosed when it shut down its sending side (a closed TCP peer also looks like this until
  // something is sent to it). The session asks while it does not read (a request is live).
  enum class PeerState { Open, HalfClosed, Gone };
  virtual PeerState peer_state() const { return PeerState::Open; }
  virtual std::string transport() const = 0;  // "unix" | "tcp" | "memory"
  // TCP only: whether this connection is encrypted (decided by its first byte, tcp_stream.hpp).
  enum class Security { Local, Undecided, Plain, Tls };
  virtual Security security() const { return Security::Local; }
  // The listener accepts only TLS (it is reachable from other machines, or was given as tls:).
  virtual bool tls_required() const { return false; }
  virtual std::string peer() const = 0;       // for logs and status
};

template <class Socket>
class AsioStream final : public Stream {
 public:
  AsioStream(Socket socket, std::string transport, std::string peer)
      : socket_(std::move(socket)), transport_(std::move(transport)), peer_(std::move(peer)) {}
  void async_read_some(boost::asio::mutable_buffer buf, Handler handler) override {
    socket_.async_read_some(buf, std::move(handler));
  }
  void async_write(const std::vector<boost::asio::const_buffer>& bufs, Handler handler) override {
    boost::asio::async_write(socket_, bufs, std::move(handler));
  }
  void close() override {
    boost::system::error_code ignored;
    socket_.shutdown(Socket::shutdown_both, ignored);
    socket_.close(ignored);
  }
  PeerState peer_state() const override {
    // POLLRDHUP is set once the peer's FIN arrived, whatever unread data precedes it; POLLHUP or
    // POLLERR once both directions are down (a closed Unix peer, a reset TCP connection).
    pollfd p{const_cast<Socket&>(socket_).native_handle(), POLLRDHUP, 0};
    if (p.fd < 0 || ::poll(&p, 1, 0) <= 0) return PeerState::Open;
    if (p.revents & (POLLHUP | POLLERR | POLLNVAL)) return PeerState::Gone;
    return (p.revents & POLLRDHUP) ? PeerState::HalfClosed : PeerState::Open;
  }
  std::string transport() const override { return transport_; }
  std::string peer() const override { return peer_; }

 private:
  Socket socket_;
  std::string transport_, peer_;
};

}  // namespace gpubridge::daemon
