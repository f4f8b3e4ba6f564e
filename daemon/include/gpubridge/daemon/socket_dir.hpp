#pragma once
// Where a Unix socket may live. Whoever can replace the socket file, or plant its lock, can serve
// our clients or make the daemon write where they choose, so the directory is checked before use,
// as OpenSSH (StrictModes) and systemd (RuntimeDirectory) do.
#include <sys/types.h>

#include <filesystem>
#include <string>

#include "gpubridge/common/result.hpp"

namespace gpubridge::daemon {

// Opens the directory `dir` (creating it 0700 when absent) and checks it, returning its file
// descriptor (O_DIRECTORY, close-on-exec). It must not be a symbolic link. `private_dir` (the
// default socket's runtime directory, which is the daemon's own): owned by `uid` with mode 0700.
// Otherwise (a directory named with --listen): owned by `uid` or root and writable by nobody else
// unless sticky (like /tmp, where others cannot rename or remove our files).
Result<int> open_socket_directory(const std::filesystem::path& dir, bool private_dir, uid_t uid);

// Opens `name` in the directory `dir_fd` as the lock file (created 0600), never following a
// symbolic link; `shown` names it in errors.
Result<int> open_lock_file(int dir_fd, const std::string& name, const std::string& shown, uid_t uid);

}  // namespace gpubridge::daemon
