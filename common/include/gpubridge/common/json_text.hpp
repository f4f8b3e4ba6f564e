#pragma once
// JSON text for what the executables print or write (--json output, reports, events). Strings
// can carry bytes from outside (a file name is any byte string on Linux): invalid UTF-8 is
// replaced by U+FFFD instead of nlohmann::json throwing type_error 316 after the work was done.
// Header-only; the including target links nlohmann_json.
#include <string>

#include <nlohmann/json.hpp>

namespace gpubridge {

inline std::string json_text(const nlohmann::json& j, int indent = -1) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace gpubridge
