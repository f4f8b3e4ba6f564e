// Board backend: the host side of docs/protocol.md "SPI link" over any SpiBridge.
#include "gpubridge/usb/board_backend.hpp"

#include <algorithm>
#include <chrono>

#include "gpubridge/common/log.hpp"
#include "gpubridge/protocol/crc32.hpp"

namespace gpubridge::usb {
namespace {

using protocol::Frame;
using protocol::Reg;
using protocol::index_of;
using protocol::kFrameBytes;

constexpr std::size_t kGroupFrames = 32;  // queued frames per BUSY check / link group
constexpr std::uint64_t kStatusBusy = 1ull << 16, kStatusMemReady = 1ull << 18, kStatusSwapPending = 1ull << 19,
                        kStatusLinkPending = 1ull << 20, kStatusLevelMask = 0xFFFF;
constexpr std::uint64_t kLinkDiscarding = 1ull << 24;
constexpr unsigned kScanoutAttempts = 3;

std::uint16_t groups_ok_of(std::uint64_t link_status) { return static_cast<std::uint16_t>(link_status >> 32); }

void append_frame(std::vector<std::uint8_t>& out, const Frame& f) { protocol::append(out, f); }

}  // namespace

BoardBackend::BoardBackend(BoardProfile profile, std::shared_ptr<void> lower, std::unique_ptr<SpiBridge> bridge,
                           BoardOptions opts)
    : profile_(std::move(profile)), lower_(std::move(lower)), bridge_(std::move(bridge)), opts_(opts) {}

BoardBackend::~BoardBackend() = default;

Result<std::unique_ptr<BoardBackend>> BoardBackend::attach(BoardProfile profile, std::shared_ptr<void> lower,
                                                          std::unique_ptr<SpiBridge> bridge, BoardOptions opts) {
  std::unique_ptr<BoardBackend> b(new BoardBackend(std::move(profile), std::move(lower), std::move(bridge), opts));
  std::lock_guard lock(b->mu_);
  if (auto r = b->attach_locked(); !r) return r.error();
  return b;
}

Error BoardBackend::gone_error() const {
  return make_error("board '" + profile_.name + "': the " + std::string(to_string(profile_.chip)) +
                        " adapter is gone (unplugged); replug it and reattach",
                    backends::kDeviceGone);
}

backends::DeviceInfo BoardBackend::info() const {
  std::lock_guard lock(mu_);
  backends::DeviceInfo i;
  i.backend = "board";
  i.board = profile_.name;
  i.bridge = std::string(bridge_->chip());
  i.max_width = std::min<unsigned>(profile_.max_width, (caps_ >> 24) & 0x7FF ? (caps_ >> 24) & 0x7FF : profile_.max_width);
  i.max_height = std::min<unsigned>(profile_.max_height, (caps_ >> 35) & 0x7FF ? (caps_ >> 35) & 0x7FF : profile_.max_height);
  i.vram_bytes = vram_bytes_;
  i.id = id_;
  i.caps = caps_;
  return i;
}

void BoardBackend::set_scanout_callback(backends::ScanoutCallback cb) {
  std::lock_guard lock(mu_);
  scanout_cb_ = std::move(cb);
}

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

void BoardBackend::track_memory_pointer(const Frame& f) {
  if (f.read) return;
  if (f.index == index_of(Reg::MEM_ADDR)) mem_addr_ = static_cast<std::uint32_t>(f.data & 0xFFFFFFF8u);
  else if (f.index == index_of(Reg::MEM_DATA) && mem_addr_) *mem_addr_ += 8;
}

void BoardBackend::track(const Frame& f) {
  if (f.index == index_of(Reg::FB_FORMAT)) fb_format_ = f.data;
  if (f.index == index_of(Reg::FB_DISPLAY)) fb_display_ = f.data;
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

Result<std::vector<std::uint64_t>> BoardBackend::read_frames(std::span<const std::uint8_t> indices) {
  std::vector<Frame> frames;
  std::vector<std::uint8_t> mosi;
  for (auto i : indices) {
    frames.push_back(Frame{true, i, 0});
    append_frame(mosi, frames.back());
  }
  const SpiWindow w{mosi, true, {}};
  auto r = exchange(std::span(&w, 1), frames);
  if (!r) return r.error();
  std::vector<std::uint64_t> values;
  for (std::size_t k = 0; k < indices.size(); ++k) {
    std::uint64_t v = 0;
    for (int b = 1; b <= 8; ++b) v = v << 8 | (*r)[k * kFrameBytes + static_cast<std::size_t>(b)];
    values.push_back(v);
  }
  return values;
}

Result<void> BoardBackend::attach_locked() {
  const std::uint8_t id_caps[] = {index_of(Reg::ID), index_of(Reg::ID), index_of(Reg::CAPS)};
  auto v = read_frames(id_caps);
  if (!v) return v.error();
  const std::uint64_t id = (*v)[0];
  if (id != (*v)[1])
    return make_error("board '" + profile_.name + "': two ID reads differ (0x" + fmt::format("{:016X}", id) + " vs 0x" +
                          fmt::format("{:016X}", (*v)[1]) + "): unreliable SPI link; lower bridge.spi_clock_hz",
                      backends::kDeviceProtocol);
  if ((id >> 32) != protocol::kIdMagic)
    return make_error("board '" + profile_.name + "': ID register reads 0x" + fmt::format("{:016X}", id) +
                          ", not a spigpu design (magic 0x53504755); load the gpubridge bitstream",
                      backends::kDeviceProtocol);
  if (((id >> 24) & 0xFF) != protocol::kVersionMajor)
    return make_error("board '" + profile_.name + "': spigpu protocol major version " + std::to_string((id >> 24) & 0xFF) +
                          " is not supported (this host speaks v1)",
                      backends::kDeviceProtocol);
  id_ = id;
  caps_ = (*v)[2];
  const unsigned caps_depth = (caps_ >> 46) & 0x3FF;
  fifo_depth_ = caps_depth ? std::min(caps_depth, profile_.fifo_depth) : profile_.fifo_depth;
  const std::uint64_t caps_vram = (caps_ & 0xFFFFFF) * 1024;
  vram_bytes_ = static_cast<std::uint32_t>(std::min<std::uint64_t>(caps_vram ? caps_vram : ~0ull, std::uint64_t{profile_.vram_kib} * 1024));
  fb_format_ = protocol::describe(Reg::FB_FORMAT).reset;
  fb_display_ = 0;
  mem_addr_.reset();  // unknown until a MEM_ADDR write is accepted

  // Register echo through HOST_TAG: proves writes land and lets us detect board resets later.
  tag_ = opts_.host_tag;
  if (!tag_) tag_ = static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()) | 1;
  std::vector<std::uint8_t> mosi;
  const Frame frames[] = {protocol::write_frame(Reg::HOST_TAG, tag_), protocol::read_frame(Reg::HOST_TAG)};
  append_frame(mosi, frames[0]);
  append_frame(mosi, frames[1]);
  const SpiWindow windows[] = {{std::span(mosi).first(kFrameBytes), false, {}}, {std::span(mosi).subspan(kFrameBytes), true, {}}};
  auto echo = exchange(windows, frames);
  if (!echo) return echo.error();
  std::uint64_t got = 0;
  for (int b = 1; b <= 8; ++b) got = got << 8 | (*echo)[static_cast<std::size_t>(b)];
  if (got != tag_)
    return make_error("board '" + profile_.name + "': HOST_TAG echo failed (wrote 0x" + fmt::format("{:016X}", tag_) +
                          ", read 0x" + fmt::format("{:016X}", got) + "); writes do not reach the device",
                      backends::kDeviceProtocol);

  const bool design_strict = (caps_ >> 56) & 0x08;
  strict_ = profile_.strict_link && design_strict;
  if (strict_) return restart_link();
  return {};
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

Result<void> BoardBackend::check_host_tag() {
  const std::uint8_t idx[] = {index_of(Reg::HOST_TAG)};
  std::uint64_t last = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {
    auto v = read_frames(idx);
    if (!v) return v.error();
    if ((*v)[0] == tag_) return {};
    last = (*v)[0];
  }
  ++board_resets_;
  mem_addr_.reset();
  const std::string msg = "board '" + profile_.name + "' was reset (HOST_TAG reads 0x" + fmt::format("{:X}", last) +
                          "): power cycle or FPGA reconfiguration, device state lost; the board was re-attached and "
                          "state must be replayed";
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

Result<std::uint64_t> BoardBackend::poll_status(std::uint64_t mask, std::uint64_t want, const char* waiting_for) {
  const std::uint8_t idx[] = {index_of(Reg::STATUS)};
  std::uint64_t last = 0;
  for (unsigned i = 0; i < opts_.max_status_polls; ++i) {
    ++stats_.status_polls;
    auto v = read_frames(idx);
    if (!v) return v.error();
    last = (*v)[0];
    if ((last & mask) == want) return last;
  }
  return make_error("board '" + profile_.name + "': timed out waiting for " + waiting_for + " after " +
                        std::to_string(opts_.max_status_polls) + " STATUS polls (last 0x" + fmt::format("{:016X}", last) +
                        "); the device is stuck",
                    backends::kDeviceTimeout);
}

Result<unsigned> BoardBackend::fifo_credits() {
  const std::uint8_t idx[] = {index_of(Reg::STATUS)};
  for (unsigned i = 0; i < opts_.max_status_polls; ++i) {
    ++stats_.status_polls;
    auto v = read_frames(idx);
    if (!v) return v.error();
    const unsigned level = static_cast<unsigned>((*v)[0] & kStatusLevelMask);
    if (level + kGroupFrames <= fifo_depth_) return fifo_depth_ - level;
  }
  return make_error("board '" + profile_.name + "': command FIFO never drained below " +
                        std::to_string(fifo_depth_ - kGroupFrames) + " entries (flow control stuck)",
                    backends::kDeviceTimeout);
}

// Queued writes, in order, exactly once: groups of ≤ 32 frames, each followed by LINK_CHECK in
// strict mode; flow control by BUSY waits (FTDI) or FIFO credits from STATUS; go-back-N resend.
Result<void> BoardBackend::send_frames(std::span<const Frame> frames) {
  std::size_t done = 0;
  unsigned failures = 0;
  bool resync_mem = false;
  std::string last_problem;
  const std::size_t batch_limit = std::max<std::size_t>(kGroupFrames, bridge_->preferred_batch_bytes() / kFrameBytes);
  while (done < frames.size()) {
    if (cancel_ && cancel_->load(std::memory_order_relaxed))
      return make_error("board '" + profile_.name + "': write batch cancelled after " + std::to_string(done) + " of " +
                            std::to_string(frames.size()) + " frames",
                        backends::kCancelled);
    if (failures > opts_.max_link_retries)
      return make_error("board '" + profile_.name + "': gave up after " + std::to_string(failures) +
                            " failed attempts to deliver a batch (" + last_problem + ")",
                        backends::kDeviceProtocol);
    std::size_t max_frames = batch_limit;
    if (!bridge_->hardware_busy_wait()) {
      auto credits = fifo_credits();
      if (!credits) {
        if (credits.error().code == backends::kDeviceTimeout) return credits.error();
        last_problem = credits.error().message;
        ++failures;
        if (auto f = on_fault(credits.error()); !f) return f;
        if (strict_) if (auto r = restart_link(); !r) return r;
        continue;
      }
      max_frames = std::min<std::size_t>(max_frames, *credits);
    }
    // Build the batch.
    std::vector<Frame> wire;
    std::vector<std::uint8_t> mosi;
    std::vector<std::size_t> group_sizes;
    SpiWindow batch;
    std::uint32_t crc = host_crc_;
    std::size_t at = done, in_batch = 0;
    auto put = [&](const Frame& f) {
      wire.push_back(f);
      const auto bytes = protocol::encode(f);
      crc = protocol::crc32_update(crc, bytes);
      mosi.insert(mosi.end(), bytes.begin(), bytes.end());
    };
    // After a failed batch the MEM_DATA pointer may have moved (a corrupted frame can arrive as
    // an immediate MEM_DATA read), so a resend re-establishes it before any MEM_DATA write.
    const bool readdress = resync_mem && mem_addr_.has_value();
    while (at < frames.size() && in_batch < max_frames) {
      const std::size_t room = (readdress && group_sizes.empty()) ? kGroupFrames - 1 : kGroupFrames;
      const std::size_t n = std::min({room, frames.size() - at, max_frames - in_batch});
      batch.busy_waits.push_back(mosi.size());
      if (readdress && group_sizes.empty()) put(protocol::write_frame(Reg::MEM_ADDR, *mem_addr_));
      for (std::size_t k = 0; k < n; ++k) put(frames[at + k]);
      if (strict_) {
        wire.push_back(protocol::write_frame(Reg::LINK_CHECK, crc));
        append_frame(mosi, wire.back());
        crc = 0;
      }
      group_sizes.push_back(n);
      at += n;
      in_batch += n;
    }
    const std::size_t batch_bytes = mosi.size();
    // Status reads ride in the same transfer: no extra round trip per batch.
    const Frame tail_strict[] = {protocol::read_frame(Reg::LINK_STATUS), protocol::read_frame(Reg::LINK_STATUS),
                                 protocol::read_frame(Reg::HOST_TAG)};
    const Frame tail_plain[] = {protocol::read_frame(Reg::STATUS), protocol::read_frame(Reg::HOST_TAG)};
    const std::span<const Frame> tail = strict_ ? std::span<const Frame>(tail_strict) : std::span<const Frame>(tail_plain);
    for (const auto& f : tail) {
      wire.push_back(f);
      append_frame(mosi, f);
    }
    batch.mosi = std::span(mosi).first(batch_bytes);
    const SpiWindow windows[] = {batch, {std::span(mosi).subspan(batch_bytes), true, {}}};
    ++stats_.batches;
    stats_.groups_sent += group_sizes.size();
    auto r = exchange(windows, wire);

    std::uint64_t link_status = 0, tag = 0, status = 0;
    if (r) {
      auto word = [&](std::size_t k) {
        std::uint64_t v = 0;
        for (std::size_t b = 1; b <= 8; ++b) v = v << 8 | (*r)[k * kFrameBytes + b];
        return v;
      };
      if (strict_) {
        link_status = word(0);
        tag = word(2);
        if ((word(0) >> 24) != (word(1) >> 24)) {
          auto s = read_link_status_stable();
          if (!s) return s.error();
          link_status = *s;
        }
      } else {
        status = word(0);
        tag = word(1);
      }
      if (tag != tag_) {
        if (auto t = check_host_tag(); !t) return t;
      }
    } else {
      last_problem = r.error().message;
      ++failures;
      resync_mem = true;
      if (auto f = on_fault(r.error()); !f) return f;
      if (!strict_)
        return make_error(r.error().message + " (strict link mode is off, so the batch cannot be resent safely)",
                          r.error().code);
      auto s = read_link_status_stable();
      if (!s) return s.error();
      link_status = *s;
    }

    if (!strict_) {
      const std::uint16_t errors = static_cast<std::uint16_t>(status >> 48);
      if (errors & (protocol::ERR_OVERFLOW | protocol::ERR_FRAMING))
        return make_error("board '" + profile_.name + "': device reports " + protocol::describe_errors(errors) +
                              " after a batch (strict link mode is off, so writes may have been lost)",
                          backends::kDeviceProtocol);
      for (std::size_t k = done; k < at; ++k) track_memory_pointer(frames[k]);
      done = at;
      stats_.payload_frames += in_batch;
      continue;
    }
    // Accepted groups form a prefix of the batch (after a failed check the device discards).
    const std::uint16_t ok_now = groups_ok_of(link_status);
    std::size_t accepted = static_cast<std::uint16_t>(ok_now - groups_ok_);
    accepted = std::min(accepted, group_sizes.size());
    groups_ok_ = ok_now;
    for (std::size_t g = 0; g < accepted; ++g) {
      for (std::size_t k = 0; k < group_sizes[g]; ++k) track_memory_pointer(frames[done + k]);
      done += group_sizes[g];
      stats_.payload_frames += group_sizes[g];
    }
    if (accepted > 0) resync_mem = false;
    if (accepted < group_sizes.size()) {
      resync_mem = true;
      if (r) {
        last_problem = "link CRC check failed for " + std::to_string(group_sizes.size() - accepted) + " group(s)";
        ++failures;
      }
      stats_.groups_resent += group_sizes.size() - accepted;
      if (auto rl = restart_link(); !rl) return rl;
    }
  }
  return {};
}

Result<void> BoardBackend::write_frames(protocol::FrameView view) {
  std::vector<std::shared_ptr<const backends::ScanoutFrame>> emitted;
  backends::ScanoutCallback cb;
  {
    std::lock_guard lock(mu_);
    if (gone_) return gone_error();
    if (view.bytes.size() % kFrameBytes != 0)
      return make_error("write_frames: " + std::to_string(view.bytes.size()) + " bytes is not a whole number of 9-byte frames",
                        backends::kBadRequest);
    std::vector<Frame> frames;
    frames.reserve(view.size());
    bool swaps = false;
    for (std::size_t i = 0; i < view.size(); ++i) {
      const Frame f = view[i];
      if (f.read)
        return make_error("write_frames: frame " + std::to_string(i) + " is a read (R/W̄ = 1); use read_register",
                          backends::kBadRequest);
      if (f.index == index_of(Reg::LINK_CTRL) || f.index == index_of(Reg::LINK_CHECK))
        return make_error("write_frames: frame " + std::to_string(i) + " writes " +
                              std::string(protocol::find_register(f.index)->name) +
                              ", which the board backend owns for link integrity",
                          backends::kBadRequest);
      if (f.index == index_of(Reg::RESET) || f.index == index_of(Reg::HOST_TAG))
        return make_error("write_frames: frame " + std::to_string(i) + " writes " +
                              std::string(protocol::find_register(f.index)->name) + "; use Backend::reset()",
                          backends::kBadRequest);
      frames.push_back(f);
    }
    if (auto r = send_frames(frames); !r) return r;
    for (const auto& f : frames) {
      track(f);
      swaps |= f.index == index_of(Reg::FB_DISPLAY);
    }
    if (swaps && profile_.scanout != ScanoutMode::Off && scanout_cb_) {
      if (auto r = emit_scanout(); !r) return r;
    }
    cb = scanout_cb_;
    emitted.swap(pending_frames_);
  }
  for (auto& f : emitted) cb(f);
  return {};
}

Result<void> BoardBackend::emit_scanout() {
  if (auto r = poll_status(kStatusBusy | kStatusLinkPending | kStatusSwapPending | kStatusLevelMask, 0, "the display swap"); !r)
    return r.error();
  const std::uint8_t idx[] = {index_of(Reg::FRAME_CRC), index_of(Reg::FRAME_CRC)};
  auto v = read_frames(idx);
  if (!v) return v.error();
  if ((*v)[0] != (*v)[1])
    return make_error("board '" + profile_.name + "': FRAME_CRC reads disagree (MISO bit errors)", backends::kDeviceProtocol);
  auto frame = std::make_shared<backends::ScanoutFrame>();
  frame->crc = static_cast<std::uint32_t>((*v)[0]);
  frame->number = ++frame_number_;
  frame->width = fb_format_ & 0x7FF;
  frame->height = (fb_format_ >> 16) & 0x7FF;
  frame->format = static_cast<protocol::PixelFormat>((fb_format_ >> 32) & 3);
  frame->swap_time = std::chrono::steady_clock::now();
  if (profile_.scanout == ScanoutMode::Readback) {
    const std::uint64_t bytes = std::uint64_t{frame->width} * frame->height * protocol::bytes_per_pixel(frame->format);
    const std::uint32_t base = static_cast<std::uint32_t>(fb_display_ & 0xFFFFFFF0u);
    if (bytes == 0 || base + bytes > vram_bytes_)
      return make_error("board '" + profile_.name + "': display buffer at 0x" + fmt::format("{:X}", base) + " of " +
                            std::to_string(bytes) + " bytes does not fit video memory (" + std::to_string(vram_bytes_) + " bytes)",
                        backends::kBadRequest);
    for (unsigned attempt = 0;; ++attempt) {
      auto px = readback_locked(base, static_cast<std::uint32_t>(bytes), /*verify=*/false);  // FRAME_CRC checks it
      if (!px) return px.error();
      if (protocol::crc32(*px) == frame->crc) {
        frame->pixels = std::move(*px);
        break;
      }
      if (attempt + 1 >= kScanoutAttempts)
        return make_error("board '" + profile_.name + "': scanout readback does not match FRAME_CRC after " +
                              std::to_string(kScanoutAttempts) + " attempts (SPI bit errors); lower bridge.spi_clock_hz",
                          backends::kDeviceProtocol);
    }
  }
  pending_frames_.push_back(std::move(frame));
  return {};
}

Result<std::uint64_t> BoardBackend::read_register(std::uint8_t index) {
  std::lock_guard lock(mu_);
  if (gone_) return gone_error();
  if (index > 0x7F) return make_error("read_register: index " + std::to_string(index) + " is beyond 0x7F", backends::kBadRequest);
  const std::uint8_t idx[] = {index};
  auto v = read_frames(idx);
  if (!v) {
    if (auto f = on_fault(v.error()); !f) return f.error();
    if (strict_) if (auto r = restart_link(); !r) return r.error();
    v = read_frames(idx);
    if (!v) return v.error();
  }
  return (*v)[0];
}

Result<void> BoardBackend::flush() {
  std::lock_guard lock(mu_);
  if (gone_) return gone_error();
  auto r = poll_status(kStatusBusy | kStatusLinkPending | kStatusLevelMask, 0, "the command FIFO to drain");
  if (!r) return r.error();
  return {};
}

Result<void> BoardBackend::reset() {
  std::lock_guard lock(mu_);
  if (gone_) return gone_error();
  std::vector<std::uint8_t> mosi;
  const Frame f = protocol::write_frame(Reg::RESET, protocol::kResetMagic);
  append_frame(mosi, f);
  const SpiWindow w{mosi, false, {}};
  if (auto r = exchange(std::span(&w, 1), std::span(&f, 1)); !r) {
    if (auto fr = on_fault(r.error()); !fr) return fr;
    return r.error();
  }
  return attach_locked();
}

Result<void> BoardBackend::upload(std::uint32_t address, std::span<const std::uint8_t> bytes) {
  std::lock_guard lock(mu_);
  if (gone_) return gone_error();
  if (address % 8 != 0)
    return make_error("upload: address 0x" + fmt::format("{:X}", address) + " is not 8-byte aligned (MEM_ADDR granularity)",
                      backends::kBadRequest);
  if (std::uint64_t{address} + bytes.size() > vram_bytes_)
    return make_error("upload: " + std::to_string(bytes.size()) + " bytes at 0x" + fmt::format("{:X}", address) +
                          " exceed video memory (" + std::to_string(vram_bytes_) + " bytes)",
                      backends::kBadRequest);
  std::vector<std::uint8_t> tail;
  std::span<const std::uint8_t> data = bytes;
  if (bytes.size() % 8 != 0) {
    // The last partial word keeps the bytes already in memory.
    const std::uint32_t last = address + static_cast<std::uint32_t>(bytes.size() / 8 * 8);
    auto old = readback_locked(last, 8, /*verify=*/true);
    if (!old) return old.error();
    tail.assign(bytes.begin(), bytes.end());
    tail.insert(tail.end(), old->begin() + static_cast<std::ptrdiff_t>(bytes.size() % 8), old->end());
    data = tail;
  }
  std::vector<Frame> frames;
  frames.reserve(data.size() / 8 + 1);
  frames.push_back(protocol::write_frame(Reg::MEM_ADDR, address));
  for (std::size_t off = 0; off < data.size(); off += 8) {
    std::uint64_t v = 0;
    for (std::size_t b = 0; b < 8; ++b) v = v << 8 | data[off + b];
    frames.push_back(protocol::write_frame(Reg::MEM_DATA, v));
  }
  return send_frames(frames);
}

Result<std::vector<std::uint8_t>> BoardBackend::readback(std::uint32_t address, std::uint32_t length) {
  std::lock_guard lock(mu_);
  if (gone_) return gone_error();
  if (std::uint64_t{address} + length > vram_bytes_)
    return make_error("readback: " + std::to_string(length) + " bytes at 0x" + fmt::format("{:X}", address) +
                          " exceed video memory (" + std::to_string(vram_bytes_) + " bytes)",
                      backends::kBadRequest);
  return readback_locked(address, length, opts_.verify_readback);
}

// One pass: MEM_ADDR (queued), wait for MEM_READY, then back-to-back MEM_DATA reads in bursts.
Result<std::vector<std::uint8_t>> BoardBackend::read_memory_once(std::uint32_t start, std::size_t words_total) {
  const Frame set_addr = protocol::write_frame(Reg::MEM_ADDR, start);
  if (auto r = send_frames(std::span(&set_addr, 1)); !r) return r.error();
  if (auto r = poll_status(kStatusBusy | kStatusLinkPending | kStatusMemReady | kStatusLevelMask, kStatusMemReady,
                           "MEM_READY after MEM_ADDR");
      !r)
    return r.error();
  std::vector<std::uint8_t> out;
  out.reserve(words_total * 8);
  const std::size_t per_window = std::max<std::size_t>(1, bridge_->preferred_batch_bytes() / kFrameBytes);
  std::vector<std::uint8_t> mosi;
  std::vector<Frame> frames;
  for (std::size_t done = 0; done < words_total;) {
    const std::size_t n = std::min(per_window, words_total - done);
    mosi.clear();
    frames.assign(n, protocol::read_frame(Reg::MEM_DATA));
    for (const auto& f : frames) append_frame(mosi, f);
    const SpiWindow w{mosi, true, {}};
    auto r = exchange(std::span(&w, 1), frames);
    if (!r) return r.error();
    for (std::size_t k = 0; k < n; ++k) {
      // Only the first read of a burst must see MEM_READY in its status byte: later ones may
      // legitimately show the look-ahead load still in flight (it completes before bit 64).
      if (k == 0 && !((*r)[k * kFrameBytes] & protocol::MISO_MEM_READY))
        return make_error("board '" + profile_.name + "': MEM_READY dropped during readback at 0x" +
                              fmt::format("{:X}", start + (done + k) * 8),
                          backends::kDeviceProtocol);
      out.insert(out.end(), r->begin() + static_cast<std::ptrdiff_t>(k * kFrameBytes + 1),
                 r->begin() + static_cast<std::ptrdiff_t>(k * kFrameBytes + kFrameBytes));
    }
    done += n;
  }
  return out;
}

// Memory reads carry no checksum on the wire, so unless the caller verifies another way (scanout
// compares FRAME_CRC) every chunk is read twice and must agree; a MISO bit error costs a re-read,
// never a silently wrong byte.
Result<std::vector<std::uint8_t>> BoardBackend::readback_locked(std::uint32_t address, std::uint32_t length, bool verify) {
  if (length == 0) return std::vector<std::uint8_t>{};
  const std::uint32_t start = address & ~7u;
  const std::uint64_t end = (std::uint64_t{address} + length + 7) & ~std::uint64_t{7};
  const std::size_t chunk_words = std::max<std::size_t>(1, bridge_->preferred_batch_bytes() / kFrameBytes);
  std::vector<std::uint8_t> out;
  out.reserve(static_cast<std::size_t>(end - start));
  for (std::uint64_t at = start; at < end;) {
    const std::size_t words = static_cast<std::size_t>(std::min<std::uint64_t>(chunk_words, (end - at) / 8));
    std::vector<std::uint8_t> previous;
    bool agreed = !verify;
    std::vector<std::uint8_t> got;
    const std::uint64_t resets_before = board_resets_;
    for (unsigned attempt = 0; attempt < 2 + opts_.max_link_retries && !(agreed && !got.empty()); ++attempt) {
      auto r = read_memory_once(static_cast<std::uint32_t>(at), words);
      if (!r) {
        // A board reset lost device state: that must reach the caller, never be retried over.
        if (r.error().code == backends::kDeviceGone || r.error().code == backends::kBadRequest ||
            board_resets_ != resets_before)
          return r.error();
        if (auto f = on_fault(r.error()); !f) return f.error();
        if (strict_) if (auto rl = restart_link(); !rl) return rl.error();
        continue;
      }
      got = std::move(*r);
      if (!verify) break;
      agreed = !previous.empty() && previous == got;
      previous = got;
    }
    if (got.empty() || (verify && !agreed))
      return make_error("board '" + profile_.name + "': memory readback at 0x" + fmt::format("{:X}", at) +
                            " never read the same twice (SPI bit errors); lower bridge.spi_clock_hz",
                        backends::kDeviceProtocol);
    out.insert(out.end(), got.begin(), got.end());
    at += words * 8;
    mem_addr_.reset();
  }
  return std::vector<std::uint8_t>(out.begin() + (address - start), out.begin() + (address - start) + length);
}

}  // namespace gpubridge::usb
