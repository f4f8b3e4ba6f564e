#include "gpubridge/daemon/server.hpp"

#include <fcntl.h>
#include <netinet/tcp.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "gpubridge/common/log.hpp"
#include "gpubridge/daemon/session.hpp"
#include "gpubridge/daemon/socket_dir.hpp"
#include "gpubridge/daemon/tcp_stream.hpp"

#include <openssl/ssl.h>

namespace gpubridge::daemon {

namespace asio = boost::asio;
using local_socket = asio::local::stream_protocol::socket;
using tcp = asio::ip::tcp;

struct Server::UnixListener {
  explicit UnixListener(asio::io_context& io) : acceptor(io) {}
  asio::local::stream_protocol::acceptor acceptor;
  std::string path, lock_path;
  int lock_fd = -1;
};

struct Server::TcpListener {
  explicit TcpListener(asio::io_context& io) : acceptor(io) {}
  tcp::acceptor acceptor;
  bool tls_required = false;
};

Server::Server(asio::io_context& io, Hub& hub) : io_(io), hub_(hub) {}
Server::~Server() { stop(); }

Result<void> Server::enable_tls(const std::string& key_path, const std::string& cert_path) {
  auto ctx = std::make_shared<asio::ssl::context>(asio::ssl::context::tls_server);
  boost::system::error_code ec;
  ctx->use_private_key_file(key_path, asio::ssl::context::pem, ec);
  if (!ec) ctx->use_certificate_file(cert_path, asio::ssl::context::pem, ec);
  if (ec) return make_error("TLS: cannot load " + key_path + " / " + cert_path + ": " + ec.message());
  SSL_CTX_set_min_proto_version(ctx->native_handle(), TLS1_3_VERSION);
  tls_ = std::move(ctx);
  return {};
}

Result<client::Address> Server::listen(const client::Address& address) {
  if (address.kind == client::Address::Kind::Unix) {
    auto l = std::make_unique<UnixListener>(io_);
    l->path = address.path;
    l->lock_path = address.path + ".lock";
    const std::filesystem::path path(address.path);
    const auto dir = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
    const bool private_dir = address.path == client::default_socket_path();
    auto dir_fd = open_socket_directory(dir, private_dir, ::geteuid());
    if (!dir_fd) return dir_fd.error();
    const std::string lock_name = path.filename().string() + ".lock";
    // The lock file is opened relative to the checked directory, never through a symlink; and it
    // must still be the file at that name once locked (a daemon that was stopping may just have
    // removed the one we opened).
    Result<int> lock = make_error("");
    for (int attempt = 0;; ++attempt) {
      lock = open_lock_file(*dir_fd, lock_name, l->lock_path, ::geteuid());
      if (!lock) break;
      if (::flock(*lock, LOCK_EX | LOCK_NB) != 0) {
        ::close(*lock);
        lock = make_error("another gpubridged is already serving " + address.path + " (it holds " + l->lock_path +
                          "); stop it or choose another --listen path");
        break;
      }
      struct stat held{}, named{};
      ::fstat(*lock, &held);
      if (::fstatat(*dir_fd, lock_name.c_str(), &named, AT_SYMLINK_NOFOLLOW) == 0 && named.st_ino == held.st_ino &&
          named.st_dev == held.st_dev)
        break;
      ::close(*lock);
      if (attempt == 3) {
        lock = make_error("the lock file " + l->lock_path + " keeps being replaced; is another gpubridged starting?");
        break;
      }
    }
    if (!lock) {
      ::close(*dir_fd);
      return lock.error();
    }
    l->lock_fd = *lock;
    // We hold the lock: whatever socket file is there belongs to a daemon that died.
    ::unlinkat(*dir_fd, path.filename().c_str(), 0);
    ::close(*dir_fd);
    boost::system::error_code ec;
    const mode_t old_mask = ::umask(0177);  // socket is born 0600: no window with wider access
    l->acceptor.open(asio::local::stream_protocol(), ec);
    if (!ec) l->acceptor.bind(asio::local::stream_protocol::endpoint(address.path), ec);
    ::umask(old_mask);
    // A deep queue: a burst of connections waits for accept instead of being refused (EAGAIN).
    if (!ec) l->acceptor.listen(asio::socket_base::max_listen_connections, ec);
    if (ec) {
      ::unlink(l->lock_path.c_str());
      ::close(l->lock_fd);
      return make_error("cannot listen on " + address.to_string() + ": " + ec.message());
    }
    ::chmod(address.path.c_str(), 0600);
    hub_.set_unix_listening(true);
    accept_unix(*l);
    unix_.push_back(std::move(l));
    return address;
  }
  auto l = std::make_unique<TcpListener>(io_);
  boost::system::error_code ec;
  tcp::resolver resolver(io_);
  auto results = resolver.resolve(address.host, std::to_string(address.port), tcp::resolver::passive, ec);
  if (ec || results.empty()) return make_error("cannot resolve listen address " + address.to_string() + ": " + ec.message());
  const tcp::endpoint ep = results.begin()->endpoint();
  l->acceptor.open(ep.protocol(), ec);
  if (!ec) l->acceptor.set_option(tcp::acceptor::reuse_address(true), ec);
  if (!ec) l->acceptor.bind(ep, ec);
  if (!ec) l->acceptor.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) return make_error("cannot listen on " + address.to_string() + ": " + ec.message());
  client::Address bound = address;
  bound.port = l->acceptor.local_endpoint().port();
  if (address.tls && !tls_) return make_error("cannot listen on " + address.to_string() + ": TLS is not set up");
  l->tls_required = tls_ && (address.tls || !client::is_loopback_host(address.host));
  accept_tcp(*l);
  tcp_.push_back(std::move(l));
  return bound;
}

void Server::accept_unix(UnixListener& l) {
  l.acceptor.async_accept([this, &l](const boost::system::error_code& ec, local_socket socket) {
    if (ec == asio::error::operation_aborted || !accepting_) return;
    if (!ec) admit(std::move(socket), "unix", l.path);
    else hub_.log_refusal("accept on " + l.path + ": " + ec.message());
    accept_unix(l);
  });
}

void Server::accept_tcp(TcpListener& l) {
  l.acceptor.async_accept([this, &l](const boost::system::error_code& ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted || !accepting_) return;
    if (!ec) {
      boost::system::error_code ignored;
      socket.set_option(tcp::no_delay(true), ignored);
      // A peer that vanished (cable, crash of its machine) is found by TCP keepalive even when
      // nothing is sent to it; one that stops acknowledging what we send, after the idle timeout.
      socket.set_option(asio::socket_base::keep_alive(true), ignored);
      const int fd = socket.native_handle();
      const int idle = 60, interval = 10, count = 3;
      ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPIDLE, &idle, sizeof idle);
      ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPINTVL, &interval, sizeof interval);
      ::setsockopt(fd, IPPROTO_TCP, TCP_KEEPCNT, &count, sizeof count);
      if (const unsigned ms = hub_.options().limits.idle_timeout_ms; ms > 0) ::setsockopt(fd, IPPROTO_TCP, TCP_USER_TIMEOUT, &ms, sizeof ms);
      auto remote = socket.remote_endpoint(ignored);
      admit(std::move(socket), "tcp", remote.address().to_string() + ":" + std::to_string(remote.port()), &l);
    } else {
      hub_.log_refusal("accept on tcp: " + ec.message());
    }
    accept_tcp(l);
  });
}

template <class Socket>
void Server::admit(Socket socket, std::string transport, std::string peer, const TcpListener* tcp_listener) {
  const auto& l = hub_.options().limits;
  // Connections waiting for HELLO have their own budget (the oldest gives way); handshaken ones
  // are capped at HELLO. This hard ceiling only bounds descriptors if sessions linger in closing.
  if (hub_.session_count() >= std::size_t{l.max_clients} + 2 * std::size_t{l.max_pending_handshakes} + 16) {
    ++refused_;
    hub_.log_refusal("refused a " + transport + " connection: " + std::to_string(hub_.session_count()) +
                     " connections open");
    auto bytes = std::make_shared<std::vector<std::uint8_t>>();
    protocol::encode(protocol::Message{0, protocol::ErrorMsg{protocol::ErrorCode::ServerFull, 0,
                                                              "server full: too many connections; try again later"}},
                     *bytes);
    auto sock = std::make_shared<Socket>(std::move(socket));
    asio::async_write(*sock, asio::buffer(*bytes), [sock, bytes](const boost::system::error_code&, std::size_t) {
      boost::system::error_code ignored;
      sock->shutdown(Socket::shutdown_both, ignored);
      sock->close(ignored);
    });
    return;
  }
  hub_.make_room_for_handshake(transport);
  auto executor = socket.get_executor();
  std::unique_ptr<Stream> stream;
  if constexpr (std::is_same_v<Socket, tcp::socket>)
    stream = std::make_unique<TcpStream>(std::move(socket), tls_, tcp_listener && tcp_listener->tls_required, std::move(peer));
  else
    stream = std::make_unique<AsioStream<Socket>>(std::move(socket), std::move(transport), std::move(peer));
  std::make_shared<Session>(hub_, std::move(stream), executor)->start();
}

void Server::stop_accepting() {
  if (!accepting_) return;
  accepting_ = false;
  boost::system::error_code ignored;
  for (auto& l : tcp_) l->acceptor.close(ignored);
  for (auto& l : unix_) l->acceptor.close(ignored);
}

void Server::stop() {
  if (stopped_) return;
  stop_accepting();
  stopped_ = true;
  for (auto& l : unix_) {
    ::unlink(l->path.c_str());
    ::unlink(l->lock_path.c_str());  // then the lock goes with the descriptor
    if (l->lock_fd >= 0) ::close(l->lock_fd);
    l->lock_fd = -1;
  }
}

}  // namespace gpubridge::daemon
