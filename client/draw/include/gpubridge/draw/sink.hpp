#pragma once
// Where the drawing API's commands go. One small interface with implementations for any
// Backend (the in-process simulator, a board), a daemon connection (client_sink.hpp) and a
// recorder that keeps the commands as a CommandStream (for traces and tests).
#include <cstdint>
#include <span>
#include <vector>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/command_stream.hpp"
#include "gpubridge/protocol/frame.hpp"

namespace gpubridge::draw {

class CommandSink {
 public:
  virtual ~CommandSink() = default;
  // Register writes (write frames only), executed in order with uploads.
  virtual Result<void> write_frames(protocol::FrameView frames) = 0;
  virtual Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) = 0;
  virtual Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) = 0;
  // Returns once every earlier command has executed.
  virtual Result<void> flush() = 0;
  // The device behind the sink: video memory, largest framebuffer and the CAPS register (a
  // program can fit itself to it, as the examples do).
  virtual backends::DeviceInfo device() const = 0;
  // Frame pacing (Context::swap): marks the end of a frame and returns once at most
  // `max_in_flight` marked frames have not executed yet. Sinks that execute in the caller's
  // thread have nothing in flight; a remote daemon's (ClientSink) uses pipelined fences.
  virtual Result<void> end_frame(unsigned max_in_flight) {
    (void)max_in_flight;
    return {};
  }
  // Size of the device's video memory (bytes), used to place buffers and textures.
  std::uint64_t vram_bytes() const { return device().vram_bytes; }
};

// Any backends::Backend: the simulator in-process, or a board through a USB-SPI bridge.
class BackendSink final : public CommandSink {
 public:
  explicit BackendSink(backends::Backend& backend) : backend_(backend) {}
  Result<void> write_frames(protocol::FrameView frames) override { return backend_.write_frames(frames); }
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override {
    return backend_.upload(address, bytes);
  }
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override {
    return backend_.readback(address, length);
  }
  Result<void> flush() override { return backend_.flush(); }
  backends::DeviceInfo device() const override { return backend_.info(); }

 private:
  backends::Backend& backend_;
};

// Records commands into a CommandStream (nothing executes; readback is an error). Use it to
// write a trace of a drawing program or to inspect what the API sends. Its device is whatever it
// is told (CAPS 0: not stated).
class RecordingSink final : public CommandSink {
 public:
  explicit RecordingSink(std::uint64_t vram_bytes = 8u << 20) { device_.vram_bytes = vram_bytes; }
  explicit RecordingSink(const backends::DeviceInfo& device) : device_(device) {}
  Result<void> write_frames(protocol::FrameView frames) override;
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override;
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override;
  Result<void> flush() override { return {}; }
  backends::DeviceInfo device() const override { return device_; }

  const protocol::CommandStream& stream() const { return stream_; }
  protocol::CommandStream take() { return std::move(stream_); }

 private:
  backends::DeviceInfo device_;
  protocol::CommandStream stream_;
};

}  // namespace gpubridge::draw
