// Board backend, memory: uploads as MEM_ADDR + MEM_DATA writes through the queued path, and
// readback as MEM_DATA read bursts, each chunk read twice unless the caller checks another way.
#include "gpubridge/usb/board_backend.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "board_parts.hpp"

namespace gpubridge::usb {

using namespace board;

void BoardBackend::track_memory_pointer(const Frame& f) {
  if (f.read) return;
  if (f.index == index_of(Reg::MEM_ADDR)) mem_addr_ = static_cast<std::uint32_t>(f.data & 0xFFFFFFF8u);
  else if (f.index == index_of(Reg::MEM_DATA) && mem_addr_) *mem_addr_ += 8;
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
