#pragma once
// One logging entry point. Each module asks for its channel ("daemon", "sim", "usb", ...);
// executables call init_logging once. Libraries log diagnostics only; they report errors by value.
#include <array>
#include <memory>
#include <string_view>

#include <spdlog/spdlog.h>

namespace gpubridge {

enum class LogFormat { Text, Json };

// The levels init_logging accepts. Executables check user input against this list (spdlog would
// turn any other word into "off" and silence every log).
inline constexpr std::array<std::string_view, 6> kLogLevels{"trace", "debug", "info", "warn", "error", "off"};
inline bool is_log_level(std::string_view level) {
  for (auto l : kLogLevels)
    if (l == level) return true;
  return false;
}
// "trace|debug|info|warn|error|off", for help texts and error messages.
std::string log_levels_text();

// level: one of kLogLevels (anything else logs at "info"). Logs go to stderr.
void init_logging(std::string_view level = "info", LogFormat format = LogFormat::Text);
std::shared_ptr<spdlog::logger> logger(std::string_view channel);

}  // namespace gpubridge
