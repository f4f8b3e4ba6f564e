#pragma once
// One logging entry point. Each module asks for its channel ("daemon", "sim", "usb", ...);
// executables call init_logging once. Libraries log diagnostics only; they report errors by value.
#include <memory>
#include <string_view>

#include <spdlog/spdlog.h>

namespace gpubridge {

enum class LogFormat { Text, Json };

// level: "trace" | "debug" | "info" | "warn" | "error" | "off". Logs go to stderr.
void init_logging(std::string_view level = "info", LogFormat format = LogFormat::Text);
std::shared_ptr<spdlog::logger> logger(std::string_view channel);

}  // namespace gpubridge
