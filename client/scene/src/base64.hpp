#pragma once
// Standard base64 (RFC 4648, '=' padding optional, whitespace ignored) for inline PNG textures.
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

namespace gpubridge::scene {

// nullopt on any character outside the alphabet or a bad length.
std::optional<std::vector<std::uint8_t>> decode_base64(std::string_view text);

}  // namespace gpubridge::scene
