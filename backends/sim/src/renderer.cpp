#include "renderer.hpp"

#include <algorithm>

#include "hier_z.hpp"
#include "sdram_spans.hpp"

namespace gpubridge::sim {

Renderer::Renderer(VideoMemory& mem, const AccuracyKnobs& knobs, unsigned threads, bool vector_routines, bool sdram_rows)
    : mem_(mem), knobs_(knobs), vector_(vector_routines), count_rows_(sdram_rows), recip_(knobs.recip_bits, knobs.nr_steps),
      pool_(threads) {
  if (pool_.workers() > 1) {
    // Constructed once: a batch's triangles are set up in place (no triangle constructed per draw).
    for (Batch* b : {&batch_, &drawing_}) {
      b->rows.resize(kMaxBatch);
      b->small.resize(kMaxBatch);
      b->full.resize(kMaxBatch);
    }
  }
  draw_job_ = [this](unsigned worker) { draw_bands(worker); };
  hz_runs_.assign(pool_.workers(), 0);
}

// Each coarse depth block, and its band's records, is touched by the one worker owning its rows.
static_assert(BandSplit::kBandRows == 1 << HierZ::kRowsLog, "cuts fall between the coarse depth bounds' bands");

namespace {
// The coarse depth bounds hold for a state whose depth writes only ever lower the stored depth
// (a LESS or LEQUAL test) and whose colour writes cannot reach the depth buffer; with the vector
// routines only (the reference routines stay the plain per-pixel path they are compared with).
bool hier_z_applies(const DrawState& st, bool vector) {
  return vector && st.z_test && (st.z_func == protocol::DepthFunc::Less || st.z_func == protocol::DepthFunc::LessEqual) &&
         st.z_in_vram && st.color_in_vram && st.buffers_disjoint;
}
}  // namespace

void Renderer::use_hier_z(RasterContext& ctx, const DrawState& st, std::uint64_t gen, unsigned w) {
  hier_z_.prepare(st.fb_width, st.fb_height);  // no worker is drawing (the callers waited)
  ctx.hier_z = &hier_z_;
  ctx.hz_gen = gen;
  ctx.hz_run = hz_runs_[w];
}

RasterContext Renderer::context(const DrawState& st, std::uint64_t gen, unsigned w) {
  RasterContext ctx{mem_, recip_, knobs_.z_bits, 0, {}, vector_};
  if (hier_z_applies(st, vector_)) use_hier_z(ctx, st, gen, w);
  return ctx;
}

Renderer::~Renderer() { wait_drawing(); }  // the workers read drawing_: stop them before it goes

// Small triangles are bound by the latency of their first depth and colour reads (random screen
// positions miss the caches): start those loads for the triangle just set up, so they overlap
// drawing the previous one and setting up the next. Its clipped bounding box is known by now (a
// box from the raw vertices before setup cost 60 more instructions per triangle).
[[gnu::always_inline]] inline void Renderer::prefetch_rows(int x0, int y0, int x1, int y1, const DrawState& st) const {
  if (!st.color_in_vram || !st.z_in_vram) return;
  const int rows = std::min(y1 - y0, 8);
  // The row's first 8 pixels (32 bytes at 4 bytes per pixel) may straddle two cache lines.
  const std::size_t last = static_cast<std::size_t>(std::min(7, x1 - 1 - x0));
  const std::size_t first = static_cast<std::size_t>(y0) * st.fb_width + static_cast<std::size_t>(x0);
  const std::uint8_t* color = mem_.data() + st.fb_draw + first * st.bpp;
  const std::size_t cpitch = std::size_t{st.fb_width} * st.bpp, clast = last * st.bpp;
  if (!st.z_test && !st.z_write) {
    for (int r = 0; r < rows; ++r, color += cpitch) {
      __builtin_prefetch(color, 1);
      __builtin_prefetch(color + clast, 1);
    }
    return;
  }
  // Colour and depth rows in one loop (half the loop overhead of two).
  const std::uint8_t* depth = mem_.data() + st.fb_z + first * 4;
  const std::size_t zpitch = std::size_t{st.fb_width} * 4, zlast = last * 4;
  for (int r = 0; r < rows; ++r, color += cpitch, depth += zpitch) {
    __builtin_prefetch(color, 1);
    __builtin_prefetch(color + clast, 1);
    __builtin_prefetch(depth, 1);
    __builtin_prefetch(depth + zlast, 1);
  }
}

// Preview mode sets up float planes for the preview routine where it applies (the exact path
// draws the rest).
// Inlined into both callers: a call per triangle costs more than its checks.
[[gnu::always_inline]] inline Renderer::SetUp Renderer::setup(const Vertex& a, const Vertex& b, const Vertex& c,
                                                              const DrawState& st, bool observing, Triangle& t,
                                                              SmallTriangle& s) const {
  // Small triangles of a plain untextured preview draw: their own setup, into the compact record.
  if (knobs_.preview && st.preview_small != 0 && !observing) {
    const SmallSetup r = small_setup_(a, b, c, st, knobs_.subpixel_bits, s);
    if (r != SmallSetup::NotSmall) return r == SmallSetup::Drawn ? SetUp::Small : SetUp::None;
  }
  const bool drawn = knobs_.preview && st.preview_ok
                         ? setup_triangle_preview(a, b, c, st, knobs_.subpixel_bits, observing, t)
                         : setup_triangle(a, b, c, st, knobs_.subpixel_bits, observing, t);
  return drawn ? SetUp::Full : SetUp::None;
}

// Inlined into draw(): a call per small triangle costs more than its body.
[[gnu::always_inline]] inline void Renderer::draw_pending() {
  if (pending_ < 0) return;
  if (pending_is_small_) {  // no errors (both buffers inside memory), counters straight into the totals
    const SmallTriangle& s = small_slots_[pending_];
    const std::uint64_t covered = counters_.covered;
    rasterize_small(s, pending_small_, counters_, s.y0, s.y1);
    modes_[pending_state_->mode_class].pixels += counters_.covered - covered;
    pending_ = -1;
    return;
  }
  const Triangle& t = slots_[pending_];
  RasterContext ctx{mem_, recip_, knobs_.z_bits, 0, {}, vector_};
  // Boxes narrower than the span solve's 16 pixels never ask the bounds (their writes not marked
  // only leave bounds looser): no set-up for them (10-px triangles).
  const bool hz = pending_hz_ && t.x1 - t.x0 >= 16;
  if (hz) use_hier_z(ctx, *pending_state_, pending_gen_, 0);
  rasterize_rows(t, *pending_state_, ctx, t.y0, t.y1);
  if (hz) hz_runs_[0] = ctx.hz_run;
  errors_ |= ctx.errors;
  add_counters(ctx.counters, *pending_state_);
  pending_ = -1;  // pending_state_ stays: the next triangle most likely uses it again
}

void Renderer::draw(const Vertex& a, const Vertex& b, const Vertex& c, const std::shared_ptr<const DrawState>& state,
                    std::uint64_t index) {
  const DrawState& st = *state;
  if (st.clip.empty()) return;
  const bool observing = static_cast<bool>(observer_);
  // No work when nothing is written (unless someone watches the attributes).
  if (st.writes_nothing && !observing) return;
  if (hz_state_ != state) {  // a new state: the coarse depth bounds start afresh
    next_generation();
    hz_state_ = state;
  }
  const bool batching = pool_.workers() > 1 && !observing && st.bands_independent;
  if (batching) {
    draw_pending();
    if (batch_n_ != 0 && batch_state_ != state) submit();
    // The front end sets the triangle up while the workers draw the previous batch. Setting up in
    // the workers instead (an equal run each, then a barrier, then the bands) took the front end's
    // setup off the busiest thread but lost this overlap: on two cores it was slower at 2 threads
    // (10-px triangles, exact 7.8 -> 6.9, preview 15.5 -> 10.2 Mtri/s; docs/simulator.md, "Threads").
    BatchRows& rows = batch_.rows[batch_n_];
    Triangle& t = batch_.full[batch_n_];
    SmallTriangle& s = batch_.small[batch_n_];
    const SetUp how = setup(a, b, c, st, false, t, s);
    if (how == SetUp::None) {
      ++rejected_;
      return;
    }
    if (how == SetUp::Small) {
      rows = {s.y0, s.y1, true};
      split_.add(s.y0, s.y1, s.den);
      count_box(s.x0, s.y0, s.x1, s.y1, st);
    } else {
      rows = {static_cast<std::int16_t>(t.y0), static_cast<std::int16_t>(t.y1), false};
      split_.add(t.y0, t.y1, t.den);
      t.index = index;
      count_rasterised(t, st);
    }
    if (batch_n_ == 0) batch_gen_ = hz_gen_;  // one state and no flush within a batch: one generation
    if (batch_state_ != state) batch_state_ = state;
    if (++batch_n_ >= batch_limit_) submit();
    return;
  }
  if (batch_n_ != 0 || drawing_active_) flush();
  // Single thread: set up into the free slot; the previous triangle is drawn after this setup so
  // the prefetched rows of this one arrive while it is drawn (order of pixel writes unchanged).
  const int slot = pending_ == 0 ? 1 : 0;
  Triangle& t = slots_[slot];
  SmallTriangle& s = small_slots_[slot];
  const SetUp how = setup(a, b, c, st, observing, t, s);
  if (how == SetUp::None) {
    ++rejected_;
    return;
  }
  const bool small = how == SetUp::Small;  // never observed, never a state that writes nothing
  if (small) {
    count_box(s.x0, s.y0, s.x1, s.y1, st);
    prefetch_rows(s.x0, s.y0, s.x1, s.y1, st);
  } else {
    t.index = index;
    count_rasterised(t, st);
    if (observing) observe_triangle(t, st, observer_);
    if (st.writes_nothing) return;
    prefetch_rows(t.x0, t.y0, t.x1, t.y1, st);
  }
  draw_pending();
  pending_ = slot;
  pending_is_small_ = small;
  pending_gen_ = hz_gen_;
  // The state object is shared with the device: copy the pointer (an atomic count update)
  // only when it changed, not once per triangle.
  if (pending_state_ != state) {
    pending_state_ = state;
    pending_hz_ = hier_z_applies(st, vector_);
    if (knobs_.preview && st.preview_small != 0) pending_small_ = small_draw(st, mem_, knobs_.z_bits);
  }
}

[[gnu::always_inline]] inline void Renderer::count_box(int x0, int y0, int x1, int y1, const DrawState& st) {
  ++rasterised_;
  auto& mode = modes_[st.mode_class];
  ++mode.triangles;
  mode.rows += static_cast<std::uint64_t>(y1 - y0);
  mode.columns += static_cast<std::uint64_t>(x1 - x0);
}

void Renderer::count_rasterised(const Triangle& t, const DrawState& st) {
  count_box(t.x0, t.y0, t.x1, t.y1, st);
  if (!count_rows_ || st.writes_nothing) return;
  const std::uint64_t covered = access_triangle_rows(sdram_, texel_cache_, t, st);
  if (st.mode_class & 4) texel_footprint_ += texel_footprint_bytes(t, st, covered);
  if (st.mode_class & 2) depth_tail_ += depth_tail_pixels(covered);
}

void Renderer::flush() {
  draw_pending();
  submit();
  wait_drawing();
  next_generation();  // whoever flushed may now read or write memory
  batch_limit_ = kFirstBatch;  // the workers are idle: the next batch starts them soon
  batches_since_flush_ = 0;
}

void Renderer::submit() {
  wait_drawing();
  if (batch_n_ == 0) {
    batch_state_.reset();
    return;
  }
  std::swap(batch_, drawing_);
  drawing_n_ = batch_n_;
  batch_n_ = 0;
  batch_limit_ = std::min(2 * batch_limit_, kMaxBatch);
  drawing_state_ = std::move(batch_state_);
  drawing_gen_ = batch_gen_;
  split_.split(pool_.workers(), batches_since_flush_++, drawing_cuts_);
  batch_state_.reset();
  drawing_ctx_.clear();
  for (unsigned w = 0; w < pool_.workers(); ++w) drawing_ctx_.push_back({context(*drawing_state_, drawing_gen_, w), 0, 0});
  drawing_active_ = true;
  pool_.start(draw_job_);
}

void Renderer::wait_drawing() {
  if (!drawing_active_) return;
  pool_.wait();
  measured_.resize(drawing_ctx_.size());
  for (unsigned w = 0; w < drawing_ctx_.size(); ++w) {
    const WorkerContext& wc = drawing_ctx_[w];
    const RasterContext& c = wc.ctx;
    errors_ |= c.errors;
    add_counters(c.counters, *drawing_state_);  // one state per batch
    if (c.hier_z) hz_runs_[w] = c.hz_run;
    const std::uint64_t shaded = c.counters.covered > c.hz_skipped_pixels ? c.counters.covered - c.hz_skipped_pixels : 0;
    measured_[w] = BandSplit::measured_work(wc.triangles, wc.rows, c.hz_skipped_rows, shaded,
                                            knobs_.preview ? BandSplit::kPreviewTriangleWork : BandSplit::kTriangleWork);
  }
  split_.measured(measured_);  // the next batch's cuts (submit() splits after this wait)
  drawing_n_ = 0;
  drawing_state_.reset();
  drawing_active_ = false;
}

// One worker's share of a batch: its rows of every triangle, in submission order.
void Renderer::draw_bands(unsigned worker) {
  const DrawState& st = *drawing_state_;
  RasterContext& c = drawing_ctx_[worker].ctx;
  const SmallDraw small = knobs_.preview && st.preview_small != 0 ? small_draw(st, mem_, knobs_.z_bits) : SmallDraw{};
  // In locals: the kernels are called through pointers, so the compiler would load the batch's
  // fields again for every triangle.
  const BatchRows* const rows = drawing_.rows.data();
  const SmallTriangle* const smalls = drawing_.small.data();
  const Triangle* const full = drawing_.full.data();
  const std::size_t count = drawing_n_;
  // This worker's rows of the batch (BandSplit): each triangle's rows among them in one call.
  const int lo = drawing_cuts_[worker], hi = drawing_cuts_[worker + 1];
  if (lo >= hi) return;
  // What this worker drew, for its measured work (BandSplit): counted in locals, stored once.
  std::uint64_t drawn = 0, drawn_rows = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const BatchRows r = rows[i];
    if (r.y1 <= lo || r.y0 >= hi) continue;  // a box outside this worker's rows: not even a call
    ++drawn;
    drawn_rows += static_cast<unsigned>(std::min<int>(r.y1, hi) - std::max<int>(r.y0, lo));
    if (r.small) rasterize_small(smalls[i], small, c.counters, lo, hi);
    else rasterize_rows(full[i], st, c, lo, hi);
  }
  drawing_ctx_[worker].triangles = drawn;
  drawing_ctx_[worker].rows = drawn_rows;
}

std::uint16_t Renderer::take_errors() {
  const std::uint16_t e = errors_;
  errors_ = 0;
  return e;
}

}  // namespace gpubridge::sim
