#pragma once
// Daemon addresses as users type them: `unix:PATH`, `tcp:HOST:PORT` or `tls:HOST:PORT` (HOST may
// be [v6]; tls: is TCP with TLS from the first byte, docs/daemon.md "Remote use").
// Shared by the daemon (listen addresses) and the Client (connect addresses) so both accept
// exactly the same spelling.
#include <cstdint>
#include <string>
#include <string_view>

#include "gpubridge/common/result.hpp"

namespace gpubridge::client {

struct Address {
  enum class Kind { Unix, Tcp } kind = Kind::Unix;
  std::string path;    // Unix
  std::string host;    // TCP (without brackets)
  std::uint16_t port = 0;
  bool tls = false;    // TCP: `tls:` (encrypted, the daemon's certificate pinned) rather than `tcp:`

  std::string to_string() const;  // "unix:/run/..." / "tcp:127.0.0.1:7420" / "tls:lab:7420"
};

// Parses `unix:PATH` | `tcp:HOST:PORT` | `tls:HOST:PORT`; a bare absolute path is a Unix socket.
// "unix:" with an empty path (or the word "default") means default_socket_path().
Result<Address> parse_address(std::string_view text);

// The address a client connects to: parse_address(text); when text is empty (no --connect given)
// $GPUBRIDGE_ADDRESS if set, else the default socket. Every client (Client::connect, the viewer,
// the CLI, the examples) resolves its --connect value here, so "no option" means the same daemon
// everywhere, and one environment variable points every program at a remote daemon.
inline constexpr const char* kAddressEnv = "GPUBRIDGE_ADDRESS";
Result<Address> parse_connect_address(std::string_view text);

// $XDG_RUNTIME_DIR/gpubridge/gpubridge.sock; /run/gpubridge/gpubridge.sock for root without
// XDG_RUNTIME_DIR; otherwise /tmp/gpubridge-<uid>/gpubridge.sock.
std::string default_socket_path();

// True for 127.0.0.0/8, ::1 and "localhost": addresses only this machine can reach.
bool is_loopback_host(std::string_view host);

}  // namespace gpubridge::client
