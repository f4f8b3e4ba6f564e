#pragma once
// Server: the listening sockets. Unix sockets live in a private directory (0700 when the daemon
// creates it), are created 0600 and are guarded by a lock file (flock) so two daemons never
// serve the same path; a stale socket is removed only while holding the lock. TCP listeners
// set TCP_NODELAY on every connection. Over the connection cap a client gets SERVER_FULL.
#include <memory>
#include <string>
#include <vector>

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange without it
#include <boost/asio.hpp>

#include "gpubridge/client/address.hpp"
#include "gpubridge/daemon/hub.hpp"

namespace gpubridge::daemon {

class Server {
 public:
  Server(boost::asio::io_context& io, Hub& hub);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  // Binds and starts accepting. Returns the bound address (TCP port 0 is resolved).
  Result<client::Address> listen(const client::Address& address);
  // Stops accepting, removes socket and lock files. Idempotent.
  void stop();
  std::size_t refused() const { return refused_; }

 private:
  struct UnixListener;
  struct TcpListener;
  void accept_unix(UnixListener& l);
  void accept_tcp(TcpListener& l);
  template <class Socket>
  void admit(Socket socket, std::string transport, std::string peer);

  boost::asio::io_context& io_;
  Hub& hub_;
  std::vector<std::unique_ptr<UnixListener>> unix_;
  std::vector<std::unique_ptr<TcpListener>> tcp_;
  std::size_t refused_ = 0;
  bool stopped_ = false;
};

}  // namespace gpubridge::daemon
