#pragma once
// The host end of the standalone SOC's UART (docs/dmc1.md, "Board path"): a serial port (a USB-UART
// such as the iCEBreaker's FT2232H channel B, a CH340, CP210x or FT232R) set to raw 8N1 at the SOC's
// baud rate with no flow control, and the UartFramer turning command words into its bytes. The SOC
// answers nothing, so a send succeeds when the kernel took the bytes; what reaches the GPU is the
// receiver's business (uart.hpp models it).
#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "gpubridge/common/result.hpp"
#include "gpubridge/dmc1/uart.hpp"

namespace gpubridge::dmc1 {

inline constexpr int kSerialCancelled = 3;  // Error::code of a send stopped by the cancel flag

struct SerialStats {
  std::uint64_t bytes = 0;  // written to the port, the opening included
  std::uint64_t words = 0;  // command and screen words
};

class SerialLink {
 public:
  // Opens `path` (e.g. /dev/ttyUSB1) raw, 8N1, no flow control, at `baud`. Errors say what to fix
  // (no such port, the dialout group, a port another program holds, an unsupported rate).
  static Result<std::unique_ptr<SerialLink>> open(const std::string& path, unsigned baud = kStandaloneBaud);
  ~SerialLink();
  SerialLink(const SerialLink&) = delete;
  SerialLink& operator=(const SerialLink&) = delete;

  // Sends command words; the first send opens the receiver's session (0x00, 0xAA). Whole words
  // only: with the cancel flag set it stops at a word boundary (code kSerialCancelled), so the SOC
  // is never left holding half a command.
  Result<void> send(std::span<const std::uint64_t> words);
  Result<void> send_screen(const ScreenCommand& c);
  // Blocks until the kernel has put every byte on the wire (tcdrain).
  Result<void> drain();
  void set_cancel_flag(const std::atomic<bool>* flag) { cancel_ = flag; }

  const std::string& path() const { return path_; }
  unsigned baud() const { return baud_; }
  const SerialStats& stats() const { return stats_; }

 private:
  struct Port;
  SerialLink(std::unique_ptr<Port> port, std::string path, unsigned baud);
  Result<void> write(std::span<const std::uint8_t> bytes);

  std::unique_ptr<Port> port_;
  std::string path_;
  unsigned baud_;
  UartFramer framer_;
  const std::atomic<bool>* cancel_ = nullptr;
  SerialStats stats_;
};

}  // namespace gpubridge::dmc1
