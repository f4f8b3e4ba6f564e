#pragma once
// Predicted GPU cycles per frame (docs/dmc1.md, "Timing"): the DMC-1 runs one span at a time; a
// span costs a start-up, a texture bind when its id differs from the sampler's, and a fixed period
// per row event (n + 2 events for an n-row wall or plane, the event count of the terrain machine
// for terrain). An end-of-column command waits for the span drawer and for the column sender to
// finish the previous column; the sender then presents the column while the next one is drawn.
// Defaults: the icebreaker's SPIflash configuration with an always-ready screen consumer, the
// conditions of the RTL cycle counts in tests/dmc1/data/golden/*.cycles.
#include <cstdint>
#include <string>
#include <vector>

#include "gpubridge/common/result.hpp"

namespace gpubridge::dmc1 {

struct TimingParameters {
  double clock_mhz = 25.0;               // GPU (1x) clock: 25 MHz on the icebreaker
  std::uint32_t startup = 250;           // reset release to the texture memory being ready
  std::uint32_t texel_period = 7;        // wall/plane row event (texel fetch period)
  std::uint32_t background_period = 2;   // row event of a texture-0 wall (no fetch)
  std::uint32_t terrain_period = 10;     // terrain event
  std::uint32_t span_overhead = 4;       // dispatch and pipeline start of a textured or terrain span
  std::uint32_t bind = 12;               // texture header read when the id changes
  std::uint32_t background_overhead = 3; // dispatch and start of a background span
  std::uint32_t command = 2;             // a parameter or a dropped span
  std::uint32_t end_of_column = 1;       // end-of-column dispatch
  std::uint32_t column_words = 241;      // the sender presents 241 words per column (the last is unused)
  std::uint32_t sender_pipeline = 4;     // palette/light pipeline stages of the sender
  std::uint32_t screen_cycles_per_word = 1;  // 1: always-ready consumer; 19: the SPI screen controller

  std::uint32_t column_send() const { return column_words * screen_cycles_per_word + sender_pipeline; }
};
// "KEY=VALUE" for one field above (`gpubridge render --device dmc1 --board-timing`).
Result<void> apply_timing_setting(TimingParameters& p, const std::string& setting);

class TimingModel {
 public:
  explicit TimingModel(TimingParameters p = {}) : p_(p), now_(p.startup) {}

  void parameter() { now_ += p_.command; }
  void dropped_span() { now_ += p_.command; }
  void wall_or_plane(std::uint32_t events, bool binds) { now_ += std::uint64_t{events} * p_.texel_period + p_.span_overhead + (binds ? p_.bind : 0); }
  void background(std::uint32_t events) { now_ += std::uint64_t{events} * p_.background_period + p_.background_overhead; }
  void terrain(std::uint32_t events, bool binds) { now_ += std::uint64_t{events} * p_.terrain_period + p_.span_overhead + (binds ? p_.bind : 0); }
  // last_of_frame: this column completes a frame (frame_cycles() gains an entry).
  void end_of_column(bool last_of_frame);

  const TimingParameters& parameters() const { return p_; }
  // Cycles of each completed frame: frame 0 from reset release (start-up included), frame k from
  // the end of frame k-1, each ending when the sender has presented the frame's last column.
  const std::vector<std::uint64_t>& frame_cycles() const { return frames_; }
  // Cycle at which everything queued so far has been drawn and sent.
  std::uint64_t drain_cycle() const { return now_ > sender_free_ ? now_ : sender_free_; }
  // Cycle at which the GPU takes its next command.
  std::uint64_t next_dispatch() const { return now_; }
  // No command arrives before `cycle` (a link slower than the GPU): the drawer idles until then.
  void idle_until(std::uint64_t cycle) { now_ = cycle > now_ ? cycle : now_; }
  void reset() { *this = TimingModel(p_); }

 private:
  TimingParameters p_;
  std::uint64_t now_;              // when the drawer is free for the next command
  std::uint64_t sender_free_ = 0;  // when the column sender finishes the column it is sending
  std::uint64_t last_frame_end_ = 0;
  std::vector<std::uint64_t> frames_;
};

}  // namespace gpubridge::dmc1
