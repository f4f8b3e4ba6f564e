#include "gpubridge/daemon/mirror_backend.hpp"

#include <algorithm>

#include "gpubridge/common/log.hpp"

#include "gpubridge/sim/sim_backend.hpp"

namespace gpubridge::daemon {
namespace {

template <class T>
Result<void> as_void(const Result<T>& r) {
  if (r) return {};
  return r.error();
}

}  // namespace

MirrorBackend::MirrorBackend(std::unique_ptr<backends::Backend> board, std::unique_ptr<backends::Backend> model)
    : board_(std::move(board)), model_(std::move(model)) {
  // Both callbacks run on the thread that called into the backend (the daemon's device thread);
  // frames are collected and paired when the forwarded call has returned from both sides.
  board_->set_scanout_callback([this](std::shared_ptr<const backends::ScanoutFrame> f) {
    std::lock_guard lock(mu_);
    board_frames_.push_back(std::move(f));
  });
  model_->set_scanout_callback([this](std::shared_ptr<const backends::ScanoutFrame> f) {
    std::lock_guard lock(mu_);
    model_frames_.push_back(std::move(f));
  });
}

MirrorBackend::~MirrorBackend() {
  board_->set_scanout_callback({});
  model_->set_scanout_callback({});
}

backends::DeviceInfo MirrorBackend::info() const { return board_->info(); }

template <class T>
Result<T> MirrorBackend::decide(Result<T> board_result, const Result<void>& model_result, const char* what) {
  // A batch cancelled in the model (shutdown, client gone) is no disagreement with the board.
  if (board_result && !model_result && model_result.error().code != backends::kCancelled) {
    std::uint64_t n;
    {
      std::lock_guard lock(mu_);
      n = ++counters_.model_errors;
    }
    // The first few are worth a line each; after that the status counter tells the story.
    if (n <= 3)
      logger("daemon")->warn("mirror: the board accepted {} but the simulator refused it: {}", what,
                             model_result.error().message);
  }
  emit_pairs();
  return board_result;
}

Result<void> MirrorBackend::write_frames(protocol::FrameView frames) {
  auto b = board_->write_frames(frames);
  auto m = model_->write_frames(frames);
  return decide(std::move(b), m, "a WRITE_FRAMES batch");
}

Result<std::uint64_t> MirrorBackend::read_register(std::uint8_t index) {
  // The model reads too: reading MEM_DATA advances MEM_ADDR, and the two must stay in step.
  auto b = board_->read_register(index);
  auto m = model_->read_register(index);
  return decide(std::move(b), as_void(m), "a register read");
}

Result<void> MirrorBackend::upload(std::uint32_t address, std::span<const std::uint8_t> bytes) {
  auto b = board_->upload(address, bytes);
  auto m = model_->upload(address, bytes);
  return decide(std::move(b), m, "an upload");
}

Result<std::vector<std::uint8_t>> MirrorBackend::readback(std::uint32_t address, std::uint32_t length) {
  auto b = board_->readback(address, length);
  auto m = model_->readback(address, length);  // same side effects on MEM_ADDR; the data is the board's
  return decide(std::move(b), as_void(m), "a readback");
}

Result<void> MirrorBackend::flush() {
  auto b = board_->flush();
  auto m = model_->flush();
  return decide(std::move(b), m, "a flush");
}

Result<void> MirrorBackend::reset() {
  auto b = board_->reset();
  auto m = model_->reset();
  return decide(std::move(b), m, "a reset");
}

void MirrorBackend::set_cancel_flag(const std::atomic<bool>* flag) {
  board_->set_cancel_flag(flag);
  model_->set_cancel_flag(flag);
}

void MirrorBackend::set_scanout_callback(backends::ScanoutCallback cb) {
  std::lock_guard lock(mu_);
  callback_ = std::move(cb);
}

MirrorCounters MirrorBackend::counters() const {
  std::lock_guard lock(mu_);
  return counters_;
}

void MirrorBackend::emit_pairs() {
  // Pairing is per forwarded call. A board reports at most the state after a batch (it reads
  // FRAME_CRC once the batch is done), while the simulator reports every FB_DISPLAY; so the
  // board's last frame of a call pairs with the simulator's last, and the simulator's earlier swaps
  // of the same call are intermediate pictures nobody saw on the board. Frames of one side only
  // (board scanout "off", a call that failed on one side) pair with nothing and are counted.
  std::vector<std::shared_ptr<const backends::ScanoutFrame>> ready;
  backends::ScanoutCallback cb;
  {
    std::lock_guard lock(mu_);
    const std::size_t pairs = std::min(board_frames_.size(), model_frames_.size());
    if (pairs == 0) {
      counters_.unpaired_frames += board_frames_.size() + model_frames_.size();
    } else {
      counters_.unpaired_frames += board_frames_.size() - pairs;  // a board with more swaps than the model
      counters_.coalesced_swaps += model_frames_.size() - pairs;
    }
    for (std::size_t i = 0; i < pairs; ++i) {
      const auto& board = board_frames_[board_frames_.size() - pairs + i];
      auto paired = std::make_shared<backends::ScanoutFrame>(*board);
      paired->reference = model_frames_[model_frames_.size() - pairs + i];
      ready.push_back(std::move(paired));
    }
    board_frames_.clear();
    model_frames_.clear();
    cb = callback_;
  }
  // Outside the lock: the callback may take its time (PNG writing) and must not block the queues.
  if (cb)
    for (auto& f : ready) cb(std::move(f));
}

Result<std::unique_ptr<backends::Backend>> make_mirror(std::unique_ptr<backends::Backend> board) {
  const auto info = board->info();
  if (info.backend != "board")
    return make_error("--mirror needs a board backend (a board profile name, emulated:BOARD or rtl:BOARD), not \"" + info.backend +
                      "\": mirror mode compares a board with the simulator");
  sim::DeviceOptions o;  // accuracy: exact, always (the reference, whatever --accuracy says)
  // The model gets the board's memory and limits, so a command that does not fit the board does
  // not fit the model either (CAPS fields from the register table).
  o.vram_bytes = std::clamp<std::uint64_t>(info.vram_bytes / 1024 * 1024, 64 * 1024, sim::kMaxVramBytes);
  o.max_width = std::clamp(info.max_width, 1u, protocol::kMaxFramebufferDim);
  o.max_height = std::clamp(info.max_height, 1u, protocol::kMaxFramebufferDim);
  if (info.caps != 0) {
    const auto& caps = protocol::describe(protocol::Reg::CAPS);
    o.fifo_depth = std::clamp(static_cast<unsigned>(caps.field("FIFO_DEPTH")->get(info.caps)), 64u, 1023u);
    o.features = static_cast<std::uint8_t>(caps.field("FEATURES")->get(info.caps) & sim::kAllFeatures);
    // CAPS2 (protocol 1.4): a board without a depth buffer refuses Z, so the model must as well
    o.features2 = protocol::has_depth_buffer(info.id, info.caps2) ? sim::FEATURE2_DEPTH : 0;
  }
  auto model = sim::SimBackend::create(o);
  if (!model) return make_error("mirror: cannot create the simulator for board \"" + info.board + "\": " + model.error().message);
  logger("daemon")->info("mirror: board {} mirrored by the simulator ({} KiB, {}x{} max)", info.board, o.vram_bytes / 1024,
                         o.max_width, o.max_height);
  return std::unique_ptr<backends::Backend>(std::make_unique<MirrorBackend>(std::move(board), std::move(*model)));
}

}  // namespace gpubridge::daemon
