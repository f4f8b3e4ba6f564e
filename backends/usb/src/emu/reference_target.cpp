#include "gpubridge/usb/emu/reference_target.hpp"

#include <algorithm>

#include "gpubridge/protocol/crc32.hpp"

namespace gpubridge::usb::emu {

using protocol::Reg;
using protocol::index_of;

ReferenceTarget::ReferenceTarget(ReferenceTargetConfig cfg) : cfg_(cfg) { power_cycle(); }

void ReferenceTarget::power_cycle() {
  vram_.assign(std::size_t{cfg_.vram_kib} * 1024, 0);
  soft_reset();
}

void ReferenceTarget::soft_reset() {
  for (auto& r : regs_) r = 0;
  for (const auto& d : protocol::register_table()) regs_[d.index] = d.reset;
  fifo_.clear();
  held_.clear();
  errors_ = 0;
  strict_ = discarding_ = group_tainted_ = false;
  link_crc_ = link_frames_ = 0;
  groups_ok_ = groups_bad_ = 0;
  mem_addr_ = 0;
  mem_ready_ = false;
  frame_count_ = 0;
  host_tag_ = frame_crc_ = 0;
}

std::size_t ReferenceTarget::free_entries() const {
  const std::size_t used = fifo_.size() + held_.size();
  return used >= cfg_.fifo_depth ? 0 : cfg_.fifo_depth - used;
}

bool ReferenceTarget::busy_pin() const { return free_entries() < 32; }

std::uint64_t ReferenceTarget::status_value() const {
  std::uint64_t v = std::uint64_t{errors_} << 48 | std::uint64_t{frame_count_} << 32;
  if (!held_.empty()) v |= 1ull << 20;
  if (mem_ready_ && fifo_.empty()) v |= 1ull << 18;
  v |= 1ull << 17;  // the reference target is always in vertical blanking
  if (!fifo_.empty()) v |= 1ull << 16;
  v |= std::min<std::uint64_t>(fifo_.size() + held_.size(), 0xFFFF);
  return v;
}

std::uint8_t ReferenceTarget::miso_status() {
  std::uint8_t s = protocol::MISO_MARKER | protocol::MISO_VBLANK;
  if (busy_pin()) s |= protocol::MISO_FIFO_NEARLY_FULL;
  if (errors_) s |= protocol::MISO_ERROR;
  if (!fifo_.empty()) s |= protocol::MISO_BUSY;
  if (mem_ready_ && fifo_.empty()) s |= protocol::MISO_MEM_READY;
  return s;
}

std::uint64_t ReferenceTarget::read_register(std::uint8_t index) {
  switch (index) {
    case index_of(Reg::STATUS): return status_value();
    case index_of(Reg::FRAME_CRC): return frame_crc_;
    case index_of(Reg::LINK_CTRL): return strict_ ? 1 : 0;
    case index_of(Reg::LINK_STATUS):
      return std::uint64_t{groups_bad_} << 48 | std::uint64_t{groups_ok_} << 32 | (discarding_ ? 1ull << 24 : 0) |
             (link_frames_ & 0xFFFFFF);
    case index_of(Reg::HOST_TAG): return host_tag_;
    case index_of(Reg::CAPS):
      return std::uint64_t{0x38} << 56 | std::uint64_t{cfg_.fifo_depth & 0x3FF} << 46 |
             std::uint64_t{cfg_.max_height & 0x7FF} << 35 | std::uint64_t{cfg_.max_width & 0x7FF} << 24 |
             (cfg_.vram_kib & 0xFFFFFF);
    // CAPS2.FEATURES2 bit 0: depth buffer. The target renders nothing and refuses no Z bits, which is
    // what a device with a depth buffer does at the link level.
    case index_of(Reg::CAPS2): return protocol::kFeature2Depth;
    case index_of(Reg::ID): return protocol::describe(Reg::ID).reset | cfg_.variant;
    case index_of(Reg::MEM_DATA): {
      if (!mem_ready_ || !fifo_.empty()) return 0;
      if (std::uint64_t{mem_addr_} + 8 > vram_.size()) {
        errors_ |= protocol::ERR_MEM_RANGE;
        return 0;
      }
      std::uint64_t v = 0;
      for (int i = 0; i < 8; ++i) v = v << 8 | vram_[mem_addr_ + i];
      return v;
    }
    default: break;
  }
  const auto* d = protocol::find_register(index);
  if (!d) {
    errors_ |= protocol::ERR_BAD_REGISTER;
    return 0;
  }
  if (d->access == protocol::Access::WriteOnly) return 0;
  return regs_[index];
}

void ReferenceTarget::frame_complete(const protocol::Frame& f) {
  const bool link_register = f.index == index_of(Reg::LINK_CHECK) || f.index == index_of(Reg::LINK_CTRL);
  if (!link_register) {
    const auto bytes = protocol::encode(f);
    link_crc_ = protocol::crc32_update(link_crc_, bytes);
    ++link_frames_;
  }
  if (f.read) {
    // MEM_DATA reads advance the pointer once the frame is complete.
    if (f.index == index_of(Reg::MEM_DATA) && mem_ready_ && fifo_.empty()) mem_addr_ += 8;
  } else {
    const auto* d = protocol::find_register(f.index);
    if (!d) {
      errors_ |= protocol::ERR_BAD_REGISTER;
    } else if (d->access == protocol::Access::ReadOnly) {
      errors_ |= protocol::ERR_BAD_REGISTER;
    } else if (d->path == protocol::Path::Immediate) {
      write_immediate(f.index, f.data);
    } else {
      enqueue(f.index, f.data);
    }
  }
  drain(cfg_.drain_per_frame == 0 ? ~0u : cfg_.drain_per_frame);
}

void ReferenceTarget::frame_aborted() {
  errors_ |= protocol::ERR_FRAMING;
  group_tainted_ = true;
}

void ReferenceTarget::write_immediate(std::uint8_t index, std::uint64_t data) {
  switch (index) {
    case index_of(Reg::ERR_CLEAR): errors_ &= static_cast<std::uint16_t>(~data); break;
    case index_of(Reg::LINK_CTRL):
      if (strict_ && !(data & 1) && (data >> 32) != protocol::kLinkClearKey) {  // leaving strict mode needs the key
        errors_ |= protocol::ERR_BAD_VALUE;
        break;
      }
      strict_ = (data & 1) != 0;
      discarding_ = false;
      group_tainted_ = false;
      held_.clear();  // writes held for an unchecked group are dropped: the host resends them
      link_crc_ = 0;
      link_frames_ = 0;
      break;
    case index_of(Reg::LINK_CHECK): {
      if (discarding_) break;  // checks are ignored until LINK_CTRL is written
      const bool match = !group_tainted_ && (data & 0xFFFFFFFFu) == link_crc_;
      if (match) {
        ++groups_ok_;
        for (const auto& q : held_) fifo_.push_back(q);
      } else {
        ++groups_bad_;
        errors_ |= protocol::ERR_LINK_CRC;
        if (strict_) discarding_ = true;
      }
      held_.clear();
      group_tainted_ = false;
      link_crc_ = 0;
      link_frames_ = 0;
      break;
    }
    case index_of(Reg::HOST_TAG): host_tag_ = data; break;
    case index_of(Reg::RESET):
      if (data == protocol::kResetMagic) soft_reset();
      else errors_ |= protocol::ERR_BAD_VALUE;
      break;
    default: break;
  }
}

void ReferenceTarget::enqueue(std::uint8_t index, std::uint64_t data) {
  if (strict_ && discarding_) return;
  if (free_entries() == 0) {
    errors_ |= protocol::ERR_OVERFLOW;
    group_tainted_ = true;
    return;
  }
  if (index == index_of(Reg::MEM_ADDR)) mem_ready_ = false;
  (strict_ ? held_ : fifo_).push_back(Queued{index, data});
}

void ReferenceTarget::drain(unsigned n) {
  while (n-- > 0 && !fifo_.empty()) {
    const Queued q = fifo_.front();
    fifo_.pop_front();
    execute(q);
  }
}

void ReferenceTarget::tick() { drain(1); }

void ReferenceTarget::execute(const Queued& q) {
  ++executed_;
  const auto check = protocol::check_write(q.index, q.data);
  errors_ |= check.errors;
  const std::uint64_t v = check.data;
  switch (q.index) {
    case index_of(Reg::MEM_ADDR):
      mem_addr_ = static_cast<std::uint32_t>(v & 0xFFFFFFF8u);
      mem_ready_ = true;
      break;
    case index_of(Reg::MEM_DATA):
      if (std::uint64_t{mem_addr_} + 8 > vram_.size()) {
        errors_ |= protocol::ERR_MEM_RANGE;
      } else {
        for (int i = 0; i < 8; ++i) vram_[mem_addr_ + i] = static_cast<std::uint8_t>(v >> (56 - 8 * i));
      }
      mem_addr_ += 8;
      break;
    case index_of(Reg::FB_DISPLAY):
      regs_[q.index] = v;
      latch_display();
      return;
    case index_of(Reg::CLEAR): {
      const auto fmt = static_cast<protocol::PixelFormat>((regs_[index_of(Reg::FB_FORMAT)] >> 32) & 3);
      clear_rect(static_cast<std::uint32_t>(regs_[index_of(Reg::FB_DRAW)] & 0xFFFFFFF0u),
                 regs_[index_of(Reg::CLEAR_COLOR)], protocol::bytes_per_pixel(fmt));
      return;
    }
    default: break;
  }
  regs_[q.index] = v;
}

// Fills the scissor rectangle of the draw buffer with CLEAR_COLOR (RGBA8888 only is packed
// exactly; other formats take the top bytes, which is enough for link tests).
void ReferenceTarget::clear_rect(std::uint32_t base, std::uint64_t value, unsigned bpp) {
  const std::uint64_t fmt = regs_[index_of(Reg::FB_FORMAT)];
  const unsigned width = fmt & 0x7FF, height = (fmt >> 16) & 0x7FF;
  const std::uint64_t sc = regs_[index_of(Reg::SCISSOR)];
  const unsigned x0 = sc & 0x7FF, y0 = (sc >> 16) & 0x7FF;
  const unsigned x1 = std::min<unsigned>((sc >> 32) & 0x7FF, width), y1 = std::min<unsigned>((sc >> 48) & 0x7FF, height);
  std::uint8_t px[4];
  for (unsigned i = 0; i < 4; ++i) px[i] = static_cast<std::uint8_t>(value >> (24 - 8 * i));
  for (unsigned y = y0; y < y1; ++y) {
    for (unsigned x = x0; x < x1; ++x) {
      const std::uint64_t at = base + (std::uint64_t{y} * width + x) * bpp;
      if (at + bpp > vram_.size()) {
        errors_ |= protocol::ERR_MEM_RANGE;
        return;
      }
      std::copy(px, px + bpp, vram_.begin() + static_cast<std::ptrdiff_t>(at));
    }
  }
}

void ReferenceTarget::latch_display() {
  const std::uint64_t fmt = regs_[index_of(Reg::FB_FORMAT)];
  const unsigned width = fmt & 0x7FF, height = (fmt >> 16) & 0x7FF;
  const auto pf = static_cast<protocol::PixelFormat>((fmt >> 32) & 3);
  const std::uint64_t base = regs_[index_of(Reg::FB_DISPLAY)] & 0xFFFFFFF0u;
  const std::uint64_t bytes = std::uint64_t{width} * height * protocol::bytes_per_pixel(pf);
  std::uint32_t crc = 0;
  if (base + bytes <= vram_.size()) {
    crc = protocol::crc32(std::span<const std::uint8_t>(vram_.data() + base, bytes));
  } else {
    errors_ |= protocol::ERR_MEM_RANGE;
  }
  ++frame_count_;
  frame_crc_ = std::uint64_t{frame_count_} << 32 | crc;
}

}  // namespace gpubridge::usb::emu
