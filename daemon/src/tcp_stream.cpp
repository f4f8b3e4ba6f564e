#include "gpubridge/daemon/tcp_stream.hpp"

#include <sys/socket.h>

namespace gpubridge::daemon {

namespace asio = boost::asio;
constexpr std::uint8_t kTlsHandshakeRecord = 0x16;  // first byte of a TLS ClientHello

namespace {
// An ssl::context is required to build an ssl::stream even when TLS is never used.
std::shared_ptr<asio::ssl::context> placeholder_context() {
  static auto ctx = std::make_shared<asio::ssl::context>(asio::ssl::context::tls_server);
  return ctx;
}
}  // namespace

TcpStream::TcpStream(asio::ip::tcp::socket socket, std::shared_ptr<asio::ssl::context> tls, bool tls_required,
                     std::string peer)
    : ctx_(tls ? tls : placeholder_context()),
      s_(std::move(socket), *ctx_),
      tls_required_(tls_required),
      peer_(std::move(peer)) {
  if (!tls) ctx_.reset();  // the stream keeps a reference to the placeholder, which lives forever
}

Stream::Security TcpStream::security() const {
  switch (mode_) {
    case Mode::Tls: return Security::Tls;
    case Mode::Plain: return Security::Plain;
    default: return Security::Undecided;
  }
}

void TcpStream::async_read_some(asio::mutable_buffer buf, Handler handler) {
  switch (mode_) {
    case Mode::Plain: s_.next_layer().async_read_some(buf, std::move(handler)); return;
    case Mode::Tls: s_.async_read_some(buf, std::move(handler)); return;
    case Mode::Closed: asio::post(s_.get_executor(), [h = std::move(handler)] { h(asio::error::operation_aborted, 0); }); return;
    default: break;
  }
  // The first read decides: wait for a byte, look at it without taking it.
  mode_ = Mode::Sniffing;
  s_.next_layer().async_wait(asio::ip::tcp::socket::wait_read,
                             [this, buf, handler = std::move(handler)](const boost::system::error_code& ec) mutable {
                               if (ec || mode_ == Mode::Closed) {
                                 handler(ec ? ec : asio::error::operation_aborted, 0);
                                 return;
                               }
                               sniffed(buf, std::move(handler));
                             });
}

void TcpStream::sniffed(asio::mutable_buffer buf, Handler handler) {
  std::uint8_t first = 0;
  const ssize_t n = ::recv(s_.next_layer().native_handle(), &first, 1, MSG_PEEK | MSG_DONTWAIT);
  if (n == 0) {
    handler(asio::error::eof, 0);
    return;
  }
  if (n < 0) {
    handler(boost::system::error_code(errno, boost::system::system_category()), 0);
    return;
  }
  if (first != kTlsHandshakeRecord || !ctx_) {
    mode_ = Mode::Plain;
    if (!held_write_.empty() || held_handler_) start_write(std::exchange(held_write_, {}), std::exchange(held_handler_, nullptr));
    s_.next_layer().async_read_some(buf, std::move(handler));
    return;
  }
  mode_ = Mode::Handshaking;
  s_.async_handshake(asio::ssl::stream_base::server,
                     [this, buf, handler = std::move(handler)](const boost::system::error_code& ec) mutable {
                       if (mode_ == Mode::Closed) {
                         handler(asio::error::operation_aborted, 0);
                         return;
                       }
                       auto held = std::exchange(held_handler_, nullptr);
                       auto held_bufs = std::exchange(held_write_, {});
                       if (ec) {
                         mode_ = Mode::Closed;
                         if (held) held(ec, 0);
                         handler(ec, 0);  // the session ends ("read error"), as for any broken stream
                         return;
                       }
                       mode_ = Mode::Tls;
                       if (held) start_write(held_bufs, std::move(held));
                       s_.async_read_some(buf, std::move(handler));
                     });
}

void TcpStream::start_write(const std::vector<asio::const_buffer>& bufs, Handler handler) {
  if (mode_ == Mode::Tls) asio::async_write(s_, bufs, std::move(handler));
  else asio::async_write(s_.next_layer(), bufs, std::move(handler));
}

void TcpStream::async_write(const std::vector<asio::const_buffer>& bufs, Handler handler) {
  switch (mode_) {
    case Mode::Handshaking:
      held_write_ = bufs;  // the buffers stay alive: the session keeps them until the handler runs
      held_handler_ = std::move(handler);
      return;
    case Mode::Closed:
      asio::post(s_.get_executor(), [h = std::move(handler)] { h(asio::error::operation_aborted, 0); });
      return;
    case Mode::Undecided:
    case Mode::Sniffing:
      // Nothing came from the client yet (an ERROR on timeout or eviction): plain, it is closing.
    case Mode::Plain: asio::async_write(s_.next_layer(), bufs, std::move(handler)); return;
    case Mode::Tls: asio::async_write(s_, bufs, std::move(handler)); return;
  }
}

void TcpStream::close() {
  mode_ = Mode::Closed;
  boost::system::error_code ignored;
  s_.next_layer().shutdown(asio::ip::tcp::socket::shutdown_both, ignored);
  s_.next_layer().close(ignored);  // outstanding operations complete with operation_aborted
  // A write held for the handshake holds the session alive: complete it now.
  if (auto h = std::exchange(held_handler_, nullptr))
    asio::post(s_.get_executor(), [h = std::move(h)] { h(asio::error::operation_aborted, 0); });
  held_write_.clear();
}

Stream::PeerState TcpStream::peer_state() const {
  pollfd p{const_cast<TcpStream*>(this)->s_.next_layer().native_handle(), POLLRDHUP, 0};
  if (p.fd < 0 || ::poll(&p, 1, 0) <= 0) return PeerState::Open;
  if (p.revents & (POLLHUP | POLLERR | POLLNVAL)) return PeerState::Gone;
  return (p.revents & POLLRDHUP) ? PeerState::HalfClosed : PeerState::Open;
}

}  // namespace gpubridge::daemon
