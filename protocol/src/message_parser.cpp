// MessageParser: the incremental socket-protocol parser. Owns one byte buffer that callers either
// copy into (feed) or read into directly (prepare/commit); parsed messages point into it.
//
// Buffer layout: [0, pos_) consumed, [pos_, end_) unconsumed stream bytes, [end_, capacity_) free.
// Room is made only when bytes are added (make_room): an empty buffer restarts at 0, otherwise the
// unconsumed bytes are moved to the front if that frees enough, else the buffer grows. A move
// happens at most once per message consumed, so no byte is copied more than once on average.
#include <algorithm>
#include <cstring>

#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::protocol {

MessageParser::MessageParser(std::uint32_t max_payload) : max_payload_(std::min(max_payload, kMaxPayload)) {}

void MessageParser::set_max_payload(std::uint32_t max_payload) { max_payload_ = std::min(max_payload, kMaxPayload); }

void MessageParser::make_room(std::size_t n, std::size_t ceiling) {
  if (pos_ == end_) {
    consumed_ += pos_;
    pos_ = end_ = 0;
  }
  if (capacity_ - end_ >= n) return;
  const std::size_t live = end_ - pos_;
  if (capacity_ - live >= n) {
    std::memmove(buf_.get(), buf_.get() + pos_, live);
  } else {
    // Doubling keeps growth amortised; the ceiling keeps it from overshooting the limit.
    const std::size_t grown = std::max(live + n, std::min(2 * capacity_, ceiling));
    auto fresh = std::make_unique_for_overwrite<std::uint8_t[]>(grown);
    if (live > 0) std::memcpy(fresh.get(), buf_.get() + pos_, live);
    buf_ = std::move(fresh);
    capacity_ = grown;
  }
  consumed_ += pos_;
  pos_ = 0;
  end_ = live;
}

void MessageParser::feed(std::span<const std::uint8_t> bytes) {
  if (failed_ || bytes.empty()) return;  // a poisoned stream is never parsed again: don't keep its bytes
  make_room(bytes.size(), kHeaderBytes + std::size_t{max_payload_} + bytes.size());
  std::memcpy(buf_.get() + end_, bytes.data(), bytes.size());
  end_ += bytes.size();
  prepared_ = 0;
}

std::optional<std::size_t> MessageParser::current_message_bytes() const {
  if (end_ - pos_ < kHeaderBytes) return std::nullopt;
  Header h;
  // Only a header that passes every check (the length against max_payload included) may size a read.
  if (decode_header(std::span<const std::uint8_t, kHeaderBytes>(buf_.get() + pos_, kHeaderBytes), max_payload_, h))
    return std::nullopt;
  return kHeaderBytes + std::size_t{h.length};
}

std::span<std::uint8_t> MessageParser::prepare(std::size_t max_bytes) {
  prepared_ = 0;
  if (failed_ || max_bytes == 0) return {};
  std::size_t want = max_bytes;
  if (const auto message = current_message_bytes()) {
    const std::size_t have = end_ - pos_;
    if (*message >= kLargeMessageBytes && *message > have) want = std::min(want, *message - have);
  }
  make_room(want, kHeaderBytes + std::size_t{max_payload_} + max_bytes);
  prepared_ = want;
  return {buf_.get() + end_, want};
}

void MessageParser::commit(std::size_t n) {
  if (failed_) return;
  end_ += std::min(n, prepared_);
  prepared_ = 0;
}

MessageParser::Status MessageParser::next(Message& out) {
  if (failed_) return Status::Error;
  const std::size_t avail = end_ - pos_;
  const std::uint8_t* p = avail > 0 ? buf_.get() + pos_ : nullptr;
  auto fail = [&](DecodeError e) {
    failed_ = true;
    e.message += " (stream offset " + std::to_string(stream_offset()) + ")";
    error_ = std::move(e);
    buf_.reset();
    consumed_ += pos_;
    capacity_ = pos_ = end_ = prepared_ = 0;
    return Status::Error;
  };

  if (avail < kHeaderBytes) {
    // Reject a wrong stream as early as its first bytes allow (an HTTP client, a stray byte).
    std::uint8_t probe[kHeaderBytes] = {kMagic0, kMagic1, kSocketVersion, static_cast<std::uint8_t>(MsgType::Ping)};
    Header ignored;
    if (avail > 0) {
      std::memcpy(probe, p, avail);  // absent length bytes stay 0
      if (auto e = decode_header(std::span<const std::uint8_t, kHeaderBytes>(probe, kHeaderBytes), max_payload_, ignored))
        return fail(std::move(*e));
    }
    return Status::NeedMore;
  }

  Header h;
  if (auto e = decode_header(std::span<const std::uint8_t, kHeaderBytes>(p, kHeaderBytes), max_payload_, h))
    return fail(std::move(*e));
  if (avail - kHeaderBytes < h.length) return Status::NeedMore;

  if (auto e = decode_payload(h, std::span<const std::uint8_t>(p + kHeaderBytes, h.length), out))
    return fail(std::move(*e));
  pos_ += kHeaderBytes + h.length;
  return Status::Ok;
}

}  // namespace gpubridge::protocol
