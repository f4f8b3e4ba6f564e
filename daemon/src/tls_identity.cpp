#include "gpubridge/daemon/tls_identity.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <openssl/err.h>
#include <openssl/evp.h>
#include <openssl/pem.h>
#include <openssl/rand.h>
#include <openssl/x509.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>

namespace gpubridge::daemon {
namespace {

template <class T, void (*F)(T*)>
struct Deleter {
  void operator()(T* p) const { F(p); }
};
using Key = std::unique_ptr<EVP_PKEY, Deleter<EVP_PKEY, EVP_PKEY_free>>;
using Cert = std::unique_ptr<X509, Deleter<X509, X509_free>>;

std::string openssl_error(const char* what) {
  char buf[256] = "unknown error";
  if (const unsigned long e = ERR_get_error()) ERR_error_string_n(e, buf, sizeof buf);
  ERR_clear_error();
  return std::string(what) + ": " + buf;
}

// Opens path for writing with the given mode, refusing to follow a symlink or reuse a file.
FILE* create_file(const std::string& path, mode_t mode) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, mode);
  return fd < 0 ? nullptr : ::fdopen(fd, "w");
}

Result<std::string> fingerprint_of(X509* cert) {
  unsigned char md[EVP_MAX_MD_SIZE];
  unsigned len = 0;
  if (X509_digest(cert, EVP_sha256(), md, &len) != 1) return make_error(openssl_error("certificate digest"));
  std::string out = "SHA256:";
  for (unsigned i = 0; i < len; ++i) {
    char b[3];
    std::snprintf(b, sizeof b, "%02x", md[i]);
    out += b;
  }
  return out;
}

Result<void> generate(const std::string& key_path, const std::string& cert_path) {
  Key key(EVP_EC_gen("P-256"));
  if (!key) return make_error(openssl_error("generating the TLS key"));
  Cert cert(X509_new());
  if (!cert) return make_error(openssl_error("X509_new"));
  X509_set_version(cert.get(), 2);
  std::uint64_t serial = 0;
  RAND_bytes(reinterpret_cast<unsigned char*>(&serial), sizeof serial);
  ASN1_INTEGER_set_uint64(X509_get_serialNumber(cert.get()), serial >> 1);
  X509_gmtime_adj(X509_getm_notBefore(cert.get()), -3600);
  X509_gmtime_adj(X509_getm_notAfter(cert.get()), 10L * 365 * 24 * 3600);
  X509_set_pubkey(cert.get(), key.get());
  X509_NAME* name = X509_get_subject_name(cert.get());
  X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_ASC, reinterpret_cast<const unsigned char*>("gpubridged"), -1, -1, 0);
  X509_set_issuer_name(cert.get(), name);
  if (X509_sign(cert.get(), key.get(), EVP_sha256()) <= 0) return make_error(openssl_error("signing the certificate"));
  FILE* kf = create_file(key_path, 0600);
  if (!kf) return make_error("cannot create " + key_path + ": " + std::strerror(errno));
  const bool key_ok = PEM_write_PrivateKey(kf, key.get(), nullptr, nullptr, 0, nullptr, nullptr) == 1;
  std::fclose(kf);
  FILE* cf = create_file(cert_path, 0644);
  if (!cf) return make_error("cannot create " + cert_path + ": " + std::strerror(errno));
  const bool cert_ok = PEM_write_X509(cf, cert.get()) == 1;
  std::fclose(cf);
  if (!key_ok || !cert_ok) return make_error(openssl_error("writing the TLS key and certificate"));
  return {};
}

}  // namespace

std::string default_tls_dir() {
  if (const char* s = std::getenv("STATE_DIRECTORY"); s && *s) return std::string(s) + "/tls";
  if (::geteuid() == 0) return "/var/lib/gpubridge/tls";
  if (const char* x = std::getenv("XDG_STATE_HOME"); x && *x) return std::string(x) + "/gpubridge/tls";
  const char* home = std::getenv("HOME");
  return std::string(home && *home ? home : ".") + "/.local/state/gpubridge/tls";
}

Result<TlsIdentity> load_or_create_tls_identity(const std::string& dir) {
  namespace fs = std::filesystem;
  TlsIdentity id{dir + "/key.pem", dir + "/cert.pem", {}, false};
  std::error_code ec;
  if (!fs::exists(dir, ec)) {
    fs::create_directories(dir, ec);
    if (ec) return make_error("tls_dir: cannot create " + dir + ": " + ec.message());
    ::chmod(dir.c_str(), 0700);
  }
  struct stat st{};
  if (::lstat(dir.c_str(), &st) != 0 || !S_ISDIR(st.st_mode)) return make_error("tls_dir: " + dir + " is not a directory");
  if (st.st_uid != ::geteuid()) return make_error("tls_dir: " + dir + " is not owned by you; the key must be the daemon's own");
  // Two daemons starting at once must not both generate: the first creates, the second loads.
  const std::string lock_path = dir + "/lock";
  const int lock = ::open(lock_path.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (lock < 0) return make_error("tls_dir: cannot open " + lock_path + ": " + std::strerror(errno));
  ::flock(lock, LOCK_EX);
  struct Unlock {
    int fd;
    ~Unlock() { ::close(fd); }
  } unlock{lock};
  const bool have_key = fs::exists(id.key_path, ec), have_cert = fs::exists(id.cert_path, ec);
  if (have_key != have_cert)
    return make_error("tls_dir: " + dir + " holds only one of key.pem and cert.pem; remove it to generate a new pair "
                      "(clients that pinned the old fingerprint must then be told the new one)");
  if (!have_key) {
    if (auto r = generate(id.key_path, id.cert_path); !r) return make_error("tls_dir: " + r.error().message);
    id.created = true;
  }
  if (::stat(id.key_path.c_str(), &st) == 0 && (st.st_mode & 077))
  {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%03o", static_cast<unsigned>(st.st_mode & 0777));
    return make_error("tls_dir: " + id.key_path + " is readable by others (mode " + mode + "); chmod 600 it");
  }
  FILE* cf = std::fopen(id.cert_path.c_str(), "r");
  if (!cf) return make_error("tls_dir: cannot read " + id.cert_path + ": " + std::strerror(errno));
  Cert cert(PEM_read_X509(cf, nullptr, nullptr, nullptr));
  std::fclose(cf);
  if (!cert) return make_error("tls_dir: " + id.cert_path + " is not a PEM certificate: " + openssl_error("PEM"));
  auto fp = fingerprint_of(cert.get());
  if (!fp) return fp.error();
  id.fingerprint = *fp;
  return id;
}

}  // namespace gpubridge::daemon
