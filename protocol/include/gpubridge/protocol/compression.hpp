#pragma once
// WRITE_FRAMES compression (docs/protocol.md 17.6): the client deflates a WRITE_FRAMES payload into
// WRITE_FRAMES_Z, the server inflates it back. Both ends keep one context each for the life of a
// connection. No I/O; inflating is bounded before it starts: never more than the frames_bytes the
// message declares (itself at most the server's max_payload), whatever the compressed stream says.
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::protocol {

class FrameDeflater {
 public:
  explicit FrameDeflater(int level = 1);  // zstd level 1: register streams compress ~5-20x at >300 MB/s
  ~FrameDeflater();
  FrameDeflater(FrameDeflater&&) noexcept;
  FrameDeflater& operator=(FrameDeflater&&) noexcept;
  // Compresses `frames` into `out` (replacing its contents). False when compression would not
  // make the message smaller (send plain WRITE_FRAMES then).
  bool deflate(FrameView frames, std::vector<std::uint8_t>& out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

class FrameInflater {
 public:
  FrameInflater();
  ~FrameInflater();
  FrameInflater(FrameInflater&&) noexcept;
  FrameInflater& operator=(FrameInflater&&) noexcept;
  // Inflates m into `out` (resized to m.frames_bytes, which the caller has checked against its own
  // limit) and checks the result like a WRITE_FRAMES payload (no read frame). Errors: MALFORMED
  // when the data does not inflate to exactly frames_bytes (a "zip bomb" stops at that size),
  // BAD_FRAME for a read frame; the message names what and where.
  std::optional<DecodeError> inflate(const WriteFramesZ& m, std::vector<std::uint8_t>& out);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gpubridge::protocol
