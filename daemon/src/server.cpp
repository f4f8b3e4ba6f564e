#include "gpubridge/daemon/server.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "gpubridge/common/log.hpp"
#include "gpubridge/daemon/session.hpp"

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
};

Server::Server(asio::io_context& io, Hub& hub) : io_(io), hub_(hub) {}
Server::~Server() { stop(); }

Result<client::Address> Server::listen(const client::Address& address) {
  if (address.kind == client::Address::Kind::Unix) {
    auto l = std::make_unique<UnixListener>(io_);
    l->path = address.path;
    l->lock_path = address.path + ".lock";
    const std::filesystem::path dir = std::filesystem::path(address.path).parent_path();
    std::error_code fec;
    if (!dir.empty() && !std::filesystem::exists(dir, fec)) {
      std::filesystem::create_directories(dir, fec);
      if (fec) return make_error("cannot create socket directory " + dir.string() + ": " + fec.message());
      ::chmod(dir.c_str(), 0700);  // only the owner may even look for the socket
    }
    l->lock_fd = ::open(l->lock_path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0600);
    if (l->lock_fd < 0) return make_error("cannot open lock file " + l->lock_path + ": " + std::strerror(errno));
    if (::flock(l->lock_fd, LOCK_EX | LOCK_NB) != 0) {
      ::close(l->lock_fd);
      return make_error("another gpubridged is already serving " + address.path + " (it holds " + l->lock_path +
                        "); stop it or choose another --listen path");
    }
    // We hold the lock: whatever socket file is there belongs to a daemon that died.
    ::unlink(address.path.c_str());
    boost::system::error_code ec;
    const mode_t old_mask = ::umask(0177);  // socket is born 0600: no window with wider access
    l->acceptor.open(asio::local::stream_protocol(), ec);
    if (!ec) l->acceptor.bind(asio::local::stream_protocol::endpoint(address.path), ec);
    ::umask(old_mask);
    if (!ec) l->acceptor.listen(128, ec);
    if (ec) {
      ::close(l->lock_fd);
      ::unlink(l->lock_path.c_str());
      return make_error("cannot listen on " + address.to_string() + ": " + ec.message());
    }
    ::chmod(address.path.c_str(), 0600);
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
  if (!ec) l->acceptor.listen(128, ec);
  if (ec) return make_error("cannot listen on " + address.to_string() + ": " + ec.message());
  client::Address bound = address;
  bound.port = l->acceptor.local_endpoint().port();
  accept_tcp(*l);
  tcp_.push_back(std::move(l));
  return bound;
}

void Server::accept_unix(UnixListener& l) {
  l.acceptor.async_accept([this, &l](const boost::system::error_code& ec, local_socket socket) {
    if (ec == asio::error::operation_aborted || stopped_) return;
    if (!ec) admit(std::move(socket), "unix", l.path);
    else logger("daemon")->warn("accept on {}: {}", l.path, ec.message());
    accept_unix(l);
  });
}

void Server::accept_tcp(TcpListener& l) {
  l.acceptor.async_accept([this, &l](const boost::system::error_code& ec, tcp::socket socket) {
    if (ec == asio::error::operation_aborted || stopped_) return;
    if (!ec) {
      boost::system::error_code ignored;
      socket.set_option(tcp::no_delay(true), ignored);
      auto remote = socket.remote_endpoint(ignored);
      admit(std::move(socket), "tcp", remote.address().to_string() + ":" + std::to_string(remote.port()));
    } else {
      logger("daemon")->warn("accept on tcp: {}", ec.message());
    }
    accept_tcp(l);
  });
}

template <class Socket>
void Server::admit(Socket socket, std::string transport, std::string peer) {
  if (hub_.session_count() >= hub_.options().limits.max_clients) {
    // Explicit refusal, then close: the client learns why instead of seeing a bare reset.
    ++refused_;
    auto bytes = std::make_shared<std::vector<std::uint8_t>>();
    protocol::encode(protocol::Message{0, protocol::ErrorMsg{protocol::ErrorCode::ServerFull, 0,
                                                              "server full: " + std::to_string(hub_.options().limits.max_clients) +
                                                                  " clients connected; try again later"}},
                     *bytes);
    auto sock = std::make_shared<Socket>(std::move(socket));
    asio::async_write(*sock, asio::buffer(*bytes), [sock, bytes](const boost::system::error_code&, std::size_t) {
      boost::system::error_code ignored;
      sock->shutdown(Socket::shutdown_both, ignored);
      sock->close(ignored);
    });
    logger("daemon")->warn("refused a {} client: connection cap reached", transport);
    return;
  }
  auto executor = socket.get_executor();
  auto stream = std::make_unique<AsioStream<Socket>>(std::move(socket), std::move(transport), std::move(peer));
  std::make_shared<Session>(hub_, std::move(stream), executor)->start();
}

void Server::stop() {
  if (stopped_) return;
  stopped_ = true;
  boost::system::error_code ignored;
  for (auto& l : tcp_) l->acceptor.close(ignored);
  for (auto& l : unix_) {
    l->acceptor.close(ignored);
    ::unlink(l->path.c_str());
    ::unlink(l->lock_path.c_str());
    if (l->lock_fd >= 0) ::close(l->lock_fd);
    l->lock_fd = -1;
  }
}

}  // namespace gpubridge::daemon
