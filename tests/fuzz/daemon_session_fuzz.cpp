// libFuzzer target: the real Session dispatch (handshake, lease, device calls, replies) over an
// in-memory stream. The first bytes choose the read split points, the rest is the client's byte
// stream (a HELLO is prepended half the time so the fuzzer reaches post-handshake paths; that HELLO
// offers zstd when bit 1 of the first byte is set, so WRITE_FRAMES_Z is inflated and checked).
// Built with -DGPUBRIDGE_FUZZ=ON (clang): target daemon_session_fuzz.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "gpubridge/common/log.hpp"
#include "gpubridge/daemon/hub.hpp"
#include "gpubridge/daemon/memory_stream.hpp"
#include "gpubridge/daemon/session.hpp"
#include "gpubridge/daemon/test_backends.hpp"

// Warnings and errors are still formatted (and so fuzzed); the info line every session logs on
// connect would otherwise fill the log and cost most of the run's time.
extern "C" int LLVMFuzzerInitialize(int*, char***) {
  gpubridge::init_logging("warn");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace gpubridge;
  if (size < 2) return 0;
  const bool prepend_hello = data[0] & 1;
  std::vector<std::size_t> chunks;
  const bool offer_zstd = data[0] & 2;
  const std::size_t n_chunks = 1 + (data[0] >> 2) % 8;
  for (std::size_t i = 0; i < n_chunks && 1 + i < size; ++i) chunks.push_back(1 + data[1 + i] % 97);
  const std::size_t skip = std::min(size, 1 + n_chunks);
  std::vector<std::uint8_t> input;
  if (prepend_hello) {
    protocol::Hello hello{protocol::kSocketVersion, "fuzz", ""};
    if (offer_zstd) hello.codecs = protocol::codec_bit(protocol::Codec::Zstd);
    protocol::encode(protocol::Message{1, hello}, input);
  }
  input.insert(input.end(), data + skip, data + size);

  boost::asio::io_context io;
  daemon::HubOptions opts;
  opts.limits.max_message_bytes = 1u << 20;  // lower cap under fuzzing, as virglrenderer's vtest fuzzer does
  daemon::Hub hub(io.get_executor(), io.get_executor(), std::make_unique<daemon::FakeScanoutBackend>(32, 16, 64 * 1024), opts);
  std::vector<std::uint8_t> output;
  auto stream = std::make_unique<daemon::MemoryStream>(io.get_executor(), std::move(input), chunks, &output);
  std::make_shared<daemon::Session>(hub, std::move(stream), io.get_executor())->start();
  // The stream ends with EOF, so the session terminates and the loop runs dry.
  io.run_for(std::chrono::seconds(2));
  // Every reply the daemon wrote must itself be a well-formed message stream.
  protocol::MessageParser p;
  p.feed(output);
  protocol::Message m;
  protocol::MessageParser::Status st;
  while ((st = p.next(m)) == protocol::MessageParser::Status::Ok) {
  }
  if (st == protocol::MessageParser::Status::Error) __builtin_trap();
  return 0;
}
