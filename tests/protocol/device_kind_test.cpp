// The device-kind table: every kind has one row with a unique name, and names round-trip.
#include <gtest/gtest.h>

#include <set>

#include "gpubridge/protocol/device_kind.hpp"

namespace gpubridge::protocol {
namespace {

TEST(DeviceKinds, TableIsComplete) {
  std::set<std::string_view> names;
  for (const auto kind : {DeviceKind::Spigpu, DeviceKind::Dmc1}) {
    const auto& info = device_kind_info(kind);
    EXPECT_EQ(info.kind, kind);
    EXPECT_FALSE(info.description.empty());
    EXPECT_EQ(parse_device_kind(info.name), kind);
    names.insert(info.name);
  }
  EXPECT_EQ(names.size(), device_kinds().size());
  EXPECT_EQ(device_kind_names(), "spigpu, dmc1");
  EXPECT_FALSE(parse_device_kind("DMC1"));  // names are exact, as in configs
  EXPECT_FALSE(parse_device_kind(""));
}

}  // namespace
}  // namespace gpubridge::protocol
