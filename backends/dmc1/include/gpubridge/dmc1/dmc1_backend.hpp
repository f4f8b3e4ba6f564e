#pragma once
// The DMC-1 behind the Backend interface (docs/dmc1.md, "Behind the daemon"): command words in
// (write_dmc1_words), 320 x 240 RGB565 frames out through the scan-out callback, one per 320
// end-of-column commands. Without a link it is the simulator; with a SerialLink it is the board
// (tinygpus' standalone SOC over a USB-UART): every word goes to the board first, then to the
// simulator, whose frames stand for the board's (it sends none back; DeviceInfo::frames_note says so).
// The spigpu operations (register writes, reads, memory) are refused: the daemon answers them with
// WRONG_DEVICE before they get here.
#include <atomic>
#include <memory>
#include <span>
#include <string>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "gpubridge/dmc1/serial_link.hpp"

namespace gpubridge::dmc1 {

struct Dmc1BackendOptions {
  unsigned threads = 1;
  std::string board;           // board profile name, with a link
};

class Dmc1Backend final : public backends::Backend {
 public:
  // `link` null: the simulator; otherwise the board behind it.
  static Result<std::unique_ptr<Dmc1Backend>> create(std::shared_ptr<const TextureMemory> textures, const Palette& palette,
                                                     const Dmc1BackendOptions& options,
                                                     std::unique_ptr<SerialLink> link = nullptr);
  ~Dmc1Backend() override;

  backends::DeviceInfo info() const override;
  Result<void> write_frames(protocol::FrameView frames) override;
  Result<void> write_dmc1_words(std::span<const std::uint64_t> words) override;
  Result<std::uint64_t> read_register(std::uint8_t index) override;
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override;
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override;
  Result<void> flush() override;
  Result<void> reset() override;
  void set_scanout_callback(backends::ScanoutCallback cb) override { callback_ = std::move(cb); }
  void set_cancel_flag(const std::atomic<bool>* flag) override;

 private:
  Dmc1Backend(std::unique_ptr<Device> device, std::unique_ptr<SerialLink> link, Dmc1BackendOptions options);
  void scan_out(const Frame& f);
  Error not_this_kind(const char* what) const;

  std::unique_ptr<Device> device_;
  std::unique_ptr<SerialLink> link_;
  Dmc1BackendOptions options_;
  backends::ScanoutCallback callback_;
  const std::atomic<bool>* cancel_ = nullptr;
};

}  // namespace gpubridge::dmc1
