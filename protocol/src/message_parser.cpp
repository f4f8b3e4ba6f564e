// MessageParser: the incremental socket-protocol parser. Owns one byte buffer that callers either
// copy into (feed) or read into directly (prepare/commit); parsed messages point into it.
//
// Buffer layout: [0, pos_) consumed, [pos_, end_) unconsumed stream bytes, [end_, capacity_) free.
// Room is made only when bytes are added (make_room): an empty buffer restarts at 0, otherwise the
// unconsumed bytes are moved to the front if that frees enough, else the buffer grows. A move
// happens at most once per message consumed, so no byte is copied more than once on average.
// prepare_keeping_last() never moves or frees the last returned message: it reads after the
// unconsumed bytes, wraps to the front of the buffer when that has more room, or moves to a larger
// buffer while the old one is kept in retired_ until the message is released.
#include <algorithm>
#include <cstring>

#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::protocol {

MessageParser::MessageParser(std::uint32_t max_payload) : max_payload_(std::min(max_payload, kMaxPayload)) {}

void MessageParser::set_max_payload(std::uint32_t max_payload) { max_payload_ = std::min(max_payload, kMaxPayload); }

void MessageParser::release_last() {
  last_begin_ = last_end_ = 0;
  retired_.reset();
  retired_capacity_ = 0;
}

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
  release_last();
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

std::size_t MessageParser::read_size(std::size_t max_bytes) const {
  if (const auto message = current_message_bytes()) {
    const std::size_t have = end_ - pos_;
    if (*message >= kLargeMessageBytes && *message > have) return std::min(max_bytes, *message - have);
  }
  return max_bytes;
}

std::span<std::uint8_t> MessageParser::prepare(std::size_t max_bytes) {
  prepared_ = 0;
  if (failed_ || max_bytes == 0) return {};
  release_last();
  const std::size_t want = read_size(max_bytes);
  make_room(want, kHeaderBytes + std::size_t{max_payload_} + max_bytes);
  prepared_ = want;
  return {buf_.get() + end_, want};
}

std::span<std::uint8_t> MessageParser::prepare_keeping_last(std::size_t max_bytes) {
  prepared_ = 0;
  if (failed_ || max_bytes == 0) return {};
  // One complete message behind the kept one is enough to go on with; reading further would
  // only fill the buffer with bytes that later have to be moved.
  if (const auto message = current_message_bytes(); message && *message <= end_ - pos_) return {};
  std::size_t want = read_size(max_bytes);
  const bool kept_here = last_end_ > last_begin_;  // else it is in retired_, or there is none
  if (pos_ == end_) {
    // Everything after the kept message is consumed: restart at the front of the buffer when the
    // room there (up to the kept message) is larger than the room at the back.
    const std::size_t front = kept_here ? last_begin_ : capacity_;
    if (front > capacity_ - end_) {
      consumed_ += pos_;
      pos_ = end_ = 0;
    }
  }
  // Unconsumed bytes in front of the kept message must stop where it starts.
  const std::size_t limit = kept_here && end_ <= last_begin_ ? last_begin_ : capacity_;
  if (limit > end_) {
    want = std::min(want, limit - end_);
    prepared_ = want;
    return {buf_.get() + end_, want};
  }
  // No free room. Only a buffer holding the kept message is left behind for a larger one, once
  // per message and never past the size limit, so reading ahead cannot pile up memory.
  if (!kept_here) return {};
  const std::size_t live = end_ - pos_;
  const std::size_t ceiling = kHeaderBytes + std::size_t{max_payload_} + max_bytes;
  const std::size_t grown = std::min(std::max(live + want, 2 * capacity_), ceiling);
  if (grown <= capacity_) return {};  // at the limit: wait until the message is released
  want = std::min(want, grown - live);
  auto fresh = std::make_unique_for_overwrite<std::uint8_t[]>(grown);
  if (live > 0) std::memcpy(fresh.get(), buf_.get() + pos_, live);
  retired_ = std::move(buf_);
  retired_capacity_ = capacity_;
  buf_ = std::move(fresh);
  capacity_ = grown;
  consumed_ += pos_;
  pos_ = 0;
  end_ = live;
  last_begin_ = last_end_ = 0;  // the kept message now lives in retired_
  prepared_ = want;
  return {buf_.get() + end_, want};
}

void MessageParser::commit(std::size_t n) {
  if (!failed_) end_ += std::min(n, prepared_);
  prepared_ = 0;
}

MessageParser::Status MessageParser::next(Message& out) {
  if (failed_) return Status::Error;
  release_last();
  const std::size_t avail = end_ - pos_;
  const std::uint8_t* p = avail > 0 ? buf_.get() + pos_ : nullptr;
  auto fail = [&](DecodeError e) {
    failed_ = true;
    e.message += " (stream offset " + std::to_string(stream_offset()) + ")";
    error_ = std::move(e);
    consumed_ += pos_;
    pos_ = end_ = 0;
    // A read may still be in flight into the span prepare*() handed out: keep its memory then.
    if (prepared_ == 0) {
      buf_.reset();
      capacity_ = 0;
    }
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
  last_begin_ = pos_;
  pos_ += kHeaderBytes + h.length;
  last_end_ = pos_;
  return Status::Ok;
}

}  // namespace gpubridge::protocol
