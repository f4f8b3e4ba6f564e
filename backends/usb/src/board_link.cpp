// Board backend, link layer: SPI windows through the bridge with every frame accounted into the
// host link CRC, register reads, STATUS polling and FIFO credits, recovery after a fault
// (HOST_TAG tells a board reset from a glitch), and the queued-write path: batches of link groups,
// flow control, go-back-N resend.
#include "gpubridge/usb/board_backend.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "board_parts.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/protocol/crc32.hpp"

namespace gpubridge::usb {

using namespace board;

void BoardBackend::note_sent(const Frame& f) {
  ++stats_.frames_sent;
  // Frames with index LINK_CTRL/LINK_CHECK (read or write) are outside the link CRC; writes restart it.
  if (f.index == index_of(Reg::LINK_CHECK) || f.index == index_of(Reg::LINK_CTRL)) {
    if (!f.read) host_crc_ = 0;
    return;
  }
  const auto bytes = protocol::encode(f);
  host_crc_ = protocol::crc32_update(host_crc_, bytes);
}

// Runs windows through the bridge; every frame in them is accounted into the host link CRC in
// wire order. MISO status bytes of captured frames must carry the marker (bit7=1, bit6=0).
Result<std::vector<std::uint8_t>> BoardBackend::exchange(std::span<const SpiWindow> windows,
                                                        std::span<const Frame> sent_in_order) {
  if (gone_) return gone_error();
  auto r = bridge_->transfer(windows);
  for (const auto& f : sent_in_order) note_sent(f);
  if (!r) return r.error();
  const auto& miso = *r;
  for (std::size_t off = 0; off + kFrameBytes <= miso.size(); off += kFrameBytes) {
    const std::uint8_t s = miso[off];
    if (protocol::miso_status_valid(s)) continue;
    const bool all_ones = std::all_of(miso.begin(), miso.end(), [](std::uint8_t b) { return b == 0xFF; });
    const bool all_zeros = std::all_of(miso.begin(), miso.end(), [](std::uint8_t b) { return b == 0x00; });
    std::string why = all_ones    ? "MISO reads all 1s: no configured FPGA (check the bitstream is loaded / CDONE)"
                      : all_zeros ? "MISO reads all 0s: FPGA held in reset or MISO not connected"
                                  : "status byte 0x" + fmt::format("{:02X}", s) + " lacks the marker (SPI bit error?)";
    return make_error("board '" + profile_.name + "': " + why, backends::kDeviceProtocol);
  }
  return r;
}

// The data bits of a read are ignored by the device (docs/protocol.md 2.2); a HOST_TAG read carries
// the tag, so a MOSI bit error that turns it into a write rewrites the same tag instead of zeroing
// it, which would look exactly like a board reset.
Frame BoardBackend::read_request(std::uint8_t index) const {
  return Frame{true, index, index == index_of(Reg::HOST_TAG) ? tag_ : 0};
}

Result<std::vector<std::uint64_t>> BoardBackend::read_frames(std::span<const std::uint8_t> indices) {
  std::vector<Frame> frames;
  std::vector<std::uint8_t> mosi;
  for (auto i : indices) {
    frames.push_back(read_request(i));
    append_frame(mosi, frames.back());
  }
  const SpiWindow w{mosi, true, {}};
  auto r = exchange(std::span(&w, 1), frames);
  if (!r) return r.error();
  std::vector<std::uint64_t> values;
  for (std::size_t k = 0; k < indices.size(); ++k) values.push_back(frame_value(*r, k));
  return values;
}

// LINK_CTRL(STRICT=1): restarts both CRCs and leaves DISCARDING; then the baseline GROUPS_OK.
Result<void> BoardBackend::restart_link() {
  std::vector<std::uint8_t> mosi;
  const Frame ctrl = protocol::write_frame(Reg::LINK_CTRL, 1);
  append_frame(mosi, ctrl);
  const SpiWindow w{mosi, false, {}};
  if (auto r = exchange(std::span(&w, 1), std::span(&ctrl, 1)); !r) return r.error();
  auto ls = read_link_status_stable();
  if (!ls) return ls.error();
  if (*ls & kLinkDiscarding)
    return make_error("board '" + profile_.name + "': LINK_CTRL write did not leave DISCARDING", backends::kDeviceProtocol);
  groups_ok_ = groups_ok_of(*ls);
  return {};
}

// Strict mode unwanted on a design that has it: a previous session (another profile) may have left
// it on, and its held writes would never execute. Leaving it takes LINK_CTRL.CLEAR_KEY since
// protocol 1.3; to older devices those bits are reserved (ERR_RESERVED_BITS), so they get a plain
// 0 (docs/protocol.md section 4). Immediate and unprotected: read back, sent again while STRICT
// still reads 1.
Result<void> BoardBackend::leave_strict_mode() {
  const Frame clear = protocol::write_frame(Reg::LINK_CTRL, protocol::link_ctrl_clear_value(id_));
  for (unsigned attempt = 0; attempt < 3; ++attempt) {
    auto strict = write_then_read(clear, Reg::LINK_CTRL);
    if (!strict) return strict.error();
    if (!(*strict & 1)) return {};
  }
  return make_error("board '" + profile_.name + "': LINK_CTRL still reads STRICT = 1 after 3 writes leaving strict mode; " +
                        "SPI bit errors: lower bridge.spi_clock_hz",
                    backends::kDeviceProtocol);
}

// LINK_STATUS read twice in one window: the counters (bits 63..24) must agree, so a MISO bit
// error cannot make us believe a group was accepted.
Result<std::uint64_t> BoardBackend::read_link_status_stable() {
  const std::uint8_t idx[] = {index_of(Reg::LINK_STATUS), index_of(Reg::LINK_STATUS)};
  for (unsigned attempt = 0; attempt < 4; ++attempt) {
    auto v = read_frames(idx);
    if (!v) return v.error();
    if (((*v)[0] >> 24) == ((*v)[1] >> 24)) return (*v)[0];
  }
  return make_error("board '" + profile_.name + "': LINK_STATUS reads disagree repeatedly (MISO bit errors); lower the SPI clock",
                    backends::kDeviceProtocol);
}

// One transfer: the immediate write `w`, then a read of `read`; returns what the read returned (the
// host's way to see that an immediate write acted).
Result<std::uint64_t> BoardBackend::write_then_read(const Frame& w, Reg read) {
  std::vector<std::uint8_t> mosi;
  const Frame frames[] = {w, read_request(index_of(read))};
  append_frame(mosi, frames[0]);
  append_frame(mosi, frames[1]);
  const SpiWindow windows[] = {{std::span(mosi).first(kFrameBytes), false, {}}, {std::span(mosi).subspan(kFrameBytes), true, {}}};
  auto r = exchange(windows, frames);
  if (!r) return r.error();
  return frame_value(*r, 0);
}

// HOST_TAG written and read back, written again (a bounded number of times) while the echo
// differs: the write is immediate and unprotected, so a MOSI bit error may garble it.
Result<void> BoardBackend::write_host_tag() {
  std::uint64_t got = 0;
  for (unsigned attempt = 0; attempt < 3; ++attempt) {
    auto echo = write_then_read(protocol::write_frame(Reg::HOST_TAG, tag_), Reg::HOST_TAG);
    if (!echo) return echo.error();
    got = *echo;
    if (got == tag_) return {};
  }
  return make_error("board '" + profile_.name + "': HOST_TAG echo failed (wrote 0x" + fmt::format("{:016X}", tag_) +
                        ", read 0x" + fmt::format("{:016X}", got) + "); writes do not reach the device",
                    backends::kDeviceProtocol);
}

// HOST_TAG differs from ours. Every reset sets it to 0 (docs/protocol.md section 4), so only 0 means
// the board was reset; any other value was written by a frame a bit error turned into a HOST_TAG
// write (e.g. LINK_CHECK 0x14 -> 0x16): the device kept its state, the tag is written again, and
// in strict mode the group that lost the frame fails its check and is resent.
Result<void> BoardBackend::check_host_tag() {
  const std::uint8_t idx[] = {index_of(Reg::HOST_TAG)};
  std::uint64_t last = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {
    auto v = read_frames(idx);
    if (!v) return v.error();
    if ((*v)[0] == tag_) return {};
    last = (*v)[0];
  }
  if (last != 0) {
    ++stats_.tag_rewrites;
    gpubridge::logger("usb")->debug("board {}: HOST_TAG reads 0x{:X}, not a reset (0): writing the tag again", profile_.name, last);
    return write_host_tag();
  }
  ++board_resets_;
  mem_addr_.reset();
  const std::string msg = "board '" + profile_.name + "' was reset (HOST_TAG reads 0): power cycle or FPGA reconfiguration, "
                          "device state lost; the board was re-attached and state must be replayed";
  if (auto r = attach_locked(); !r) return make_error(msg + "; re-attach failed: " + r.error().message, r.error().code);
  return make_error(msg, backends::kDeviceProtocol);
}

Result<void> BoardBackend::on_fault(const Error& e) {
  if (e.code == backends::kDeviceGone) {
    gone_ = true;
    return e;
  }
  ++stats_.recoveries;
  gpubridge::logger("usb")->debug("board {}: recovering after: {}", profile_.name, e.message);
  if (auto r = bridge_->recover(); !r) {
    if (r.error().code == backends::kDeviceGone) gone_ = true;
    return r;
  }
  return check_host_tag();
}

// STATUS is read twice per poll (one transfer) and the wait ends only when both reads show it
// ended: a MOSI bit error turns a STATUS read into a read of another register or a write, whose
// MISO data (often 0) would otherwise pass for an idle device; one error cannot garble both.
Result<std::uint64_t> BoardBackend::poll_status(std::uint64_t mask, std::uint64_t want, const char* waiting_for) {
  const std::uint8_t idx[] = {index_of(Reg::STATUS), index_of(Reg::STATUS)};
  std::uint64_t last = 0;
  for (unsigned i = 0; i < opts_.max_status_polls; ++i) {
    ++stats_.status_polls;
    auto v = read_frames(idx);
    if (!v) return v.error();
    last = (*v)[1];
    if (((*v)[0] & mask) == want && (last & mask) == want) return last;
  }
  return make_error("board '" + profile_.name + "': timed out waiting for " + waiting_for + " after " +
                        std::to_string(opts_.max_status_polls) + " STATUS polls (last 0x" + fmt::format("{:016X}", last) +
                        "); the device is stuck",
                    backends::kDeviceTimeout);
}

// FIFO_LEVEL from two STATUS reads in one transfer, the higher one counting (a garbled read must
// not grant credits the FIFO does not have).
Result<unsigned> BoardBackend::fifo_credits() {
  const std::uint8_t idx[] = {index_of(Reg::STATUS), index_of(Reg::STATUS)};
  for (unsigned i = 0; i < opts_.max_status_polls; ++i) {
    ++stats_.status_polls;
    auto v = read_frames(idx);
    if (!v) return v.error();
    const unsigned level = static_cast<unsigned>(std::max((*v)[0] & kStatusLevelMask, (*v)[1] & kStatusLevelMask));
    if (level + kGroupFrames <= fifo_depth_) return fifo_depth_ - level;
  }
  return make_error("board '" + profile_.name + "': command FIFO never drained below " +
                        std::to_string(fifo_depth_ - kGroupFrames) + " entries (flow control stuck)",
                    backends::kDeviceTimeout);
}

// ---- queued writes -----------------------------------------------------------------------

// One transfer of the frames still to send: groups of at most kGroupFrames payload frames (the
// first led by MEM_ADDR after a failed batch; each closed by LINK_CHECK in strict mode), then the
// status reads that ride in the same transfer, so a batch costs no extra round trip.
struct BoardBackend::Batch {
  std::vector<Frame> wire;               // every frame of the transfer, in wire order
  std::vector<std::uint8_t> mosi;        // their bytes: the groups, then the status reads
  std::vector<std::size_t> groups;       // payload frames per group
  std::size_t payload = 0;               // payload frames in all
  std::size_t body_bytes = 0;            // MOSI bytes of the groups
  std::vector<std::size_t> busy_waits;   // MOSI offsets of the group starts: wait for BUSY low there
};

// What the send loop carries from one batch to the next.
struct BoardBackend::SendProgress {
  std::size_t done = 0;      // payload frames the device has accepted
  unsigned failures = 0;     // failed attempts so far
  bool resync_mem = false;   // a batch failed: MEM_DATA's pointer may have moved, re-send MEM_ADDR
  std::string last_problem;  // for the give-up message
};

// The batch's status reads: LINK_STATUS twice and HOST_TAG in strict mode, else STATUS and HOST_TAG.
struct BoardBackend::BatchStatus {
  std::uint64_t link_status = 0, status = 0;
};

// How many frames the next batch may carry: the bridge's preferred batch, and with no hardware
// BUSY wait the FIFO credits STATUS grants. 0 after a fault was recovered (try again).
Result<std::size_t> BoardBackend::batch_room(std::size_t batch_limit, SendProgress& p) {
  if (bridge_->hardware_busy_wait()) return batch_limit;
  auto credits = fifo_credits();
  if (credits) return std::min<std::size_t>(batch_limit, *credits);
  if (credits.error().code == backends::kDeviceTimeout) return credits.error();
  p.last_problem = credits.error().message;
  ++p.failures;
  if (auto f = on_fault(credits.error()); !f) return f.error();
  if (strict_)
    if (auto r = restart_link(); !r) return r.error();
  return std::size_t{0};
}

BoardBackend::Batch BoardBackend::build_batch(std::span<const Frame> rest, std::size_t max_frames, bool readdress) const {
  Batch b;
  std::uint32_t crc = host_crc_;
  auto put = [&](const Frame& f) {
    b.wire.push_back(f);
    const auto bytes = protocol::encode(f);
    crc = protocol::crc32_update(crc, bytes);
    b.mosi.insert(b.mosi.end(), bytes.begin(), bytes.end());
  };
  while (b.payload < rest.size() && b.payload < max_frames) {
    const bool lead = readdress && b.groups.empty();
    const std::size_t n = std::min({lead ? kGroupFrames - 1 : kGroupFrames, rest.size() - b.payload, max_frames - b.payload});
    b.busy_waits.push_back(b.mosi.size());
    if (lead) put(protocol::write_frame(Reg::MEM_ADDR, *mem_addr_));
    for (std::size_t k = 0; k < n; ++k) put(rest[b.payload + k]);
    if (strict_) {
      b.wire.push_back(protocol::write_frame(Reg::LINK_CHECK, crc));
      append_frame(b.mosi, b.wire.back());
      crc = 0;
    }
    b.groups.push_back(n);
    b.payload += n;
  }
  b.body_bytes = b.mosi.size();
  const Frame tail_strict[] = {protocol::read_frame(Reg::LINK_STATUS), protocol::read_frame(Reg::LINK_STATUS),
                               read_request(index_of(Reg::HOST_TAG))};
  const Frame tail_plain[] = {protocol::read_frame(Reg::STATUS), read_request(index_of(Reg::HOST_TAG))};
  for (const auto& f : strict_ ? std::span<const Frame>(tail_strict) : std::span<const Frame>(tail_plain)) {
    b.wire.push_back(f);
    append_frame(b.mosi, f);
  }
  return b;
}

// The status a batch ended with. A failed transfer is a fault: recovered here, then (strict mode)
// LINK_STATUS says which groups arrived; without strict mode nothing can say, so it is an error.
Result<BoardBackend::BatchStatus> BoardBackend::batch_status(const Result<std::vector<std::uint8_t>>& reply, SendProgress& p) {
  BatchStatus s;
  if (!reply) {
    p.last_problem = reply.error().message;
    ++p.failures;
    p.resync_mem = true;
    if (auto f = on_fault(reply.error()); !f) return f.error();
    if (!strict_)
      return make_error(reply.error().message + " (strict link mode is off, so the batch cannot be resent safely)",
                        reply.error().code);
    auto ls = read_link_status_stable();
    if (!ls) return ls.error();
    s.link_status = *ls;
    return s;
  }
  // The reply holds the captured window only: the status reads.
  std::uint64_t tag = 0;
  if (strict_) {
    s.link_status = frame_value(*reply, 0);
    tag = frame_value(*reply, 2);
    if ((s.link_status >> 24) != (frame_value(*reply, 1) >> 24)) {  // counters disagree: MISO bit error
      auto ls = read_link_status_stable();
      if (!ls) return ls.error();
      s.link_status = *ls;
    }
  } else {
    s.status = frame_value(*reply, 0);
    tag = frame_value(*reply, 1);
  }
  if (tag != tag_)
    if (auto t = check_host_tag(); !t) return t.error();
  return s;
}

// Moves `done` past what the device accepted. Strict mode: the accepted groups are a prefix of
// the batch (after a failed check the device discards until LINK_CTRL), the rest is resent.
Result<void> BoardBackend::account_batch(const Batch& b, BatchStatus s, bool transfer_ok, std::span<const Frame> frames,
                                         SendProgress& p) {
  if (!strict_) {
    const std::uint16_t errors = static_cast<std::uint16_t>(s.status >> 48);
    if (errors & (protocol::ERR_OVERFLOW | protocol::ERR_FRAMING))
      return make_error("board '" + profile_.name + "': device reports " + protocol::describe_errors(errors) +
                            " after a batch (strict link mode is off, so writes may have been lost)",
                        backends::kDeviceProtocol);
    for (std::size_t k = p.done; k < p.done + b.payload; ++k) track_memory_pointer(frames[k]);
    p.done += b.payload;
    stats_.payload_frames += b.payload;
    return {};
  }
  const std::uint16_t ok_now = groups_ok_of(s.link_status);
  const std::size_t accepted = std::min<std::size_t>(static_cast<std::uint16_t>(ok_now - groups_ok_), b.groups.size());
  groups_ok_ = ok_now;
  for (std::size_t g = 0; g < accepted; ++g) {
    for (std::size_t k = 0; k < b.groups[g]; ++k) track_memory_pointer(frames[p.done + k]);
    p.done += b.groups[g];
    stats_.payload_frames += b.groups[g];
  }
  if (accepted > 0) p.resync_mem = false;
  if (accepted < b.groups.size()) {
    p.resync_mem = true;
    if (transfer_ok) {
      p.last_problem = "link CRC check failed for " + std::to_string(b.groups.size() - accepted) + " group(s)";
      ++p.failures;
    }
    stats_.groups_resent += b.groups.size() - accepted;
    if (auto r = restart_link(); !r) return r;
  }
  return {};
}

// Queued writes, in order, exactly once: groups of ≤ 32 frames, each followed by LINK_CHECK in
// strict mode; flow control by BUSY waits (FTDI) or FIFO credits from STATUS; go-back-N resend.
Result<void> BoardBackend::send_frames(std::span<const Frame> frames) {
  SendProgress p;
  const std::size_t batch_limit = std::max<std::size_t>(kGroupFrames, bridge_->preferred_batch_bytes() / kFrameBytes);
  while (p.done < frames.size()) {
    if (cancel_ && cancel_->load(std::memory_order_relaxed))
      return make_error("board '" + profile_.name + "': write batch cancelled after " + std::to_string(p.done) + " of " +
                            std::to_string(frames.size()) + " frames",
                        backends::kCancelled);
    if (p.failures > opts_.max_link_retries)
      return make_error("board '" + profile_.name + "': gave up after " + std::to_string(p.failures) +
                            " failed attempts to deliver a batch (" + p.last_problem + ")",
                        backends::kDeviceProtocol);
    auto room = batch_room(batch_limit, p);
    if (!room) return room.error();
    if (*room == 0) continue;
    const Batch b = build_batch(frames.subspan(p.done), *room, p.resync_mem && mem_addr_.has_value());
    const SpiWindow windows[] = {{std::span(b.mosi).first(b.body_bytes), false, b.busy_waits},
                                 {std::span(b.mosi).subspan(b.body_bytes), true, {}}};
    ++stats_.batches;
    stats_.groups_sent += b.groups.size();
    const auto reply = exchange(windows, b.wire);
    auto s = batch_status(reply, p);
    if (!s) return s.error();
    if (auto r = account_batch(b, *s, reply.ok(), frames, p); !r) return r;
  }
  return {};
}

}  // namespace gpubridge::usb
