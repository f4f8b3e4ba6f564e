#pragma once
// ScanoutFeed: swaps from the device thread to the network thread. On the device thread every
// swap is counted, compared with its mirror reference and written to --frames-dir; the network
// thread is handed only the newest swap, with at most one hand-off queued at a time. A device that
// swaps faster than the network thread fans out therefore never piles frames up in the network
// loop, and after stop() (shutdown) nothing is handed over at all.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange without it
#include <boost/asio.hpp>

#include "gpubridge/backends/backend.hpp"

namespace gpubridge::daemon {

// Mirror mode: swaps compared and those whose CRCs differ.
struct MirrorStats {
  std::uint64_t compared = 0, mismatches = 0;
  std::optional<std::uint32_t> first_mismatch, last_mismatch;  // frame numbers
  std::optional<std::uint64_t> first_mismatch_pixels;           // differing pixels; none for CRC-only boards
  std::optional<std::uint64_t> last_mismatch_pixels;            // the same for the latest mismatch
};

class ScanoutFeed {
 public:
  using Frame = std::shared_ptr<const backends::ScanoutFrame>;
  // fan_out runs on `net` with the newest swap.
  ScanoutFeed(boost::asio::any_io_executor net, std::string frames_dir, std::function<void(Frame)> fan_out);

  void push(Frame frame);  // device thread (the backend's scanout callback)
  void stop();             // any thread

  std::uint64_t count() const { return count_.load(); }
  std::uint32_t last_number() const { return last_number_.load(); }
  std::uint64_t pngs_written() const { return pngs_written_.load(); }
  MirrorStats mirror_stats() const;

 private:
  void compare_mirrored(const backends::ScanoutFrame& frame);  // device thread
  void write_png(const backends::ScanoutFrame& frame);          // device thread

  boost::asio::any_io_executor net_;
  std::string frames_dir_;
  std::function<void(Frame)> fan_out_;
  std::atomic<bool> stopped_{false};
  std::atomic<std::uint64_t> count_{0}, pngs_written_{0};
  std::atomic<std::uint32_t> last_number_{0};
  mutable std::mutex mu_;  // guards newest_ and mirror_
  Frame newest_;           // handed off, not yet taken by the network thread
  MirrorStats mirror_;
};

}  // namespace gpubridge::daemon
