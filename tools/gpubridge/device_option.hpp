#pragma once
// `--device KIND` for the commands that serve more than one device kind: the choices and the help
// text come from protocol's device-kind table, so a new kind appears here without an edit.
#include <string>

#include <CLI/CLI.hpp>

#include "gpubridge/protocol/device_kind.hpp"

namespace gpubridge::cli {

inline CLI::Option* add_device_option(CLI::App* sub, protocol::DeviceKind& kind) {
  std::string help = "device kind";
  for (const auto& k : protocol::device_kinds())
    help += (k.kind == protocol::device_kinds().front().kind ? ": " : "; ") + std::string(k.name) + ", " + std::string(k.description);
  // Only the table's names are accepted (not CLI11's enum numbers); each becomes its enumerator.
  auto by_name = [](std::string& value) -> std::string {
    const auto k = protocol::parse_device_kind(value);
    if (!k) return "unknown device kind \"" + value + "\" (" + protocol::device_kind_names() + ")";
    value = std::to_string(static_cast<int>(*k));
    return {};
  };
  return sub->add_option("--device", kind, help)
      ->transform(CLI::Validator(by_name, "", "device kind"))
      ->type_name("KIND")
      ->default_str(std::string(protocol::device_kind_info(kind).name));
}

}  // namespace gpubridge::cli
