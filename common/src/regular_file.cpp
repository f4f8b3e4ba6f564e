#include "gpubridge/common/regular_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace gpubridge {

Result<std::string> read_regular_file(const std::filesystem::path& path, std::uint64_t limit, const char* what) {
  const std::string shown = path.string();
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) return make_error(shown + ": cannot open " + what + " (" + std::strerror(errno) + ")");
  struct stat st{};
  Result<std::string> result = make_error("");
  if (::fstat(fd, &st) != 0) {
    result = make_error(shown + ": cannot open " + what + " (" + std::strerror(errno) + ")");
  } else if (S_ISDIR(st.st_mode)) {
    result = make_error(shown + ": is a directory, not a " + what);
  } else if (!S_ISREG(st.st_mode)) {
    result = make_error(shown + ": is not a regular file (a pipe or a device); save the " + std::string(what) +
                        " to a file and pass that");
  } else if (static_cast<std::uint64_t>(st.st_size) > limit) {
    result = make_error(shown + ": " + what + " of " + std::to_string(st.st_size) + " bytes exceeds the limit of " +
                        std::to_string(limit) + " bytes");
  } else {
    std::string data(static_cast<std::size_t>(st.st_size), '\0');
    std::size_t done = 0;
    while (done < data.size()) {
      const ssize_t n = ::read(fd, data.data() + done, data.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
    if (done != data.size())
      result = make_error(shown + ": short read of " + what + " (file changed while reading?)");
    else
      result = std::move(data);
  }
  ::close(fd);
  return result;
}

// Inputs are sized before reading (traces are also read twice: format sniffing, then the reader):
// they must be regular files. Pipes and devices get a message saying so instead of "Operation not supported".
Result<void> check_regular_file(const std::filesystem::path& path, const char* what) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (ec || !std::filesystem::exists(st)) return make_error(path.string() + ": cannot open " + what + " (" +
                                                            (ec ? ec.message() : std::string("no such file")) + ")");
  if (std::filesystem::is_directory(st)) return make_error(path.string() + ": is a directory, not a " + what);
  if (!std::filesystem::is_regular_file(st))
    return make_error(path.string() + ": is not a regular file (a pipe or a device); save the " + what +
                      " to a file and pass that");
  return {};
}

}  // namespace gpubridge
