#pragma once
// Whom a client talks to on a Unix socket. The daemon must run as the client's own user or as root
// (checked with SO_PEERCRED): another local user who got hold of the socket's directory (e.g.
// /tmp/gpubridge-UID created first by someone else) could otherwise serve false frames and replies
// and see everything the client draws. GPUBRIDGE_DAEMON_UID=N trusts the daemon of uid N as well.
#include <string>

#include "gpubridge/common/result.hpp"

namespace gpubridge::client {

inline constexpr const char* kTrustedDaemonUidEnv = "GPUBRIDGE_DAEMON_UID";

// Checks the peer of the connected Unix socket `fd`; `where` names it in the error.
Result<void> check_daemon_owner(int fd, const std::string& where);
// The same with the trusted uids given: `self` and root, plus `extra` when it is not -1.
Result<void> check_daemon_owner(int fd, const std::string& where, unsigned self, long extra);

}  // namespace gpubridge::client
