#pragma once
// backends::Backend for a real (or emulated) FPGA board reached through a SpiBridge: burst writes
// under one chip select, FIFO flow control, strict link integrity with go-back-N resend,
// STATUS/ID/memory reads, upload/readback through MEM_ADDR/MEM_DATA and scanout frames.
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <mutex>
#include <optional>

#include "gpubridge/backends/backend.hpp"
#include "gpubridge/usb/board_profile.hpp"
#include "gpubridge/usb/spi_bridge.hpp"

namespace gpubridge::usb {

struct BoardOptions {
  unsigned max_link_retries = 8;   // resends of one batch before giving up with kDeviceProtocol
  unsigned max_status_polls = 20000;  // bounded polling of STATUS (flow control, flush, swap)
  std::uint64_t host_tag = 0;      // written to HOST_TAG at attach (0 = derived from the clock)
  bool verify_readback = true;     // read memory twice and compare (MISO has no checksum)
};

// Link counters for tests, benchmarks and `gpubridge bringup`.
struct LinkStats {
  std::uint64_t frames_sent = 0, payload_frames = 0, groups_sent = 0, groups_resent = 0, batches = 0;
  std::uint64_t status_polls = 0, recoveries = 0;
  std::uint64_t tag_rewrites = 0;  // HOST_TAG found overwritten by a garbled frame (not a reset) and written again
  std::uint64_t reset_retries = 0;  // RESET frames sent again because HOST_TAG showed the first did not act
};

class BoardBackend final : public backends::Backend {
 public:
  // `lower` keeps whatever sits below the bridge alive (libusb handle, chip model chain); it is
  // destroyed after the bridge. Attaching checks ID and CAPS, writes HOST_TAG and enables strict
  // link mode when the profile and the design both support it (else makes sure it is off).
  static Result<std::unique_ptr<BoardBackend>> attach(BoardProfile profile, std::shared_ptr<void> lower,
                                                      std::unique_ptr<SpiBridge> bridge, BoardOptions opts = {});
  ~BoardBackend() override;

  backends::DeviceInfo info() const override;
  Result<void> write_frames(protocol::FrameView frames) override;
  Result<std::uint64_t> read_register(std::uint8_t index) override;
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes) override;
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length) override;
  Result<void> flush() override;
  Result<void> reset() override;
  void set_scanout_callback(backends::ScanoutCallback cb) override;
  // Checked between the SPI transfers of a write batch.
  void set_cancel_flag(const std::atomic<bool>* flag) override { cancel_ = flag; }

  SpiBridge& bridge() { return *bridge_; }
  const BoardProfile& profile() const { return profile_; }
  const LinkStats& link_stats() const { return stats_; }
  bool strict_link() const { return strict_; }

 private:
  BoardBackend(BoardProfile profile, std::shared_ptr<void> lower, std::unique_ptr<SpiBridge> bridge, BoardOptions opts);
  Result<void> attach_locked();
  // Link layer (board_link.cpp).
  struct Batch;
  struct BatchStatus;
  struct SendProgress;
  Result<void> send_frames(std::span<const protocol::Frame> frames);  // writes, link + flow control
  Result<std::size_t> batch_room(std::size_t batch_limit, SendProgress& p);
  Batch build_batch(std::span<const protocol::Frame> rest, std::size_t max_frames, bool readdress) const;
  Result<BatchStatus> batch_status(const Result<std::vector<std::uint8_t>>& reply, SendProgress& p);
  Result<void> account_batch(const Batch& b, BatchStatus s, bool transfer_ok, std::span<const protocol::Frame> frames,
                             SendProgress& p);
  Result<std::vector<std::uint64_t>> read_frames(std::span<const std::uint8_t> indices);
  // The values of constant registers (ID, CAPS, CAPS2), each read twice per burst; a burst whose
  // pairs disagree is read again, three bursts at most.
  Result<std::vector<std::uint64_t>> read_constants(std::initializer_list<protocol::Reg> regs);
  Result<std::vector<std::uint8_t>> exchange(std::span<const SpiWindow> windows,
                                             std::span<const protocol::Frame> sent_in_order);
  Result<void> on_fault(const Error& e);
  Result<void> restart_link();
  Result<void> leave_strict_mode();
  Result<std::uint64_t> read_link_status_stable();
  protocol::Frame read_request(std::uint8_t index) const;
  Result<std::uint64_t> write_then_read(const protocol::Frame& w, protocol::Reg read);
  Result<void> write_host_tag();
  Result<void> check_host_tag();
  Result<std::uint64_t> poll_status(std::uint64_t mask, std::uint64_t want, const char* waiting_for);
  Result<unsigned> fifo_credits();
  void note_sent(const protocol::Frame& f);
  // Memory (board_memory.cpp).
  Result<std::vector<std::uint8_t>> readback_locked(std::uint32_t address, std::uint32_t length, bool verify);
  Result<std::vector<std::uint8_t>> read_memory_once(std::uint32_t start, std::size_t words);
  void track_memory_pointer(const protocol::Frame& f);
  // Scanout (board_scanout.cpp).
  Result<void> emit_scanout();
  // Attach and the Backend calls (board_backend.cpp).
  void track(const protocol::Frame& f);
  Error gone_error() const;

  BoardProfile profile_;
  std::shared_ptr<void> lower_;          // destroyed after bridge_ (declared first)
  std::unique_ptr<SpiBridge> bridge_;
  BoardOptions opts_;
  mutable std::mutex mu_;
  backends::ScanoutCallback scanout_cb_;
  const std::atomic<bool>* cancel_ = nullptr;
  std::uint64_t id_ = 0, caps_ = 0, caps2_ = 0;  // caps2_: 0 on a device before protocol 1.4 (no CAPS2)
  unsigned fifo_depth_ = 0;
  std::uint32_t vram_bytes_ = 0;
  bool strict_ = false, gone_ = false;
  std::uint32_t host_crc_ = 0;   // CRC-32 of frames sent since the last LINK_CHECK/LINK_CTRL
  std::uint16_t groups_ok_ = 0;  // LINK_STATUS.GROUPS_OK after the last accounted batch
  std::uint64_t tag_ = 0;
  std::uint64_t fb_format_ = 0, fb_display_ = 0;
  std::uint32_t frame_number_ = 0;
  std::optional<std::uint32_t> mem_addr_;  // device MEM_ADDR pointer after the last accepted write
  std::uint64_t board_resets_ = 0;        // resets (power cycles) detected through HOST_TAG
  LinkStats stats_;
  std::vector<std::shared_ptr<const backends::ScanoutFrame>> pending_frames_;  // emitted after unlocking
};

}  // namespace gpubridge::usb
