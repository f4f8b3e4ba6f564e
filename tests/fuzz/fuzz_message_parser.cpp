// Fuzzes MessageParser with the input fed (feed() or prepare/commit) in pieces whose sizes derive
// from the input. Properties: no crash/UB, the buffer stays bounded, offsets advance exactly by
// each message's size, every accepted message re-encodes to the very bytes it was parsed from,
// and a poisoned parser stays poisoned.
#include <cstring>
#include <vector>

#include "fuzz_check.hpp"
#include "gpubridge/protocol/messages.hpp"

using namespace gpubridge::protocol;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  // Byte 0 picks the receive limit: odd = small (byte 1 × 16, so TOO_LARGE is reachable with
  // small inputs), even = the 16 MiB ceiling. The rest is the stream.
  std::uint32_t max_payload = kMaxPayload;
  std::size_t skip = 1;
  if ((data[0] & 1) && size >= 2) {
    max_payload = std::uint32_t{data[1]} * 16;
    skip = 2;
  }
  const std::vector<std::uint8_t> stream(data + skip, data + size);
  // Split points come from the stream itself so no input bytes are wasted on them.
  MessageParser parser(max_payload);
  std::size_t fed = 0, parsed_until = 0, step = 1;
  bool failed = false;
  while (fed < stream.size() && !failed) {
    // Bit 5 of the byte at the split point picks the way in: feed() (a copy) or a direct read
    // (prepare/commit, as the daemon does), which may offer less room than asked for.
    const bool direct = stream[fed] & 32;
    step = (step * 7 + (stream[fed] & 31)) % 97 + 1;
    std::size_t n = std::min(step, stream.size() - fed);
    if (direct) {
      const auto space = parser.prepare(step);
      FUZZ_CHECK(!space.empty() && space.size() <= step);
      n = std::min(n, space.size());
      std::memcpy(space.data(), stream.data() + fed, n);
      parser.commit(n);
    } else {
      parser.feed(std::span(stream).subspan(fed, n));
    }
    fed += n;
    // Unconsumed bytes are at most one partial message plus this read; the buffer grows by
    // doubling capped at kHeaderBytes + max_payload + the read size.
    FUZZ_CHECK(parser.held_bytes() <= 4096 + 2 * (std::size_t{max_payload} + kHeaderBytes) + step);
    for (;;) {
      Message m;
      const auto st = parser.next(m);
      if (st == MessageParser::Status::NeedMore) break;
      if (st == MessageParser::Status::Error) {
        failed = true;
        FUZZ_CHECK(!parser.error().message.empty());
        Message again;
        FUZZ_CHECK(parser.next(again) == MessageParser::Status::Error);
        break;
      }
      const std::size_t end = parser.stream_offset();
      FUZZ_CHECK(end > parsed_until && end <= fed);
      const auto re = encode(m);
      FUZZ_CHECK(re.size() == end - parsed_until);
      FUZZ_CHECK(std::memcmp(re.data(), stream.data() + parsed_until, re.size()) == 0);
      parsed_until = end;
    }
  }
  return 0;
}
