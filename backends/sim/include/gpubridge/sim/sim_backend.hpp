#pragma once
// The simulator behind the Backend interface: the daemon's default device and what
// `gpubridge render` uses in-process.
#include <memory>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/sim/device.hpp"

namespace gpubridge::sim {

class SimBackend final : public backends::Backend {
 public:
  static Result<std::unique_ptr<SimBackend>> create(const DeviceOptions& options = {});

  backends::DeviceInfo info() const override;
  // Every frame must be a write (read bit clear), else kBadRequest and nothing is written.
  Result<void> write_frames(protocol::FrameView frames) override;
  Result<std::uint64_t> read_register(std::uint8_t index) override;
  // Same effect as MEM_ADDR/MEM_DATA: executes earlier commands first, then copies the bytes.
  // A range beyond VRAM is refused (kBadRequest) without writing anything.
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override;
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override;
  Result<void> flush() override;
  Result<void> reset() override;
  void set_scanout_callback(backends::ScanoutCallback cb) override;
  // Checked every kCancelCheckFrames frames of a write batch.
  void set_cancel_flag(const std::atomic<bool>* flag) override { cancel_ = flag; }
  static constexpr std::size_t kCancelCheckFrames = 64;

  Device& device() { return *device_; }

 private:
  explicit SimBackend(std::unique_ptr<Device> device) : device_(std::move(device)) {}
  std::unique_ptr<Device> device_;
  const std::atomic<bool>* cancel_ = nullptr;
};

}  // namespace gpubridge::sim
