#pragma once
// TLS for `tls:HOST:PORT` (OpenSSL, TLS 1.3 only). The daemon's certificate is self-signed, so it
// is not checked against certificate authorities but pinned by the SHA-256 fingerprint of its DER
// form, as SSH pins host keys:
//   - $GPUBRIDGE_TLS_FINGERPRINT given: the daemon must present exactly that one;
//   - else the known-hosts file ($GPUBRIDGE_KNOWN_HOSTS, else $XDG_CONFIG_HOME/gpubridge/known_hosts,
//     else ~/.config/gpubridge/known_hosts), one "HOST:PORT SHA256:HEX" line per daemon: a known
//     daemon must present its pinned fingerprint; an unknown one is trusted on first use, added to
//     the file and announced on stderr.
// A mismatch is refused with both fingerprints and the line to remove if the key legitimately changed.
#include <memory>
#include <span>
#include <string>

#include <chrono>

#include "gpubridge/client/address.hpp"
#include "gpubridge/common/result.hpp"

struct ssl_st;      // OpenSSL's SSL
struct ssl_ctx_st;  // OpenSSL's SSL_CTX

namespace gpubridge::client {

inline constexpr const char* kFingerprintEnv = "GPUBRIDGE_TLS_FINGERPRINT";
inline constexpr const char* kKnownHostsEnv = "GPUBRIDGE_KNOWN_HOSTS";

std::string known_hosts_path();
// "SHA256:ab12..." (lower-case hex, no colons); accepts "sha256:", colons and upper case on input.
std::string normalize_fingerprint(std::string_view text);

class TlsConnection {
 public:
  // Runs the TLS handshake on the connected non-blocking socket fd (not owned) and checks the pin.
  static Result<std::unique_ptr<TlsConnection>> establish(int fd, const Address& address,
                                                          std::chrono::steady_clock::time_point deadline);
  ~TlsConnection();
  // Like recv/send on a non-blocking socket: > 0 bytes, 0 end of stream, -EAGAIN nothing possible
  // yet (poll the socket), -EPROTO a TLS error (last_error()), other -errno.
  long read(std::span<std::uint8_t> room);
  long write(std::span<const std::uint8_t> bytes);
  bool pending() const;  // decrypted bytes buffered inside TLS
  const std::string& fingerprint() const { return fingerprint_; }
  const std::string& last_error() const { return error_; }

 private:
  TlsConnection() = default;
  long result(int rc);
  ::ssl_st* ssl_ = nullptr;
  ::ssl_ctx_st* ctx_ = nullptr;
  std::string fingerprint_, error_;
};

}  // namespace gpubridge::client
