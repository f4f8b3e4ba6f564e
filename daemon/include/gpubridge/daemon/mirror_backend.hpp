#pragma once
// Mirror mode (gpubridged --mirror, docs/daemon.md "Mirror mode"): hardware-in-the-loop bring-up.
// MirrorBackend sits in front of a board and forwards every command, in order, to the board and
// to a reference model (the simulator, configured like the board). Results of reads and readbacks
// come from the board; the model executes them too so its MEM_ADDR and flags stay in step. Every
// board swap is paired with the model's swap at the same point of the command stream (the last
// one of the same call) and reported as the board's ScanoutFrame with `reference` set to the
// model's frame.
#include <cstdint>
#include <vector>
#include <memory>
#include <mutex>

#include "gpubridge/backends/backend.hpp"

namespace gpubridge::daemon {

struct MirrorCounters {
  std::uint64_t model_errors = 0;     // commands the board accepted but the model refused
  std::uint64_t unpaired_frames = 0;  // swaps of one side only in a call (board scanout off, a failed call)
  std::uint64_t coalesced_swaps = 0;  // model swaps before the last one of a call (the board shows the last)

  // The daemon's STATUS adds up the counters of every mirror it served (a board that comes back
  // after an unplug gets a new MirrorBackend).
  MirrorCounters& operator+=(const MirrorCounters& o) {
    model_errors += o.model_errors;
    unpaired_frames += o.unpaired_frames;
    coalesced_swaps += o.coalesced_swaps;
    return *this;
  }
};

class MirrorBackend final : public backends::Backend {
 public:
  MirrorBackend(std::unique_ptr<backends::Backend> board, std::unique_ptr<backends::Backend> model);
  ~MirrorBackend() override;

  backends::DeviceInfo info() const override;  // the board's
  Result<void> write_frames(protocol::FrameView frames) override;
  Result<std::uint64_t> read_register(std::uint8_t index) override;
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override;
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override;
  Result<void> flush() override;
  Result<void> reset() override;
  void set_scanout_callback(backends::ScanoutCallback cb) override;
  void set_cancel_flag(const std::atomic<bool>* flag) override;  // both sides

  MirrorCounters counters() const;  // safe from any thread (STATUS reads it on the network thread)
  backends::Backend& board() { return *board_; }
  backends::Backend& model() { return *model_; }

 private:
  // The board's result decides; a model failure is only counted and logged (the board is the
  // device under test, the model must not make it fail).
  template <class T>
  Result<T> decide(Result<T> board_result, const Result<void>& model_result, const char* what);
  void emit_pairs();  // after each forwarded call: pair that call's frames and hand them out

  std::unique_ptr<backends::Backend> board_;
  std::unique_ptr<backends::Backend> model_;
  mutable std::mutex mu_;  // guards the queues, the callback and the counters
  std::vector<std::shared_ptr<const backends::ScanoutFrame>> board_frames_, model_frames_;  // this call's
  backends::ScanoutCallback callback_;
  MirrorCounters counters_;
};

// Wraps `board` with the simulator configured from the board's own description (memory size,
// framebuffer limits, FIFO depth and feature bits from CAPS). Fails when the backend is not a
// board or when gpubridged was built without the simulator.
Result<std::unique_ptr<backends::Backend>> make_mirror(std::unique_ptr<backends::Backend> board);

}  // namespace gpubridge::daemon
