#pragma once
// The four bridge chips' shipped generic board profiles, for suites that run once per chip.
#include <gtest/gtest.h>

#include <string>

namespace gpubridge::test {

inline const auto kFourBridgeChips =
    ::testing::Values(std::string("ft232h-generic"), std::string("ch341a-generic"), std::string("mcp2210-generic"),
                      std::string("cp2130-generic"));

// "ft232h-generic" → "ft232h_generic" (gtest names allow no '-').
inline std::string chip_test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string n = info.param;
  for (auto& c : n)
    if (c == '-') c = '_';
  return n;
}

}  // namespace gpubridge::test
