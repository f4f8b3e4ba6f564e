#include "gpubridge/dmc1/link.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

#include "dispatcher.hpp"

namespace gpubridge::dmc1 {

Result<LinkEstimate> estimate_link(std::span<const std::uint64_t> words, double baud, std::shared_ptr<const TextureMemory> textures,
                                   const TimingParameters& timing, unsigned fifo_depth, unsigned bits_per_byte) {
  if (!(baud > 0) || !std::isfinite(baud) || bits_per_byte == 0)
    return make_error("link estimate: baud rate must be a positive number");
  if (!(timing.clock_mhz > 0)) return make_error("link estimate: the GPU clock (clock_mhz) must be positive");
  if (!textures) return make_error("link estimate: needs a texture memory (terrain spans read it)");
  // Only the dispatcher and the timing model: what the link estimate needs is when each command is
  // taken, which terrain spans make depend on texels; the pixels are never looked at.
  Dispatcher dispatcher(std::move(textures));
  CommandFifo fifo;
  fifo.clear(0);
  TimingModel model(timing);
  DeviceStats stats;
  LinkEstimate e;
  e.baud = baud;
  const double cycles_per_word = 8.0 * bits_per_byte / baud * timing.clock_mhz * 1e6;
  std::deque<std::uint64_t> waiting;  // dispatch cycles of commands that had arrived and not yet left the FIFO
  std::uint64_t busy = 0;
  for (std::size_t i = 0; i < words.size(); ++i) {
    // The word is complete after its 8 bytes (plus the sync byte and the 0x00 before it).
    const auto arrival = static_cast<std::uint64_t>(std::ceil((static_cast<double>(i) + 1.25) * cycles_per_word));
    while (!waiting.empty() && waiting.front() <= arrival) waiting.pop_front();
    model.idle_until(arrival);
    const std::uint64_t dispatch = model.next_dispatch();
    waiting.push_back(dispatch);
    e.max_fifo = std::max<unsigned>(e.max_fifo, static_cast<unsigned>(waiting.size()) - 1);  // one sits in the GPU's buffer
    dispatcher.push(words[i], fifo, model, stats);
    if (fifo.full()) fifo.clear(dispatcher.draw_buffer());  // nothing draws the queued spans
    busy += model.next_dispatch() - dispatch;
  }
  const auto& frames = model.frame_cycles();
  e.frames = frames.size();
  std::uint64_t end = 0;
  for (const std::uint64_t f : frames) end += f;
  if (end == 0) end = model.drain_cycle();
  e.seconds = static_cast<double>(end) / (timing.clock_mhz * 1e6);
  e.frames_per_second = e.seconds > 0 ? static_cast<double>(e.frames) / e.seconds : 0;
  e.gpu_busy = end ? static_cast<double>(busy) / static_cast<double>(end) : 0;
  e.overflow = e.max_fifo > fifo_depth;
  return e;
}

Result<double> fastest_lossless_baud(std::span<const std::uint64_t> words, std::shared_ptr<const TextureMemory> textures,
                                     const TimingParameters& timing, unsigned fifo_depth) {
  double lo = 9600, hi = 100e6;  // lo never overflows on a real stream; hi always does
  auto ok = [&](double baud) -> Result<bool> {
    auto e = estimate_link(words, baud, textures, timing, fifo_depth);
    if (!e) return e.error();
    return !e->overflow;
  };
  auto first = ok(lo);
  if (!first) return first.error();
  if (!*first) return 0.0;
  auto top = ok(hi);
  if (!top) return top.error();
  if (*top) return hi;
  while (hi / lo > 1.01) {
    const double mid = std::sqrt(lo * hi);
    auto m = ok(mid);
    if (!m) return m.error();
    (*m ? lo : hi) = mid;
  }
  return lo;
}

}  // namespace gpubridge::dmc1
