#pragma once
// The in-process simulator as a CommandSink that also keeps the latest scanned-out frame. Only
// built when gpubridge_sim is in the tree.
#include <memory>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/draw/sink.hpp"
#include "gpubridge/sim/sim_backend.hpp"

namespace gpubridge::draw {

class SimulatorSink final : public CommandSink {
 public:
  static Result<std::unique_ptr<SimulatorSink>> create(const sim::DeviceOptions& options = {});

  Result<void> write_frames(protocol::FrameView frames) override { return backend_->write_frames(frames); }
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override {
    return backend_->upload(address, bytes);
  }
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override {
    return backend_->readback(address, length);
  }
  Result<void> flush() override { return backend_->flush(); }
  backends::DeviceInfo device() const override { return backend_->info(); }

  // The most recent frame scanned out by a swap (nullptr before the first swap).
  std::shared_ptr<const backends::ScanoutFrame> latest_frame() const { return *latest_; }
  std::uint64_t frames_scanned_out() const { return *count_; }
  sim::SimBackend& backend() { return *backend_; }

 private:
  explicit SimulatorSink(std::unique_ptr<sim::SimBackend> b) : backend_(std::move(b)) {}
  std::unique_ptr<sim::SimBackend> backend_;
  // Shared with the scanout callback, so the sink stays movable without dangling captures.
  std::shared_ptr<std::shared_ptr<const backends::ScanoutFrame>> latest_ =
      std::make_shared<std::shared_ptr<const backends::ScanoutFrame>>();
  std::shared_ptr<std::uint64_t> count_ = std::make_shared<std::uint64_t>(0);
};

}  // namespace gpubridge::draw
