#pragma once
// Reading small files that users name (configurations, token files, traces and their assets, DMC-1
// streams, palettes, texture images): regular files only, with a size limit checked before anything
// is allocated. A directory, FIFO, device or
// socket is refused without blocking, by what it is ("is a directory, not a configuration file").
#include <cstdint>
#include <filesystem>
#include <string>

#include "gpubridge/common/result.hpp"

namespace gpubridge {

// The whole file. The file is opened with O_NONBLOCK (a FIFO without a writer does not hang) and
// checked with fstat on that descriptor, so what is read is what was checked. `what` names the
// file's role in errors; `limit` is in bytes.
Result<std::string> read_regular_file(const std::filesystem::path& path, std::uint64_t limit, const char* what);

// A regular file, or an error naming `what` ("trace") and the problem; for readers that open the
// file themselves (traces are read twice: format sniffing, then the reader).
Result<void> check_regular_file(const std::filesystem::path& path, const char* what);

}  // namespace gpubridge
