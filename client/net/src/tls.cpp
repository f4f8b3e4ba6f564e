#include "gpubridge/client/tls.hpp"

#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/ssl.h>
#include <openssl/x509.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace gpubridge::client {
namespace {

using Clock = std::chrono::steady_clock;

std::string openssl_error() {
  const unsigned long e = ERR_get_error();
  if (!e) return "TLS handshake failed";
  char buf[256];
  ERR_error_string_n(e, buf, sizeof buf);
  ERR_clear_error();
  return buf;
}

std::string host_port(const Address& a) {
  const bool v6 = a.host.find(':') != std::string::npos;
  return (v6 ? "[" + a.host + "]" : a.host) + ":" + std::to_string(a.port);
}

Error security_error(std::string what) { return make_error(std::move(what), 5 /* kSecurityError */); }

// Checks the presented fingerprint against the pin; trusts and records an unknown daemon.
Result<void> check_pin(const Address& a, const std::string& presented) {
  const std::string where = a.to_string();
  if (const char* given = std::getenv(kFingerprintEnv); given && *given) {
    const std::string want = normalize_fingerprint(given);
    if (want == presented) return {};
    return security_error("the daemon at " + where + " presented certificate " + presented + ", not " + want +
                          " as " + kFingerprintEnv + " requires: refusing it (someone may be intercepting the "
                          "connection; compare with `gpubridged --tls-fingerprint` on the daemon's machine)");
  }
  const std::string path = known_hosts_path();
  const std::string key = host_port(a);
  std::ifstream in(path);
  std::string line;
  for (unsigned n = 1; std::getline(in, line); ++n) {
    const auto sp = line.find(' ');
    if (line.empty() || line[0] == '#' || sp == std::string::npos || line.substr(0, sp) != key) continue;
    const std::string pinned = normalize_fingerprint(line.substr(sp + 1));
    if (pinned == presented) return {};
    return security_error("the daemon at " + where + " presented certificate " + presented + ", but " + path + ":" +
                          std::to_string(n) + " pins " + pinned + ": refusing it (someone may be intercepting the "
                          "connection). If the daemon's key was regenerated, check its fingerprint with "
                          "`gpubridged --tls-fingerprint` there and remove that line.");
  }
  // Trust on first use: record it, and say so.
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
  std::ofstream out(path, std::ios::app);
  if (!out) return security_error("cannot record the daemon's fingerprint in " + path + " (set " + kKnownHostsEnv + ")");
  out << key << ' ' << presented << '\n';
  std::fprintf(stderr, "gpubridge: trusting the daemon at %s on first use: certificate %s, pinned in %s\n", where.c_str(),
               presented.c_str(), path.c_str());
  return {};
}

}  // namespace

std::string known_hosts_path() {
  if (const char* p = std::getenv(kKnownHostsEnv); p && *p) return p;
  if (const char* x = std::getenv("XDG_CONFIG_HOME"); x && *x) return std::string(x) + "/gpubridge/known_hosts";
  const char* home = std::getenv("HOME");
  return std::string(home && *home ? home : ".") + "/.config/gpubridge/known_hosts";
}

std::string normalize_fingerprint(std::string_view text) {
  if (text.size() >= 7 && (text.substr(0, 7) == "SHA256:" || text.substr(0, 7) == "sha256:")) text.remove_prefix(7);
  std::string hex;
  for (char c : text) {
    if (c == ':' || c == ' ' || c == '\n' || c == '\r') continue;
    hex += static_cast<char>(c >= 'A' && c <= 'F' ? c - 'A' + 'a' : c);
  }
  return "SHA256:" + hex;
}

Result<std::unique_ptr<TlsConnection>> TlsConnection::establish(int fd, const Address& a, Clock::time_point deadline) {
  std::unique_ptr<TlsConnection> t(new TlsConnection);
  const std::string where = a.to_string();
  t->ctx_ = SSL_CTX_new(TLS_client_method());
  if (!t->ctx_) return security_error("TLS: " + openssl_error());
  SSL_CTX_set_min_proto_version(t->ctx_, TLS1_3_VERSION);
  // The certificate is self-signed: it is verified by its pinned fingerprint below, not by a CA.
  SSL_CTX_set_verify(t->ctx_, SSL_VERIFY_NONE, nullptr);
  t->ssl_ = SSL_new(t->ctx_);
  if (!t->ssl_) return security_error("TLS: " + openssl_error());
  SSL_set_mode(t->ssl_, SSL_MODE_ENABLE_PARTIAL_WRITE | SSL_MODE_ACCEPT_MOVING_WRITE_BUFFER);
  SSL_set_fd(t->ssl_, fd);
  SSL_set_tlsext_host_name(t->ssl_, a.host.c_str());
  for (;;) {
    const int rc = SSL_connect(t->ssl_);
    if (rc == 1) break;
    const int err = SSL_get_error(t->ssl_, rc);
    if (err != SSL_ERROR_WANT_READ && err != SSL_ERROR_WANT_WRITE) {
      const std::string why = err == SSL_ERROR_SYSCALL || err == SSL_ERROR_ZERO_RETURN
                                  ? std::string("the connection was closed during the TLS handshake")
                                  : openssl_error();
      return security_error("TLS handshake with " + where + " failed: " + why +
                            "; is it a gpubridged TCP listener (tls: needs one; a listener on loopback also takes tcp:)?");
    }
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    pollfd p{fd, static_cast<short>(err == SSL_ERROR_WANT_READ ? POLLIN : POLLOUT), 0};
    if (left <= 0 || ::poll(&p, 1, static_cast<int>(left)) == 0)
      return make_error("TLS handshake with " + where + ": timed out", 2 /* kTimeoutError */);
  }
  X509* cert = SSL_get1_peer_certificate(t->ssl_);
  if (!cert) return security_error("the daemon at " + where + " presented no certificate");
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned len = 0;
  X509_digest(cert, EVP_sha256(), md, &len);
  X509_free(cert);
  std::string hex;
  for (unsigned i = 0; i < len; ++i) {
    char b[3];
    std::snprintf(b, sizeof b, "%02x", md[i]);
    hex += b;
  }
  t->fingerprint_ = "SHA256:" + hex;
  if (auto r = check_pin(a, t->fingerprint_); !r) return r.error();
  return t;
}

TlsConnection::~TlsConnection() {
  if (ssl_) SSL_free(ssl_);
  if (ctx_) SSL_CTX_free(ctx_);
}

long TlsConnection::result(int rc) {
  if (rc > 0) return rc;
  switch (SSL_get_error(ssl_, rc)) {
    case SSL_ERROR_WANT_READ:
    case SSL_ERROR_WANT_WRITE: return -EAGAIN;
    case SSL_ERROR_ZERO_RETURN: return 0;
    case SSL_ERROR_SYSCALL: {
      const int e = errno;
      ERR_clear_error();
      return e ? -e : 0;  // 0: the peer closed without close_notify
    }
    default: error_ = openssl_error(); return -EPROTO;
  }
}

long TlsConnection::read(std::span<std::uint8_t> room) {
  ERR_clear_error();
  return result(SSL_read(ssl_, room.data(), static_cast<int>(std::min<std::size_t>(room.size(), 1 << 30))));
}

long TlsConnection::write(std::span<const std::uint8_t> bytes) {
  ERR_clear_error();
  return result(SSL_write(ssl_, bytes.data(), static_cast<int>(std::min<std::size_t>(bytes.size(), 1 << 30))));
}

bool TlsConnection::pending() const { return ssl_ && SSL_pending(ssl_) > 0; }

}  // namespace gpubridge::client
