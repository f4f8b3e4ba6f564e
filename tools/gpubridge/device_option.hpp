#pragma once
// `--device KIND` for the commands that serve more than one device kind: the choices and the help
// text come from protocol's device-kind table, so a new kind appears here without an edit.
#include <map>
#include <string>

#include <CLI/CLI.hpp>

#include "gpubridge/protocol/device_kind.hpp"

namespace gpubridge::cli {

inline CLI::Option* add_device_option(CLI::App* sub, protocol::DeviceKind& kind) {
  std::map<std::string, protocol::DeviceKind> names;
  std::string help = "device kind:";
  for (const auto& k : protocol::device_kinds()) {
    names.emplace(std::string(k.name), k.kind);
    help += " " + std::string(k.name) + " (" + std::string(k.description) + ")";
  }
  return sub->add_option("--device", kind, help)
      ->transform(CLI::CheckedTransformer(names))
      ->default_str(std::string(protocol::device_kind_info(kind).name));
}

}  // namespace gpubridge::cli
