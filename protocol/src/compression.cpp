// zstd behind FrameDeflater / FrameInflater (compression.hpp). One-shot calls into flat buffers:
// the decoder writes straight into the caller's buffer of frames_bytes and stops there, and its
// window is capped at the largest payload, so a hostile frame header cannot make it allocate more.
#include "gpubridge/protocol/compression.hpp"

#include <zstd.h>

#include <string>

namespace gpubridge::protocol {

struct FrameDeflater::Impl {
  ZSTD_CCtx* ctx = ZSTD_createCCtx();
  int level = 1;
  ~Impl() { ZSTD_freeCCtx(ctx); }
};

FrameDeflater::FrameDeflater(int level) : impl_(std::make_unique<Impl>()) { impl_->level = level; }
FrameDeflater::~FrameDeflater() = default;
FrameDeflater::FrameDeflater(FrameDeflater&&) noexcept = default;
FrameDeflater& FrameDeflater::operator=(FrameDeflater&&) noexcept = default;

bool FrameDeflater::deflate(FrameView frames, std::vector<std::uint8_t>& out) {
  if (!impl_->ctx || frames.bytes.empty()) return false;
  out.resize(ZSTD_compressBound(frames.bytes.size()));
  const std::size_t n =
      ZSTD_compressCCtx(impl_->ctx, out.data(), out.size(), frames.bytes.data(), frames.bytes.size(), impl_->level);
  if (ZSTD_isError(n) || n + 5 >= frames.bytes.size()) return false;  // 5: codec + frames_bytes fields
  out.resize(n);
  return true;
}

struct FrameInflater::Impl {
  ZSTD_DCtx* ctx = ZSTD_createDCtx();
  Impl() {
    // 2^24 = 16 MiB = kMaxPayload: no legitimate stream needs a larger window.
    if (ctx) ZSTD_DCtx_setParameter(ctx, ZSTD_d_windowLogMax, 24);
  }
  ~Impl() { ZSTD_freeDCtx(ctx); }
};

FrameInflater::FrameInflater() : impl_(std::make_unique<Impl>()) {}
FrameInflater::~FrameInflater() = default;
FrameInflater::FrameInflater(FrameInflater&&) noexcept = default;
FrameInflater& FrameInflater::operator=(FrameInflater&&) noexcept = default;

std::optional<DecodeError> FrameInflater::inflate(const WriteFramesZ& m, std::vector<std::uint8_t>& out) {
  if (!impl_->ctx) return DecodeError{ErrorCode::Internal, "WRITE_FRAMES_Z: no zstd context (out of memory)"};
  out.resize(m.frames_bytes);
  // A stream that would inflate past frames_bytes fails with "destination buffer is too small"
  // after writing at most frames_bytes: the bound holds before any byte beyond it is produced.
  const std::size_t n = ZSTD_decompressDCtx(impl_->ctx, out.data(), out.size(), m.data.data(), m.data.size());
  if (ZSTD_isError(n)) {
    out.clear();
    return DecodeError{ErrorCode::Malformed, "WRITE_FRAMES_Z data (payload byte 5) does not inflate to the declared " +
                                                 std::to_string(m.frames_bytes) + " frames_bytes: zstd: " +
                                                 ZSTD_getErrorName(n)};
  }
  if (n != m.frames_bytes) {
    out.clear();
    return DecodeError{ErrorCode::Malformed, "WRITE_FRAMES_Z data inflates to " + std::to_string(n) +
                                                 " bytes, not the declared frames_bytes " + std::to_string(m.frames_bytes)};
  }
  const FrameView frames{out};
  if (const std::size_t f = first_read_frame(frames); f * kFrameBytes < out.size())
    return DecodeError{ErrorCode::BadFrame, "WRITE_FRAMES_Z frame " + std::to_string(f) + " (inflated byte " +
                                                std::to_string(f * kFrameBytes) + ") has the read bit set; use READ_REG"};
  return std::nullopt;
}

}  // namespace gpubridge::protocol
