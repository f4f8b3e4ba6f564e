#pragma once
// Client-side checks shared by the daemon tests (tests/daemon) and the in-process auto-attach test
// (tests/usb): STATUS as JSON, and waiting for a DEVICE_EVENT.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "gpubridge/client/client.hpp"

namespace gpubridge::test {

// STATUS_REPLY as JSON; a failed request fails the test and gives an empty object.
inline nlohmann::json status_of(client::Client& c) {
  auto s = c.status(std::chrono::milliseconds(2000));
  EXPECT_TRUE(s) << (s ? "" : s.error().message);
  return s ? nlohmann::json::parse(*s) : nlohmann::json::object();
}

// The first DEVICE_EVENT named `name` within `timeout` (PING makes the client read what arrived).
inline std::optional<nlohmann::json> wait_event(client::Client& c, const std::string& name,
                                                std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    for (const auto& text : c.take_device_events()) {
      auto j = nlohmann::json::parse(text);
      if (j.value("event", "") == name) return j;
    }
    if (!c.ping(std::chrono::milliseconds(1000))) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return std::nullopt;
}

}  // namespace gpubridge::test
