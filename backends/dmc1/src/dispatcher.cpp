#include "dispatcher.hpp"

#include <algorithm>

#include "fixed_point.hpp"

namespace gpubridge::dmc1 {

void Dispatcher::push(std::uint64_t word, CommandFifo& fifo, TimingModel& timing, DeviceStats& stats) {
  ++stats.commands;
  const auto t0 = static_cast<std::uint32_t>(word >> 32), t1 = static_cast<std::uint32_t>(word);
  const CommandKind kind = kind_of(word);
  switch (kind) {
    case CommandKind::RayCs:  // 14-bit fields in the command, 13-bit registers
      regs_.cos = sext(t0, 13);
      regs_.sin = sext(t0 >> 14, 13);
      break;
    case CommandKind::UvOffset:
      regs_.v_offset = sext(t0, 24);
      regs_.u_offset = sext(t1 >> 1, 24);
      regs_.lightmap = (t1 >> 25) & 1;
      break;
    case CommandKind::PlaneA:
      regs_.ny = sext(t0, 10);
      regs_.uy = sext(t0 >> 10, 10);
      regs_.vy = sext(t0 >> 20, 10);
      regs_.dot_u = wrap24(std::int64_t{sext(t1 >> 1, 14)} * 256);
      regs_.dot_v = wrap24(std::int64_t{sext(t1 >> 15, 14)} * 256);
      break;
    case CommandKind::ViewZ: regs_.view_z = sext(t0, 16); break;
    case CommandKind::EndOfColumn: {
      SpanJob job;
      job.type = JobType::EndOfColumn;
      job.column = static_cast<std::uint16_t>(column_);
      fifo.jobs.push_back(job);
      draw_buffer_ ^= 1;
      column_ = (column_ + 1) % kColumns;
      const bool last = column_ == 0;
      fifo.frame_complete = last;
      timing.end_of_column(last);
      ++stats.columns;
      return;
    }
    default: span(word, kind, fifo, timing, stats); return;
  }
  ++stats.parameters;
  timing.parameter();
}

void Dispatcher::span(std::uint64_t word, CommandKind kind, CommandFifo& fifo, TimingModel& timing, DeviceStats& stats) {
  const auto t0 = static_cast<std::uint32_t>(word >> 32), t1 = static_cast<std::uint32_t>(word);
  const unsigned start = (t1 >> 10) & 255, raw_end = (t1 >> 18) & 255;
  if (start > raw_end) {  // the dispatcher never hands these to the drawer
    ++stats.dropped_spans;
    timing.dropped_span();
    return;
  }
  const unsigned end = std::min(raw_end, kRows - 1);
  const unsigned tid = t1 & 1023;
  const bool binds = tid != 0 && tid != regs_.sampler_texture;
  if (binds) {
    regs_.binding = textures_->binding(tid);
    ++stats.texture_binds;
  }
  regs_.sampler_texture = tid;

  SpanJob job;
  job.start = static_cast<std::uint8_t>(start);
  job.end = static_cast<std::uint8_t>(end);
  job.lightmap = regs_.lightmap;
  job.background = tid == 0;
  job.light = static_cast<std::uint8_t>((t1 >> 26) & 15);
  job.binding = regs_.binding;
  // A span starting beyond row 239 still runs one pixel (at a row that is never sent).
  const std::uint32_t events = (end >= start ? end - start + 1 : 1) + 2;  // two warm-up events

  switch (kind) {
    case CommandKind::Wall:
      job.dist = static_cast<std::uint32_t>(sext(t0, 16)) & 0x7FFFFFFF;
      if (job.background) {
        job.type = JobType::Fill;
        job.entry = job.lightmap ? kBackgroundTexel : (15u << 12 | kBackgroundTexel);
        ++stats.backgrounds;
        timing.background(events);
      } else {
        job.type = JobType::Wall;
        job.u = t0 >> 24;
        job.v_fixed = ((t0 >> 16) & 255) << 11;
        job.v_step = t0 & 0x3FFF;
        ++stats.walls;
        timing.wall_or_plane(events, binds);
      }
      regs_.advance_dots(events);
      stats.row_events += events;
      break;
    case CommandKind::Plane:
      regs_.ded = sext(t0, 16);
      regs_.dot_ray = wrap24(std::int64_t{sext(t0 >> 16, 16)} * 256);
      job.type = JobType::Plane;
      job.dot_ray = regs_.dot_ray;
      job.dot_u = regs_.dot_u;
      job.dot_v = regs_.dot_v;
      job.ny = regs_.ny;
      job.uy = regs_.uy;
      job.vy = regs_.vy;
      job.ded = regs_.ded;
      job.u_offset = regs_.u_offset;
      job.v_offset = regs_.v_offset;
      regs_.advance_dots(events);
      ++stats.planes;
      stats.row_events += events;
      timing.wall_or_plane(events, binds);
      break;
    default: {  // terrain
      job.type = JobType::Pixels;
      const std::uint32_t terrain_events = terrain(word, start, end, job, fifo);
      ++stats.terrains;
      stats.row_events += terrain_events;
      timing.terrain(terrain_events, binds);
      break;
    }
  }
  fifo.jobs.push_back(job);
}

// The terrain event machine (docs/dmc1.md, "Terrain"). Unlike walls and planes, each event's state
// depends on the texel fetched two events earlier (the projected height decides where the column
// ends), so terrain runs event by event here; its writes only wait for the depth test.
std::uint32_t Dispatcher::terrain(std::uint64_t word, unsigned start, unsigned end, SpanJob& job, CommandFifo& fifo) {
  ParameterRegisters& r = regs_;
  const auto t0 = static_cast<std::uint32_t>(word >> 32);
  const unsigned end_distance = t0 & 2047;
  const bool pick = (t0 >> 31) != 0;
  // {start_distance, 8'b0} sign-extended from bit 18: a start of 1024 or more sets bit 19 (done).
  const std::int32_t first = wrap24(sext(std::uint64_t{(t0 >> 16) & 2047} << 8, 19));
  std::int32_t tcol = first, prev = first, tc_v = first;  // column distance, previous one, interpolated
  unsigned current = start;  // row being drawn
  unsigned stop = start;     // row the current projected column reaches (`end` in the RTL)
  unsigned skip = 3;         // warm-up shift register: no writes and no row advance while bit 0 is set
  bool ready = false;        // a column step happened: the next event projects its height
  bool picked = false;
  job.first_write = static_cast<std::uint32_t>(fifo.writes.size());

  auto fetch = [&]() -> std::uint8_t {
    if (job.background) return kBackgroundTexel;
    const std::uint32_t d = (static_cast<std::uint32_t>(ready ? tcol : tc_v) >> 8) & 2047;
    const std::int32_t tr_u = wrap24((wrap32(std::int64_t{d} * r.cos) >> 2) + std::int64_t{r.u_offset});
    const std::int32_t tr_v = wrap24((wrap32(std::int64_t{d} * r.sin) >> 2) + std::int64_t{r.v_offset});
    const std::uint32_t u = (static_cast<std::uint32_t>(tr_u) >> 12) & 1023;
    // v bit 10 selects the colour half while rows remain, the height half at a column step.
    const std::uint32_t v = ((static_cast<std::uint32_t>(tr_v) >> 12) & 1023) | (current < stop ? 1024u : 0u);
    return textures_->texel(job.binding, u, v);
  };
  // The texel seen at event k was fetched after event k - 2 (one fetch in flight).
  std::uint8_t older = 0, newer = fetch();
  std::uint32_t events = 0;
  for (;;) {
    const std::uint8_t texel = older;
    older = newer;
    const auto dist_bits = static_cast<std::uint32_t>(tcol) & 0xFFFFFF;
    const bool rows_done = current >= stop;
    const bool drawing = ((dist_bits >> 8) & 2047) <= end_distance && !((dist_bits >> 19) & 1);
    if (!ready && !(skip & 1) && (texel != kTransparentTexel || job.lightmap) && current < kRows) {
      const std::uint32_t dist = (dist_bits >> 5) & 0x7FFFF;
      const unsigned l4 = job.background ? 15 : light_nibble(job.light, dist);
      fifo.writes.push_back({static_cast<std::uint8_t>(current),
                             static_cast<std::uint16_t>(job.lightmap ? texel : (l4 << 12 | texel)), dist});
    }
    if (ready) {  // project the height sampled at the step: the screen row this column reaches
      const std::int32_t h = wrap32(std::int64_t{kInverse.unsigned_at((dist_bits >> 8) & 2047)} * (texel - r.view_z));
      const std::int32_t scrh = sext(static_cast<std::uint64_t>((h >> 8) + 120), 16);
      const unsigned next_stop = scrh < 0 ? 0 : std::min(static_cast<unsigned>(scrh), end);
      r.scrh_diff = static_cast<std::uint8_t>(next_stop - current);
      ready = false;
      tc_v = prev;
      stop = next_stop;
      if (pick && !picked) r.picked_height = texel;
      picked = true;
    } else {
      const std::uint32_t steps = ((dist_bits >> 8) - (static_cast<std::uint32_t>(prev) >> 8)) & 2047;
      const std::uint32_t tc_v_step = (((steps * kInverse.unsigned_at(r.scrh_diff)) & 0xFFFFFF) >> 8) & 0x3FFF;
      if (rows_done) {  // step the distance: 8 units, doubling every 512
        prev = tcol;
        tcol = wrap24(std::int64_t{tcol} + (2048 << ((dist_bits >> 17) & 3)));
      }
      ready = rows_done;
      if (!(skip & 1)) {
        if (!rows_done) current = (current + 1) & 255;
        tc_v = wrap24(std::int64_t{tc_v} + tc_v_step);
      }
      r.advance_dots(1);
      skip = (skip & 2) ? skip >> 1 : (rows_done ? 1 : 0);
    }
    ++events;
    // At most 120 distance steps of 3 events plus 240 rows: the bound only guards the FIFO.
    if (!drawing || events >= CommandFifo::kMaxWritesPerSpan) break;
    newer = fetch();
  }
  job.writes = static_cast<std::uint32_t>(fifo.writes.size()) - job.first_write;
  return events;
}

}  // namespace gpubridge::dmc1
