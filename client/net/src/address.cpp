#include "gpubridge/client/address.hpp"

#include <arpa/inet.h>
#include <unistd.h>

#include <charconv>
#include <cstdlib>

namespace gpubridge::client {

std::string Address::to_string() const {
  if (kind == Kind::Unix) return "unix:" + path;
  const char* scheme = tls ? "tls:" : "tcp:";
  if (host.find(':') != std::string::npos) return scheme + ("[" + host + "]:") + std::to_string(port);
  return scheme + host + ":" + std::to_string(port);
}

std::string default_socket_path() {
  if (const char* xdg = std::getenv("XDG_RUNTIME_DIR"); xdg && *xdg) return std::string(xdg) + "/gpubridge/gpubridge.sock";
  if (::geteuid() == 0) return "/run/gpubridge/gpubridge.sock";
  return "/tmp/gpubridge-" + std::to_string(::geteuid()) + "/gpubridge.sock";
}

Result<Address> parse_address(std::string_view text) {
  auto bad = [&](std::string_view why) {
    return make_error("bad address \"" + std::string(text) + "\": " + std::string(why) +
                      " (expected unix:PATH, tcp:HOST:PORT or tls:HOST:PORT)");
  };
  Address a;
  if (text.starts_with("/")) {
    a.path = std::string(text);
    return a;
  }
  if (text.starts_with("unix:")) {
    a.path = std::string(text.substr(5));
    if (a.path.empty() || a.path == "default") a.path = default_socket_path();
    if (a.path.size() >= 108) return bad("Unix socket paths are limited to 107 bytes");
    return a;
  }
  if (!text.starts_with("tcp:") && !text.starts_with("tls:")) return bad("unknown scheme");
  a.kind = Address::Kind::Tcp;
  a.tls = text.starts_with("tls:");
  std::string_view rest = text.substr(4);
  std::string_view port_text;
  if (rest.starts_with("[")) {
    const auto close = rest.find(']');
    if (close == std::string_view::npos || close + 1 >= rest.size() || rest[close + 1] != ':')
      return bad("IPv6 hosts are written [ADDR]:PORT");
    a.host = std::string(rest.substr(1, close - 1));
    port_text = rest.substr(close + 2);
  } else {
    const auto colon = rest.rfind(':');
    if (colon == std::string_view::npos) return bad("missing :PORT");
    a.host = std::string(rest.substr(0, colon));
    port_text = rest.substr(colon + 1);
  }
  if (a.host.empty()) return bad("missing host");
  unsigned port = 0;
  const auto [end, ec] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
  if (ec != std::errc() || end != port_text.data() + port_text.size() || port > 65535)
    return bad("port must be a number 0..65535");
  a.port = static_cast<std::uint16_t>(port);
  return a;
}

Result<Address> parse_connect_address(std::string_view text) {
  if (text.empty())
    if (const char* env = std::getenv(kAddressEnv); env && *env) {
      auto a = parse_address(env);
      if (!a) return make_error(std::string(kAddressEnv) + ": " + a.error().message);
      return a;
    }
  return parse_address(text.empty() ? std::string_view("unix:") : text);
}

bool is_loopback_host(std::string_view host) {
  if (host == "localhost" || host == "::1") return true;
  in_addr v4{};
  const std::string h(host);
  if (::inet_pton(AF_INET, h.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  return false;
}

}  // namespace gpubridge::client
