#pragma once
// Reading whole input files (traces, texture images, palettes) with errors that name the file and
// what to do: missing files, directories, pipes and devices, and files above a size limit are
// refused before anything is allocated.
#include <cstdint>
#include <filesystem>
#include <string>

#include "gpubridge/common/result.hpp"

namespace gpubridge {

// A regular file, or an error naming `what` ("trace", "palette") and the problem.
Result<void> check_regular_file(const std::filesystem::path& path, const char* what);
// Reads a whole file after checking its size against `limit` (nothing is allocated first).
Result<std::string> read_small_file(const std::filesystem::path& path, std::uint64_t limit, const char* what);

}  // namespace gpubridge
