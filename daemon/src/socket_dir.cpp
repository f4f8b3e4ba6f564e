#include "gpubridge/daemon/socket_dir.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace gpubridge::daemon {
namespace {

std::string octal(mode_t mode) {
  char text[8];
  std::snprintf(text, sizeof text, "%04o", static_cast<unsigned>(mode & 07777));
  return text;
}

}  // namespace

Result<int> open_socket_directory(const std::filesystem::path& dir, bool private_dir, uid_t uid) {
  const std::string shown = dir.string();
  if (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST) {
    if (errno != ENOENT) return make_error("cannot create socket directory " + shown + ": " + std::strerror(errno));
    std::error_code ec;  // its parents are missing too: the last component is still made 0700 below
    std::filesystem::create_directories(dir.parent_path(), ec);
    if (ec || (::mkdir(dir.c_str(), 0700) != 0 && errno != EEXIST))
      return make_error("cannot create socket directory " + shown + ": " + (ec ? ec.message() : std::strerror(errno)));
  }
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    struct stat st{};
    if ((err == ELOOP || err == ENOTDIR) && ::lstat(dir.c_str(), &st) == 0 && S_ISLNK(st.st_mode))
      return make_error("socket directory " + shown + " is a symbolic link; refusing it (whoever made it can point it "
                        "anywhere): remove it and gpubridged creates a real directory");
    return make_error("cannot open socket directory " + shown + ": " + std::strerror(err));
  }
  struct stat st{};
  ::fstat(fd, &st);
  auto refuse = [&](const std::string& why) -> Result<int> {
    ::close(fd);
    return make_error("socket directory " + shown + " " + why);
  };
  const std::string you = "uid " + std::to_string(uid);
  if (private_dir) {
    if (st.st_uid != uid)
      return refuse("is owned by uid " + std::to_string(st.st_uid) + ", not by you (" + you +
                    "): another user created it, perhaps to take over your socket; remove it, or listen elsewhere "
                    "(--listen unix:PATH)");
    if ((st.st_mode & 077) != 0)
      return refuse("has mode " + octal(st.st_mode) + "; it must be 0700 so that only you can reach or replace the "
                    "socket: chmod 0700 " + shown + " (or remove it and gpubridged creates it)");
    return fd;
  }
  if (st.st_uid != uid && st.st_uid != 0)
    return refuse("is owned by uid " + std::to_string(st.st_uid) + ", neither by you (" + you +
                  ") nor by root: its owner could replace the socket; choose a directory of your own");
  if ((st.st_mode & 022) != 0 && (st.st_mode & S_ISVTX) == 0)
    return refuse("has mode " + octal(st.st_mode) + ": other users may rename or replace files in it; choose a "
                  "directory only you can write to (or a sticky one like /tmp)");
  return fd;
}

Result<int> open_lock_file(int dir_fd, const std::string& name, const std::string& shown, uid_t uid) {
  const int fd = ::openat(dir_fd, name.c_str(), O_RDWR | O_CREAT | O_NOFOLLOW | O_CLOEXEC | O_NONBLOCK, 0600);
  if (fd < 0) {
    if (errno == ELOOP)
      return make_error("lock file " + shown + " is a symbolic link; refusing to follow it (someone may have planted "
                        "it): remove it");
    return make_error("cannot open lock file " + shown + ": " + std::strerror(errno));
  }
  struct stat st{};
  ::fstat(fd, &st);
  if (!S_ISREG(st.st_mode) || st.st_uid != uid) {
    ::close(fd);
    return make_error("lock file " + shown + " is not a regular file of yours (uid " + std::to_string(st.st_uid) +
                      "); remove it");
  }
  return fd;
}

}  // namespace gpubridge::daemon
