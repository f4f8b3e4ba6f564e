#pragma once
// A CommandSink that streams to a gpubridged daemon over its socket protocol (Client from
// gpubridge_client). Only built when that library is in the tree.
#include <memory>
#include <string_view>

#include "gpubridge/client/client.hpp"
#include "gpubridge/draw/sink.hpp"

namespace gpubridge::draw {

class ClientSink final : public CommandSink {
 public:
  // Uses a connected, handshaken client that holds the device lease.
  explicit ClientSink(client::Client& client);
  // Connects to `address` ("" = $GPUBRIDGE_ADDRESS, else the default socket), says hello as `name`
  // (token "" = $GPUBRIDGE_TOKEN / $GPUBRIDGE_TOKEN_FILE) and acquires the lease (waiting for it up
  // to `timeout`).
  static Result<std::unique_ptr<ClientSink>> connect(std::string_view address, std::string_view name,
                                                     std::string_view token = {},
                                                     client::Timeout timeout = client::kDefaultTimeout);

  Result<void> write_frames(protocol::FrameView frames) override { return client_->write_frames(frames); }
  // Not waiting for UPLOAD_ACK: a texture streamed every frame costs no round trip (the daemon
  // executes it in order; an error comes back with a later call).
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override {
    return client_->upload_async(address, bytes);
  }
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override {
    return client_->readback(address, length);
  }
  Result<void> flush() override { return client_->fence(); }
  // From the daemon's WELCOME device description (backend, board, limits, "vram_bytes", "caps",
  // "caps2", "id"); what it does not say keeps DeviceInfo's defaults, and 8 MiB of video memory.
  backends::DeviceInfo device() const override { return device_; }
  Result<void> end_frame(unsigned max_in_flight) override {
    if (auto h = client_->fence_async(); !h) return h.error();
    return client_->wait_fences(max_in_flight);
  }

  client::Client& client() { return *client_; }

 private:
  std::unique_ptr<client::Client> owned_;
  client::Client* client_;
  backends::DeviceInfo device_;
};

}  // namespace gpubridge::draw
