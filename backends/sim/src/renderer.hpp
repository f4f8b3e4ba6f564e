#pragma once
// Runs kicked triangles through setup and the rasteriser. With one thread every triangle is drawn
// at once. With N threads triangles are batched while the render state stays the same; a batch is
// drawn by N workers that each walk all triangles in submission order and draw only their own
// rows (a run of whole 16-row bands each, cut by an estimate of the batch's work weighted by the
// work the workers measured on earlier batches: BandSplit), so
// the bytes are identical for any N. The calling thread (the device front end) decodes and sets
// up the next batch while the workers draw the previous one; batches are drawn one after another,
// and flush() waits for both.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "band_split.hpp"
#include "gpubridge/common/band_pool.hpp"
#include "draw_state.hpp"
#include "gpubridge/sim/device.hpp"
#include "gpubridge/sim/timing.hpp"
#include "rasterizer.hpp"
#include "reciprocal.hpp"
#include "setup.hpp"
#include "video_memory.hpp"

namespace gpubridge::sim {

class Renderer {
 public:
  // sdram_rows: count the SDRAM rows the drawn spans open (DeviceOptions::sdram_rows).
  Renderer(VideoMemory& mem, const AccuracyKnobs& knobs, unsigned threads, bool vector_routines, bool sdram_rows = false);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  void set_observer(PixelObserver observer) { observer_ = std::move(observer); }
  // Draws (or queues) one triangle. A state object different from the batch's flushes the batch.
  void draw(const Vertex& a, const Vertex& b, const Vertex& c, const std::shared_ptr<const DrawState>& state,
            std::uint64_t index);
  // Completes every queued triangle (the batch, or the one pending triangle of the single-thread
  // pipeline). Call before anything reads or writes video memory.
  void flush();

  // ERR_* flags raised by drawing since the last call.
  std::uint16_t take_errors();
  std::uint64_t triangles_rasterised() const { return rasterised_; }
  const RasterCounters& counters() const { return counters_; }
  // Triangles, box rows and covered pixels per render-state class; triangles set up for nothing.
  const std::array<DeviceStats::ModeWork, DeviceStats::kModeClasses>& mode_work() const { return modes_; }
  std::uint64_t triangles_rejected() const { return rejected_; }
  // The SDRAM rows the drawn triangles' spans open (the timing model's row counts); clears touch it.
  // Counted only when asked for at construction (counts_sdram_rows()).
  SdramRows& sdram_rows() { return sdram_; }
  bool counts_sdram_rows() const { return count_rows_; }
  // Texture bytes the textured triangles' footprints hold (texel_footprint_bytes).
  std::uint64_t texel_footprint() const { return texel_footprint_; }
  // The ecp5's texel cache replayed beside the rows (its misses are texel reads in the row stream).
  TexelCache& texel_cache() { return texel_cache_; }
  std::uint64_t depth_tail() const { return depth_tail_; }  // depth_tail_pixels of the depth classes
  void reset_counters() {
    sdram_.reset_counts();
    texel_cache_.reset_counts();
    depth_tail_ = 0;
    texel_footprint_ = 0;
    counters_ = {};
    rasterised_ = 0;
    rejected_ = 0;
    modes_ = {};
  }

  static constexpr std::size_t kMaxBatch = 4096;
  // The first batch after a flush holds at most this many triangles, and each batch after it
  // twice as many as the one before, up to kMaxBatch: the workers start drawing after the first
  // few set-up triangles instead of after 4,096 of them (a frame of 2,000 triangles was set up
  // whole on the device thread before either worker drew a pixel).
  static constexpr std::size_t kFirstBatch = 128;

 private:
  // Hands the filling batch to the workers (after the one they are drawing) and returns.
  void submit();
  // Waits for the batch the workers are drawing and collects its errors and counters.
  void wait_drawing();
  void draw_bands(unsigned worker);
  void draw_pending();
  void prefetch_rows(int x0, int y0, int x1, int y1, const DrawState& st) const;
  // How a triangle was set up: not at all (it draws nothing), as a compact small-triangle record
  // (SmallTriangle, preview) or as a Triangle.
  enum class SetUp { None, Small, Full };
  // Sets up a triangle as the state and the accuracy want it, into s or t.
  SetUp setup(const Vertex& a, const Vertex& b, const Vertex& c, const DrawState& st, bool observing, Triangle& t,
              SmallTriangle& s) const;
  // Counts a triangle that was set up (rasterised, and its state class's triangles, rows, columns).
  void count_rasterised(const Triangle& t, const DrawState& st);
  void count_box(int x0, int y0, int x1, int y1, const DrawState& st);
  // A context for drawing with st in coarse-depth generation gen, for worker w (hier_z.hpp).
  RasterContext context(const DrawState& st, std::uint64_t gen, unsigned w);
  // Lets ctx use the coarse depth bounds for st in generation gen, as worker w's run (no worker draws).
  void use_hier_z(RasterContext& ctx, const DrawState& st, std::uint64_t gen, unsigned w);
  // Ends the coarse depth bounds' generation (at every flush and change of state).
  void next_generation() { ++hz_gen_; }


  VideoMemory& mem_;
  AccuracyKnobs knobs_;
  bool vector_;
  bool count_rows_;
  ReciprocalUnit recip_;
  BandPool pool_;
  PixelObserver observer_;
  // What a band worker reads of every triangle of a batch to find its rows (the box rows, and
  // whether the triangle is in the batch's compact small records or its Triangles): 6 bytes
  // instead of a line of a 920-byte Triangle for the triangles not in its bands.
  struct BatchRows {
    std::int16_t y0 = 0, y1 = 0;
    bool small = false;
  };
  // A batch: entry i is rows[i] and, as rows[i].small says, small[i] or full[i].
  struct Batch {
    std::vector<BatchRows> rows;
    std::vector<SmallTriangle> small;
    std::vector<Triangle> full;
  };
  Batch batch_;  // being filled by the front end: its first batch_n_
  std::size_t batch_n_ = 0;
  std::size_t batch_limit_ = kFirstBatch;  // the filling batch is handed over at this many triangles
  unsigned batches_since_flush_ = 0;  // batches handed over since the last flush (BandSplit's weight sets)
  std::shared_ptr<const DrawState> batch_state_;
  Batch drawing_;  // being drawn by the workers: its first drawing_n_
  std::size_t drawing_n_ = 0;
  std::shared_ptr<const DrawState> drawing_state_;
  BandSplit split_;  // the filling batch's estimated work by band
  std::vector<int> drawing_cuts_;  // worker w draws the drawing batch's rows drawing_cuts_[w]..[w + 1] - 1
  // One worker's context on cache lines of its own: the workers write their counters and run
  // numbers while they draw, and two contexts side by side in one line bounced it between cores.
  struct alignas(64) WorkerContext {
    RasterContext ctx;
    // The triangles this worker drew rows of and those rows (their boxes' rows in its run): with
    // the context's covered and coarse-depth-rejected pixels, its measured work (BandSplit).
    std::uint64_t triangles = 0, rows = 0;
  };
  std::vector<WorkerContext> drawing_ctx_;  // one per worker
  std::vector<std::int64_t> measured_;  // each worker's measured work on the batch just drawn (BandSplit::measured)
  bool drawing_active_ = false;
  std::function<void(unsigned)> draw_job_;
  Triangle slots_[2];
  SmallTriangle small_slots_[2];
  int pending_ = -1;  // slot set up but not yet drawn (single-thread pipelining)
  bool pending_is_small_ = false;  // the pending triangle is small_slots_[pending_], not slots_[pending_]
  std::shared_ptr<const DrawState> pending_state_;
  SmallDraw pending_small_;  // for pending_state_ when it has small preview triangles
  SmallSetupRoutine small_setup_ = small_setup_routine();
  std::uint16_t errors_ = 0;
  std::uint64_t rasterised_ = 0;
  std::uint64_t rejected_ = 0;
  RasterCounters counters_;
  std::array<DeviceStats::ModeWork, DeviceStats::kModeClasses> modes_{};
  SdramRows sdram_;
  TexelCache texel_cache_;
  std::uint64_t depth_tail_ = 0;
  std::uint64_t texel_footprint_ = 0;
  // Coarse depth bounds (hier_z.hpp): their generation, the state it belongs to (held, so a new
  // state cannot reuse its address unnoticed), the generations of the filling batch, the batch
  // being drawn and the pending triangle, and each worker's last Kernel run number.
  HierZ hier_z_;
  std::uint64_t hz_gen_ = 1;
  std::shared_ptr<const DrawState> hz_state_;
  std::uint64_t batch_gen_ = 0, drawing_gen_ = 0, pending_gen_ = 0;
  bool pending_hz_ = false;  // the bounds apply to pending_state_
  std::vector<std::uint32_t> hz_runs_;
  void add_counters(const RasterCounters& c, const DrawState& st) {
    counters_.add(c);
    modes_[st.mode_class].pixels += c.covered;
  }
};

}  // namespace gpubridge::sim
