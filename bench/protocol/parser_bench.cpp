// Parser throughput: how fast bytes become typed messages and commands, without sockets.
//   MessageParser/{Feed,Direct}/<frames per batch>/<read bytes>: a WRITE_FRAMES stream cut into
//     reads of a realistic size (4 KiB, 64 KiB, a Unix socket's ~208 KiB buffer, the daemon's
//     1 MiB). Feed = read into a separate buffer, then feed() copies it (the daemon before direct
//     reads); Direct = read straight into prepare()'s span, then commit(). The memcpy from the
//     source stream stands in for the kernel's copy in read(2), so both sides do the same I/O work.
//   BinaryTrace/<frames per batch>: read_binary_trace, records/s.
//   TextTrace: parse_text_trace on the canonical text of a drawing stream, lines/s.
// Figures are reported as bytes_per_second / items_per_second by Google Benchmark.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include "gpubridge/protocol/messages.hpp"
#include "gpubridge/protocol/text_trace.hpp"
#include "gpubridge/protocol/trace.hpp"

namespace gpubridge::protocol {
namespace {

constexpr std::size_t kStreamBytes = 16u << 20;  // per benchmark iteration

FramesCmd frames_batch(std::size_t frames, std::uint64_t seed) {
  FramesCmd b;
  for (std::size_t i = 0; i < frames; ++i) {
    // A drawing-like mix: vertices with colours (fields vary, so nothing is trivially constant).
    const std::uint64_t v = (seed + i) * 0x9E3779B97F4A7C15ull;
    if (i % 2 == 0)
      b.push(write_frame(Reg::VERTEX, v & 0x0000'FFFF'0FFF'0FFFull));
    else
      b.push(write_frame(Reg::COLOR, v));
  }
  return b;
}

// WRITE_FRAMES messages of `frames` frames each, about kStreamBytes in all.
std::vector<std::uint8_t> write_frames_stream(std::size_t frames) {
  std::vector<std::uint8_t> stream;
  const std::size_t message = kHeaderBytes + frames * kFrameBytes;
  const std::size_t count = std::max<std::size_t>(1, kStreamBytes / message);
  stream.reserve(count * message);
  for (std::size_t i = 0; i < count; ++i) {
    const auto batch = frames_batch(frames, i * frames);
    encode(Message{static_cast<std::uint32_t>(i + 1), WriteFrames{batch.view()}}, stream);
  }
  return stream;
}

// Parses every message; returns the number of frames seen (checked, so the work is not elided).
std::size_t drain(MessageParser& p, benchmark::State& state) {
  std::size_t frames = 0;
  Message m;
  MessageParser::Status st;
  while ((st = p.next(m)) == MessageParser::Status::Ok) frames += std::get<WriteFrames>(m.payload).frames.size();
  if (st == MessageParser::Status::Error) state.SkipWithError(p.error().message.c_str());
  return frames;
}

template <bool kDirect>
void BM_MessageParser(benchmark::State& state) {
  const auto frames_per_batch = static_cast<std::size_t>(state.range(0));
  const auto read_bytes = static_cast<std::size_t>(state.range(1));
  const auto stream = write_frames_stream(frames_per_batch);
  const std::size_t expect_frames = (stream.size() / (kHeaderBytes + frames_per_batch * kFrameBytes)) * frames_per_batch;
  std::vector<std::uint8_t> read_buf(kDirect ? 0 : read_bytes);
  for (auto _ : state) {
    MessageParser p;
    std::size_t at = 0, frames = 0;
    while (at < stream.size()) {
      std::size_t n;
      if constexpr (kDirect) {
        const auto space = p.prepare(read_bytes);
        n = std::min(space.size(), stream.size() - at);
        std::memcpy(space.data(), stream.data() + at, n);  // the "read(2)"
        p.commit(n);
      } else {
        n = std::min(read_bytes, stream.size() - at);
        std::memcpy(read_buf.data(), stream.data() + at, n);  // the "read(2)"
        p.feed({read_buf.data(), n});
      }
      at += n;
      frames += drain(p, state);
    }
    if (frames != expect_frames) state.SkipWithError("parsed frame count differs from the stream's");
    benchmark::DoNotOptimize(frames);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * stream.size()));
  state.counters["frames_per_s"] = benchmark::Counter(static_cast<double>(state.iterations() * expect_frames),
                                                       benchmark::Counter::kIsRate);
}

void parser_args(benchmark::internal::Benchmark* b) {
  for (std::int64_t frames : {64, 116508})  // a draw call's batch; the daemon benchmark's ~1 MiB batch
    for (std::int64_t read : {4096, 65536, 212992, 1048576}) b->Args({frames, read});
  b->ArgNames({"frames", "read"})->Unit(benchmark::kMillisecond);
}
BENCHMARK(BM_MessageParser<false>)->Name("MessageParser/Feed")->Apply(parser_args);
BENCHMARK(BM_MessageParser<true>)->Name("MessageParser/Direct")->Apply(parser_args);

CommandStream drawing_stream(std::size_t frames_per_batch, std::size_t total_frames) {
  CommandStream s;
  for (std::size_t done = 0; done < total_frames; done += frames_per_batch)
    s.commands.push_back(TimedCommand{done, frames_batch(frames_per_batch, done)});
  return s;
}

void BM_BinaryTrace(benchmark::State& state) {
  const auto frames_per_batch = static_cast<std::size_t>(state.range(0));
  const auto s = drawing_stream(frames_per_batch, 1u << 20);
  const auto bytes = write_binary_trace(s);
  if (!bytes) {
    state.SkipWithError(bytes.error().message.c_str());
    return;
  }
  for (auto _ : state) {
    auto r = read_binary_trace(*bytes, "bench.gbtrace");
    if (!r || r->commands.size() != s.commands.size()) state.SkipWithError("binary trace did not read back");
    benchmark::DoNotOptimize(r);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes->size()));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * s.commands.size()));  // records
  state.SetLabel("items = records");
}
BENCHMARK(BM_BinaryTrace)->Name("BinaryTrace")->Arg(3)->Arg(64)->ArgName("frames")->Unit(benchmark::kMillisecond);

void BM_TextTrace(benchmark::State& state) {
  const auto text = write_text_trace(drawing_stream(64, 1u << 17));
  const auto lines = static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
  for (auto _ : state) {
    auto r = parse_text_trace(text, "bench.trace", {});
    if (!r) state.SkipWithError(r.error().message.c_str());
    benchmark::DoNotOptimize(r);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * text.size()));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * lines));
  state.SetLabel("items = lines");
}
BENCHMARK(BM_TextTrace)->Name("TextTrace")->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace gpubridge::protocol

BENCHMARK_MAIN();
