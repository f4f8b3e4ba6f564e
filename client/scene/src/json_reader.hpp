#pragma once
// Typed access to a JSON document with errors that name the file and the JSON path
// ("scene.json: draws[2].vertices[7].x: expected a number, got a string").
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "gpubridge/common/result.hpp"

namespace gpubridge::scene {

class JsonReader {
 public:
  explicit JsonReader(std::string file) : file_(std::move(file)) {}

  Error error(std::string_view path, std::string_view problem) const;

  static std::string child(std::string_view path, std::string_view key);
  static std::string index(std::string_view path, std::size_t i);

  // Errors for keys not in `allowed` (catches typos such as "colour").
  Result<void> only_keys(const nlohmann::json& obj, std::string_view path,
                         std::initializer_list<std::string_view> allowed) const;
  Result<const nlohmann::json*> object(const nlohmann::json& j, std::string_view path) const;
  Result<const nlohmann::json*> array(const nlohmann::json& j, std::string_view path) const;
  // Finite number (NaN/Inf rejected; JSON itself cannot spell them, huge literals overflow to Inf).
  Result<double> number(const nlohmann::json& j, std::string_view path) const;
  Result<double> number_in(const nlohmann::json& j, std::string_view path, double lo, double hi) const;
  Result<unsigned> uint_in(const nlohmann::json& j, std::string_view path, unsigned lo, unsigned hi) const;
  Result<bool> boolean(const nlohmann::json& j, std::string_view path) const;
  Result<std::string> string(const nlohmann::json& j, std::string_view path) const;
  // A string matched case-insensitively against `names`; returns its position.
  Result<std::size_t> choice(const nlohmann::json& j, std::string_view path, std::span<const std::string_view> names) const;

  const std::string& file() const { return file_; }

 private:
  std::string file_;
};

std::string_view json_type_name(const nlohmann::json& j);

}  // namespace gpubridge::scene
