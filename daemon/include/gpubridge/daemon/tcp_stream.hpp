#pragma once
// TcpStream: a TCP connection that is TLS or plain, decided by its first byte (a TLS ClientHello
// starts with 0x16, a gpubridge message with 'G'), so one port serves both. Before the first read
// nothing is decided; a TLS handshake runs inside the session's handshake deadline (the session's
// timers close a client that stalls it). A listener that requires TLS (not loopback, or `tls:`)
// still reads a plain client, whose HELLO is then refused (RequestHandler), so it learns why.
#include <memory>

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange without it
#include <boost/asio.hpp>
#include <boost/asio/ssl.hpp>

#include "gpubridge/daemon/stream.hpp"

namespace gpubridge::daemon {

class TcpStream final : public Stream {
 public:
  // tls: the server context (null: this daemon has no TLS; every client is plain).
  TcpStream(boost::asio::ip::tcp::socket socket, std::shared_ptr<boost::asio::ssl::context> tls, bool tls_required,
            std::string peer);
  void async_read_some(boost::asio::mutable_buffer buf, Handler handler) override;
  void async_write(const std::vector<boost::asio::const_buffer>& bufs, Handler handler) override;
  void close() override;
  PeerState peer_state() const override;
  std::string transport() const override { return "tcp"; }
  std::string peer() const override { return peer_; }
  Security security() const override;
  bool tls_required() const override { return tls_required_; }

 private:
  enum class Mode { Undecided, Sniffing, Handshaking, Plain, Tls, Closed };
  void sniffed(boost::asio::mutable_buffer buf, Handler handler);
  void start_write(const std::vector<boost::asio::const_buffer>& bufs, Handler handler);

  std::shared_ptr<boost::asio::ssl::context> ctx_;
  boost::asio::ssl::stream<boost::asio::ip::tcp::socket> s_;
  bool tls_required_;
  std::string peer_;
  Mode mode_ = Mode::Undecided;
  // A write asked for during the TLS handshake waits for it.
  std::vector<boost::asio::const_buffer> held_write_;
  Handler held_handler_;
};

}  // namespace gpubridge::daemon
