// Board backend: the host side of docs/protocol.md "SPI link" over any SpiBridge. This file:
// attaching (ID, CAPS, HOST_TAG, strict link) and the Backend calls; the link layer, memory and
// scanout are board_link.cpp, board_memory.cpp and board_scanout.cpp.
#include "gpubridge/usb/board_backend.hpp"

#include <algorithm>
#include <chrono>

#include <fmt/format.h>

#include "board_parts.hpp"

namespace gpubridge::usb {

using namespace board;

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
  i.caps2 = caps2_;
  return i;
}

void BoardBackend::set_scanout_callback(backends::ScanoutCallback cb) {
  std::lock_guard lock(mu_);
  scanout_cb_ = std::move(cb);
}

void BoardBackend::track(const Frame& f) {
  if (f.index == index_of(Reg::FB_FORMAT)) fb_format_ = f.data;
  if (f.index == index_of(Reg::FB_DISPLAY)) fb_display_ = f.data;
}

// A bit error on MOSI turns a read into a read of another register, one on MISO garbles the
// value: so each constant is read twice, and the burst again while a pair differs.
Result<std::vector<std::uint64_t>> BoardBackend::read_constants(std::initializer_list<Reg> regs) {
  std::vector<std::uint8_t> indices;
  for (const Reg r : regs) indices.insert(indices.end(), 2, index_of(r));
  const auto differing = [](const std::vector<std::uint64_t>& v) {
    for (std::size_t i = 0; i < v.size(); i += 2)
      if (v[i] != v[i + 1]) return i;
    return v.size();
  };
  auto v = read_frames(indices);
  for (unsigned attempt = 1; attempt < 3 && v && differing(*v) != v->size(); ++attempt) v = read_frames(indices);
  if (!v) return v.error();
  if (const std::size_t i = differing(*v); i != v->size())
    return make_error("board '" + profile_.name + "': two " + std::string(protocol::find_register(indices[i])->name) +
                          " reads differ three times (0x" + fmt::format("{:016X}", (*v)[i]) + " vs 0x" +
                          fmt::format("{:016X}", (*v)[i + 1]) + "): unreliable SPI link; lower bridge.spi_clock_hz",
                      backends::kDeviceProtocol);
  std::vector<std::uint64_t> values;
  for (std::size_t i = 0; i < v->size(); i += 2) values.push_back((*v)[i]);
  return values;
}

Result<void> BoardBackend::attach_locked() {
  auto v = read_constants({Reg::ID, Reg::CAPS});
  if (!v) return v.error();
  const std::uint64_t id = (*v)[0];
  if ((id >> 32) != protocol::kIdMagic)
    return make_error("board '" + profile_.name + "': ID register reads 0x" + fmt::format("{:016X}", id) +
                          ", not a spigpu design (magic 0x53504755); load the gpubridge bitstream",
                      backends::kDeviceProtocol);
  if (((id >> 24) & 0xFF) != protocol::kVersionMajor)
    return make_error("board '" + profile_.name + "': spigpu protocol major version " + std::to_string((id >> 24) & 0xFF) +
                          " is not supported (this host speaks v1)",
                      backends::kDeviceProtocol);
  id_ = id;
  caps_ = (*v)[1];
  // CAPS2 exists from protocol 1.4 on (on an older device its index is undefined and the read would
  // raise ERR_BAD_REGISTER).
  caps2_ = 0;
  if (protocol::protocol_minor(id) >= 4) {
    auto c = read_constants({Reg::CAPS2});
    if (!c) return c.error();
    caps2_ = (*c)[0];
  }
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
  // Never the LINK_CTRL.CLEAR_KEY in the upper half: HOST_TAG (0x16) is two index flips from
  // LINK_CTRL (0x13), and a clear must stay out of reach of bit errors (docs/protocol.md section 4).
  if ((tag_ >> 32) == protocol::kLinkClearKey) tag_ ^= 1ull << 32;
  if (auto r = write_host_tag(); !r) return r;

  const bool design_strict = (caps_ >> 56) & 0x08;
  strict_ = profile_.strict_link && design_strict;
  if (strict_) return restart_link();
  if (design_strict) return leave_strict_mode();
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

// RESET is immediate and unprotected by the link CRC (its magic value guards against stray
// resets, not against a garbled one being ignored), so it goes out with a HOST_TAG read behind it:
// a reset device reads 0; anything else means the RESET frame was garbled and it is sent again.
Result<void> BoardBackend::reset() {
  std::lock_guard lock(mu_);
  if (gone_) return gone_error();
  std::uint64_t tag = 0;
  for (unsigned attempt = 0; attempt < 3; ++attempt) {
    if (attempt > 0) ++stats_.reset_retries;
    auto r = write_then_read(protocol::write_frame(Reg::RESET, protocol::kResetMagic), Reg::HOST_TAG);
    if (!r) {
      if (auto fr = on_fault(r.error()); !fr) return fr;
      return r.error();
    }
    tag = *r;
    if (tag == 0) return attach_locked();
  }
  return make_error("board '" + profile_.name + "': RESET did not act (HOST_TAG still reads 0x" + fmt::format("{:X}", tag) +
                        " after 3 attempts); SPI bit errors: lower bridge.spi_clock_hz",
                    backends::kDeviceProtocol);
}

}  // namespace gpubridge::usb
