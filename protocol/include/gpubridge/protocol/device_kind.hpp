#pragma once
// The device kinds gpubridge drives (docs/protocol.md, "Device kinds"): spigpu, the register GPU of
// this protocol, and sylefeb's DMC-1 (docs/dmc1.md), whose commands are 64-bit words. One table:
// the CLI's --device lists, board profiles' "device_kind" and their error messages read it.
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace gpubridge::protocol {

enum class DeviceKind { Spigpu, Dmc1 };

struct DeviceKindInfo {
  DeviceKind kind;
  std::string_view name;         // as written in configs and on the command line
  std::string_view label;        // in messages
  std::string_view description;  // one line, for --help
};

std::span<const DeviceKindInfo> device_kinds();
const DeviceKindInfo& device_kind_info(DeviceKind k);
std::optional<DeviceKind> parse_device_kind(std::string_view name);
// "spigpu, dmc1": for --help and "expected one of" messages.
std::string device_kind_names();

}  // namespace gpubridge::protocol
