#pragma once
// Server: the listening sockets. A Unix socket lives in a directory no other user can write to
// (socket_dir.hpp: the default runtime directory must be ours and 0700), is created 0600 and is
// guarded by a lock file (flock, never through a symlink) held until the process ends, so two
// daemons never serve the same path; a stale socket is removed only while holding the lock. TCP
// listeners set TCP_NODELAY and keepalive on every connection. Admission (docs/daemon.md
// "Limits"): connections still waiting for their HELLO have a budget per transport in which the
// oldest gives way to a new one; the cap on clients applies at HELLO (Hub::may_handshake).
#include <memory>
#include <string>
#include <vector>

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange without it
#include <boost/asio.hpp>
#include <boost/asio/ssl/context.hpp>

#include "gpubridge/client/address.hpp"
#include "gpubridge/daemon/hub.hpp"

namespace gpubridge::daemon {

class Server {
 public:
  Server(boost::asio::io_context& io, Hub& hub);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // TLS for TCP listeners: the key and certificate (tls_identity.hpp). Without it TCP is plain.
  Result<void> enable_tls(const std::string& key_path, const std::string& cert_path);
  // Binds and starts accepting. Returns the bound address (TCP port 0 is resolved). A TCP listener
  // with TLS enabled takes TLS and plain clients; only TLS ones when it is `tls:` or not loopback.
  Result<client::Address> listen(const client::Address& address);
  // Stops accepting; the socket and lock files stay until stop() (shutdown: nothing can connect,
  // and no second daemon can start on the path while this one still runs). Idempotent.
  void stop_accepting();
  // Stops accepting, removes socket and lock files and releases the lock. Idempotent.
  void stop();
  std::size_t refused() const { return refused_; }

 private:
  struct UnixListener;
  struct TcpListener;
  void accept_unix(UnixListener& l);
  void accept_tcp(TcpListener& l);
  template <class Socket>
  void admit(Socket socket, std::string transport, std::string peer, const TcpListener* tcp_listener = nullptr);

  boost::asio::io_context& io_;
  Hub& hub_;
  std::vector<std::unique_ptr<UnixListener>> unix_;
  std::vector<std::unique_ptr<TcpListener>> tcp_;
  std::shared_ptr<boost::asio::ssl::context> tls_;
  std::size_t refused_ = 0;
  bool accepting_ = true;
  bool stopped_ = false;
};

}  // namespace gpubridge::daemon
