// Input files: the checks and whole-file reads shared by traces, texture images and palettes.
#include "gpubridge/common/file_read.hpp"

#include <cerrno>
#include <cstring>
#include <fstream>

namespace gpubridge {

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

// Reads a whole file after checking its size against `limit` (nothing is allocated first).
Result<std::string> read_small_file(const std::filesystem::path& path, std::uint64_t limit, const char* what) {
  if (auto r = check_regular_file(path, what); !r) return r.error();
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) return make_error(path.string() + ": cannot open " + what + " (" + ec.message() + ")");
  if (size > limit)
    return make_error(path.string() + ": " + what + " of " + std::to_string(size) + " bytes exceeds the limit of " +
                      std::to_string(limit) + " bytes");
  std::ifstream in(path, std::ios::binary);
  if (!in) return make_error(path.string() + ": cannot open " + what + " (" + std::strerror(errno) + ")");
  std::string data(static_cast<std::size_t>(size), '\0');
  in.read(data.data(), static_cast<std::streamsize>(size));
  if (static_cast<std::uint64_t>(in.gcount()) != size)
    return make_error(path.string() + ": short read of " + what + " (file changed while reading?)");
  return data;
}

}  // namespace gpubridge
