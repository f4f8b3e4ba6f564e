#include "gpubridge/common/log.hpp"

#include <mutex>
#include <string>

#include <spdlog/sinks/stdout_color_sinks.h>

namespace gpubridge {
namespace {
std::mutex g_mutex;
spdlog::level::level_enum g_level = spdlog::level::info;
std::string g_pattern = "[%H:%M:%S.%e] [%n] [%^%l%$] %v";
}  // namespace

std::string log_levels_text() {
  std::string out;
  for (auto l : kLogLevels) out += (out.empty() ? "" : "|") + std::string(l);
  return out;
}

void init_logging(std::string_view level, LogFormat format) {
  std::lock_guard lock(g_mutex);
  g_level = is_log_level(level) ? spdlog::level::from_str(std::string(level)) : spdlog::level::info;
  if (format == LogFormat::Json)
    g_pattern = R"({"time":"%Y-%m-%dT%H:%M:%S.%e","channel":"%n","level":"%l","msg":"%v"})";
  spdlog::apply_all([](const std::shared_ptr<spdlog::logger>& l) {
    l->set_level(g_level);
    l->set_pattern(g_pattern);
  });
}

std::shared_ptr<spdlog::logger> logger(std::string_view channel) {
  std::lock_guard lock(g_mutex);
  const std::string name(channel);
  if (auto existing = spdlog::get(name)) return existing;
  auto l = spdlog::stderr_color_mt(name);
  l->set_level(g_level);
  l->set_pattern(g_pattern);
  return l;
}

}  // namespace gpubridge
