#include "gpubridge/protocol/device_kind.hpp"

namespace gpubridge::protocol {
namespace {

constexpr DeviceKindInfo kKinds[] = {
    {DeviceKind::Spigpu, "spigpu", "spigpu", "the gpubridge register GPU (this protocol; simulator, boards, gateware)"},
    {DeviceKind::Dmc1, "dmc1", "DMC-1", "sylefeb's DMC-1 column GPU (64-bit command words; docs/dmc1.md)"},
};

}  // namespace

std::span<const DeviceKindInfo> device_kinds() { return kKinds; }

const DeviceKindInfo& device_kind_info(DeviceKind k) {
  for (const auto& i : kKinds)
    if (i.kind == k) return i;
  return kKinds[0];  // unreachable: every enumerator has a row (DeviceKinds.TableIsComplete)
}

std::optional<DeviceKind> parse_device_kind(std::string_view name) {
  for (const auto& i : kKinds)
    if (i.name == name) return i.kind;
  return std::nullopt;
}

std::string device_kind_names() {
  std::string out;
  for (const auto& i : kKinds) out += (out.empty() ? "" : ", ") + std::string(i.name);
  return out;
}

}  // namespace gpubridge::protocol
