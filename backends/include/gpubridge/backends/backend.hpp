#pragma once
// The one interface every device sits behind: the simulator (default, sigrok-`demo` style) and
// real boards reached through USB-SPI bridges. The daemon, the CLI's `render` and the tests only
// talk to this interface.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/device_kind.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::backends {

// One scanned-out frame (one per FB_DISPLAY swap), in the device's pixel format.
struct ScanoutFrame {
  std::uint32_t number = 0;  // full 32-bit frame counter (STATUS.FRAME_COUNT is its low 16 bits)
  unsigned width = 0, height = 0;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  std::vector<std::uint8_t> pixels;  // width * height * bpp, rows top to bottom; empty when the
                                     // backend only knows the FRAME_CRC (board profile "scanout": "crc")
  std::uint32_t crc = 0;             // FRAME_CRC of these bytes
  std::chrono::steady_clock::time_point swap_time{};
  // Mirror mode (daemon --mirror): the simulator's frame for the same swap, fed the same commands
  // as the board (the golden model). Null everywhere else.
  std::shared_ptr<const ScanoutFrame> reference = nullptr;
};
using ScanoutCallback = std::function<void(std::shared_ptr<const ScanoutFrame>)>;

struct DeviceInfo {
  // The device kind the backend serves (docs/protocol.md 17.7): which command messages it takes
  // (spigpu: WRITE_FRAMES, READ_REG, UPLOAD, READBACK; dmc1: DMC1_WORDS).
  protocol::DeviceKind kind = protocol::DeviceKind::Spigpu;
  std::string backend;  // "sim" or "board"
  std::string board;    // profile name ("" for the plain simulator)
  std::string bridge;   // bridge chip ("" for the simulator)
  unsigned max_width = protocol::kMaxFramebufferDim;
  unsigned max_height = protocol::kMaxFramebufferDim;
  std::uint64_t vram_bytes = 0;
  std::uint64_t id = 0;    // ID register
  std::uint64_t caps = 0;  // CAPS register
  // CAPS2 register (protocol 1.4; 0 for an older device, which has no CAPS2): protocol::has_depth_buffer.
  std::uint64_t caps2 = 0;
  // Where the scanned-out frames come from when not from the device itself ("" = the device's own):
  // a board that sends no frames back shows the simulator's, and says so here.
  std::string frames_note;
  // Which arithmetic renders the frames (docs/protocol.md, WELCOME): "exact" (the hardware's bits:
  // a board, the DMC-1, the simulator's default), "preview" (the simulator's float rasteriser,
  // `--accuracy preview`) or "knobs" (the simulator with hardware-precision knobs changed).
  std::string accuracy = "exact";
};

// Error codes of backend results (Error::code).
enum BackendError : int {
  kDeviceGone = 100,      // unplugged / NO_DEVICE: caller may fall back to the simulator
  kDeviceTimeout = 101,   // bridge or flow-control timeout; device state unknown
  kDeviceProtocol = 102,  // bad response (not configured, stuck MISO, link CRC failure after retries)
  kBadRequest = 103,      // caller error (address out of range, read frame in a write batch, ...)
  kCancelled = 104,       // stopped early because the cancel flag was set (set_cancel_flag)
};

class Backend {
 public:
  virtual ~Backend() = default;

  virtual DeviceInfo info() const = 0;

  // Register writes exactly as 9-byte wire frames (read bit must be 0). Executed in order.
  // spigpu backends only; the daemon sends a DMC-1 backend none (it answers WRONG_DEVICE).
  virtual Result<void> write_frames(protocol::FrameView frames) = 0;
  // DMC-1 command words (docs/dmc1.md), executed in order. DMC-1 backends only: the default refuses.
  virtual Result<void> write_dmc1_words(std::span<const std::uint64_t> words) {
    (void)words;
    return make_error(std::string(protocol::device_kind_info(info().kind).label) + " backend takes no DMC-1 command words",
                      kBadRequest);
  }
  // Reads a register over the device's read path (immediate; see docs/protocol.md).
  virtual Result<std::uint64_t> read_register(std::uint8_t index) = 0;
  // Bulk memory access through MEM_ADDR/MEM_DATA (or an equivalent fast path with the same effect).
  virtual Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) = 0;
  virtual Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) = 0;
  // Returns once every earlier command has executed.
  virtual Result<void> flush() = 0;
  // Soft reset (RESET register): registers, FIFO and flags to reset values; memory kept.
  virtual Result<void> reset() = 0;
  // Called for every scanned-out frame, on the thread that caused the swap.
  virtual void set_scanout_callback(ScanoutCallback cb) = 0;
  // A long write_frames may stop between frames once *flag is true (the daemon is stopping, or the
  // client whose batch it is went away) and then returns kCancelled; the frames before that point
  // have executed. The flag outlives the backend. Default: never checked (the batch runs to its end).
  virtual void set_cancel_flag(const std::atomic<bool>* flag) { (void)flag; }
};

}  // namespace gpubridge::backends
