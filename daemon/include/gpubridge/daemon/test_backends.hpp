#pragma once
// Two small backends for measurement and tests (selected with backend "discard" / "fake"):
// - DiscardBackend accepts everything and counts it: the sink `gpubridge bench daemon` measures
//   the daemon's own overhead against.
// - FakeScanoutBackend keeps register values and a small memory, and scans out a deterministic
//   frame (filled from CLEAR_COLOR, numbered) on every FB_DISPLAY write, so frame fan-out can be
//   tested without the simulator.
#include <atomic>
#include <cstdint>
#include <vector>

#include "gpubridge/backends/backend.hpp"

namespace gpubridge::daemon {

class DiscardBackend final : public backends::Backend {
 public:
  backends::DeviceInfo info() const override;
  Result<void> write_frames(protocol::FrameView frames) override;
  Result<std::uint64_t> read_register(std::uint8_t index) override;
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override;
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override;
  Result<void> flush() override { return {}; }
  Result<void> reset() override { return {}; }
  void set_scanout_callback(backends::ScanoutCallback) override {}

  std::uint64_t frames_written() const { return frames_.load(std::memory_order_relaxed); }

 private:
  std::atomic<std::uint64_t> frames_{0};
};

class FakeScanoutBackend final : public backends::Backend {
 public:
  FakeScanoutBackend(unsigned width = 64, unsigned height = 48, std::size_t memory_bytes = 1u << 20);
  backends::DeviceInfo info() const override;
  Result<void> write_frames(protocol::FrameView frames) override;
  Result<std::uint64_t> read_register(std::uint8_t index) override;
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override;
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override;
  Result<void> flush() override { return {}; }
  Result<void> reset() override;
  void set_scanout_callback(backends::ScanoutCallback cb) override { callback_ = std::move(cb); }

 private:
  void scan_out();
  unsigned width_, height_;
  std::vector<std::uint8_t> memory_;
  std::uint64_t regs_[protocol::kRegisterCount] = {};
  std::uint32_t frame_number_ = 0;
  backends::ScanoutCallback callback_;
};

}  // namespace gpubridge::daemon
