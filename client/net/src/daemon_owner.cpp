#include "gpubridge/client/daemon_owner.hpp"

#include <pwd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>

namespace gpubridge::client {
namespace {

std::string user_name(uid_t uid) {
  passwd pw{}, *found = nullptr;
  char buf[1024];
  if (::getpwuid_r(uid, &pw, buf, sizeof buf, &found) == 0 && found) return std::string(" (") + found->pw_name + ")";
  return "";
}

}  // namespace

Result<void> check_daemon_owner(int fd, const std::string& where, unsigned self, long extra) {
  ucred cred{};
  socklen_t len = sizeof cred;
  if (::getsockopt(fd, SOL_SOCKET, SO_PEERCRED, &cred, &len) != 0)
    return make_error("cannot tell who runs the daemon at " + where + ": " + std::strerror(errno), 3);
  if (cred.uid == static_cast<uid_t>(-1))  // no peer: the socket is not connected
    return make_error("cannot tell who runs the daemon at " + where + ": the connection has no peer", 3);
  if (cred.uid == self || cred.uid == 0 || (extra >= 0 && cred.uid == static_cast<uid_t>(extra))) return {};
  const std::string uid = std::to_string(cred.uid);
  return make_error("the daemon at " + where + " runs as uid " + uid + user_name(cred.uid) + ", not as you (uid " +
                        std::to_string(self) + ") or root: refusing it, because another user's daemon could show you "
                        "false frames and see what you draw (has someone else created the socket's directory?); "
                        "if you trust it, set " + kTrustedDaemonUidEnv + "=" + uid,
                    3);
}

Result<void> check_daemon_owner(int fd, const std::string& where) {
  long extra = -1;
  if (const char* env = std::getenv(kTrustedDaemonUidEnv); env && *env) {
    const char* end = env + std::strlen(env);
    unsigned long v = 0;
    const auto [p, ec] = std::from_chars(env, end, v);
    if (ec != std::errc() || p != end || v > 0xFFFFFFFFul)
      return make_error(std::string(kTrustedDaemonUidEnv) + "='" + env + "' is not a uid (a number such as 1000)", 3);
    extra = static_cast<long>(v);
  }
  return check_daemon_owner(fd, where, ::geteuid(), extra);
}

}  // namespace gpubridge::client
