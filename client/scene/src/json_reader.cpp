#include "json_reader.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>

#include <fmt/format.h>

namespace gpubridge::scene {

std::string_view json_type_name(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null: return "null";
    case nlohmann::json::value_t::object: return "an object";
    case nlohmann::json::value_t::array: return "an array";
    case nlohmann::json::value_t::string: return "a string";
    case nlohmann::json::value_t::boolean: return "a boolean";
    case nlohmann::json::value_t::binary: return "binary";
    case nlohmann::json::value_t::discarded: return "nothing";
    default: return "a number";
  }
}

Error JsonReader::error(std::string_view path, std::string_view problem) const {
  if (path.empty()) return make_error(fmt::format("{}: {}", file_, problem));
  return make_error(fmt::format("{}: {}: {}", file_, path, problem));
}

std::string JsonReader::child(std::string_view path, std::string_view key) {
  return path.empty() ? std::string(key) : fmt::format("{}.{}", path, key);
}

std::string JsonReader::index(std::string_view path, std::size_t i) { return fmt::format("{}[{}]", path, i); }

Result<void> JsonReader::only_keys(const nlohmann::json& obj, std::string_view path,
                                   std::initializer_list<std::string_view> allowed) const {
  for (const auto& [key, value] : obj.items()) {
    if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
    std::string list;
    for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
    return error(child(path, key), fmt::format("unknown key; expected one of: {}", list));
  }
  return {};
}

Result<const nlohmann::json*> JsonReader::object(const nlohmann::json& j, std::string_view path) const {
  if (!j.is_object()) return error(path, fmt::format("expected an object, got {}", json_type_name(j)));
  return &j;
}

Result<const nlohmann::json*> JsonReader::array(const nlohmann::json& j, std::string_view path) const {
  if (!j.is_array()) return error(path, fmt::format("expected an array, got {}", json_type_name(j)));
  return &j;
}

Result<double> JsonReader::number(const nlohmann::json& j, std::string_view path) const {
  if (!j.is_number()) return error(path, fmt::format("expected a number, got {}", json_type_name(j)));
  const double v = j.get<double>();
  if (std::isnan(v)) return error(path, "NaN is not allowed");
  if (std::isinf(v)) return error(path, "the number is too large (infinite)");
  return v;
}

Result<double> JsonReader::number_in(const nlohmann::json& j, std::string_view path, double lo, double hi) const {
  auto v = number(j, path);
  if (!v) return v;
  if (*v < lo || *v > hi) return error(path, fmt::format("{} is outside [{}, {}]", *v, lo, hi));
  return v;
}

Result<unsigned> JsonReader::uint_in(const nlohmann::json& j, std::string_view path, unsigned lo, unsigned hi) const {
  auto v = number(j, path);
  if (!v) return v.error();
  if (*v != std::floor(*v)) return error(path, fmt::format("expected a whole number, got {}", *v));
  if (*v < lo || *v > hi) return error(path, fmt::format("{} is outside {}..{}", *v, lo, hi));
  return static_cast<unsigned>(*v);
}

Result<bool> JsonReader::boolean(const nlohmann::json& j, std::string_view path) const {
  if (!j.is_boolean()) return error(path, fmt::format("expected true or false, got {}", json_type_name(j)));
  return j.get<bool>();
}

Result<std::string> JsonReader::string(const nlohmann::json& j, std::string_view path) const {
  if (!j.is_string()) return error(path, fmt::format("expected a string, got {}", json_type_name(j)));
  return j.get<std::string>();
}

Result<std::size_t> JsonReader::choice(const nlohmann::json& j, std::string_view path,
                                       std::span<const std::string_view> names) const {
  auto s = string(j, path);
  if (!s) return s.error();
  auto eq = [](std::string_view a, std::string_view b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
             return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
           });
  };
  for (std::size_t i = 0; i < names.size(); ++i)
    if (eq(*s, names[i])) return i;
  std::string list;
  for (auto n : names) list += (list.empty() ? "" : ", ") + std::string(n);
  return error(path, fmt::format("\"{}\" is not one of: {}", *s, list));
}

}  // namespace gpubridge::scene
