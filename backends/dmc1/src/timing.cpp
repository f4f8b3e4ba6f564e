#include "gpubridge/dmc1/timing.hpp"

#include <charconv>
#include <utility>

namespace gpubridge::dmc1 {

void TimingModel::end_of_column(bool last_of_frame) {
  // The EOC waits for the drawer (now_) and for the sender to finish the previous column.
  const std::uint64_t start = (now_ > sender_free_ ? now_ : sender_free_) + p_.end_of_column;
  now_ = start;
  sender_free_ = start + p_.column_send();
  if (last_of_frame) {
    frames_.push_back(sender_free_ - last_frame_end_);
    last_frame_end_ = sender_free_;
  }
}

Result<void> apply_timing_setting(TimingParameters& p, const std::string& setting) {
  const auto eq = setting.find('=');
  const std::string key = setting.substr(0, eq);
  const std::string value = eq == std::string::npos ? "" : setting.substr(eq + 1);
  if (eq == std::string::npos || value.empty())
    return make_error("timing setting '" + setting + "': expected KEY=VALUE, e.g. screen_cycles_per_word=19");
  if (key == "clock_mhz") {
    double v = 0;
    auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
    if (ec != std::errc() || ptr != value.data() + value.size() || !(v > 0 && v <= 1000))
      return make_error("timing setting clock_mhz=" + value + ": expected a number of MHz in (0, 1000]");
    p.clock_mhz = v;
    return {};
  }
  const std::pair<const char*, std::uint32_t TimingParameters::*> integers[] = {
      {"startup", &TimingParameters::startup},
      {"texel_period", &TimingParameters::texel_period},
      {"background_period", &TimingParameters::background_period},
      {"terrain_period", &TimingParameters::terrain_period},
      {"span_overhead", &TimingParameters::span_overhead},
      {"bind", &TimingParameters::bind},
      {"background_overhead", &TimingParameters::background_overhead},
      {"command", &TimingParameters::command},
      {"end_of_column", &TimingParameters::end_of_column},
      {"column_words", &TimingParameters::column_words},
      {"sender_pipeline", &TimingParameters::sender_pipeline},
      {"screen_cycles_per_word", &TimingParameters::screen_cycles_per_word},
  };
  std::string known = "clock_mhz";
  for (const auto& [name, field] : integers) {
    known += std::string(", ") + name;
    if (key != name) continue;
    std::uint32_t v = 0;
    auto [ptr, ec] = std::from_chars(value.data(), value.data() + value.size(), v);
    if (ec != std::errc() || ptr != value.data() + value.size() || v > 1'000'000)
      return make_error("timing setting " + key + "=" + value + ": expected a whole number of cycles, 0..1000000");
    p.*field = v;
    return {};
  }
  return make_error("timing setting '" + key + "' is unknown; the settings are " + known);
}

}  // namespace gpubridge::dmc1
