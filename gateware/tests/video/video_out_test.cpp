// gateware/rtl/soc/video_out.v alone, Verilated with one board's parameters (VIDEO_* definitions, see
// CMakeLists.txt): a known framebuffer in a behavioural VRAM (answers in order after 1..4 clocks,
// refuses requests at random, as the arbiter does when another client wins), the scanout's display
// counters (hcount, vcount: a line of 800 x PIX_DIV clocks, 525 lines), a swap as the scanout latches
// it (frame_start with the frame's address at the vertical sync), and two frames of output checked
// sample by sample against VESA 640 x 480 at 60 Hz timing and the expected picture (scaled, centred
// or at the top left as the board's CENTRE says, expanded as docs/protocol.md section 6 says, black around it and before the first swap).
// A board whose pixels have their own clock (PCLK = 1, the ULX3S) runs two clocks at their real ratio:
// the core at 52.08 MHz, one picosecond a clock slower so that its phase drifts through every
// position against the 25 MHz pixel clock, the scanout's counters advanced by the module's tick as
// the scanout does; a core edge up to 2 ns after a pixel edge sees the pixel toggle metastable and
// the first synchroniser stage resolves to the old or the new level at random. Every value the pixel
// domain takes from the core at its line end must then have been still at least two core clocks
// (less that aperture) before and after it (crossing (2) in video_out.v): the bench checks that at
// every core-domain line end.
#include <gtest/gtest.h>

#include <cstdint>
#include <deque>
#include <random>
#include <vector>

#include GPUBRIDGE_VIDEO_HEADER
#if GPUBRIDGE_VIDEO_PCLK
#include GPUBRIDGE_VIDEO_ROOT_HEADER
#endif

namespace {

constexpr int kHTotal = 800, kVTotal = 525, kHActive = 640, kVActive = 480;
constexpr int kPixDiv = GPUBRIDGE_VIDEO_PIX_DIV;
constexpr int kScale = 1 << GPUBRIDGE_VIDEO_SCALE_LOG2;
constexpr int kBits = GPUBRIDGE_VIDEO_BITS;
constexpr bool kCentre = GPUBRIDGE_VIDEO_CENTRE != 0;  // else a smaller picture is at the top left
constexpr int kVaw = GPUBRIDGE_VIDEO_VAW;
constexpr long kLineWords = 1L << GPUBRIDGE_VIDEO_LINE_AW;  // words of a line buffer half
constexpr bool kPclk = GPUBRIDGE_VIDEO_PCLK != 0;           // pixels on their own clock
// PCLK = 1: periods in picoseconds (ULX3S: 625 MHz / 25 and / 12, the core a picosecond slower to drift)
constexpr long kPixPs = 40000, kCorePs = 19201, kAperturePs = 2000;

struct Sample {
  bool hs, vs, de;
  int r, g, b;
};

struct Rgb {
  int r, g, b;
};

// a framebuffer of the given format in big-endian VRAM bytes (docs/protocol.md section 6)
struct Frame {
  int format, width, height;
  std::uint32_t addr;  // byte address, 16-byte aligned
  std::vector<std::uint32_t> pixels;
  int bpp() const { return format == 0 ? 4 : format == 1 ? 2 : 1; }
  Rgb expanded(int x, int y) const {
    const std::uint32_t p = pixels[static_cast<std::size_t>(y * width + x)];
    if (format == 0) return {int(p >> 24), int(p >> 16 & 0xFF), int(p >> 8 & 0xFF)};
    if (format == 1) {
      const int r5 = int(p >> 11 & 31), g6 = int(p >> 5 & 63), b5 = int(p & 31);
      return {r5 << 3 | r5 >> 2, g6 << 2 | g6 >> 4, b5 << 3 | b5 >> 2};
    }
    return {int(p >> 6 & 3) * 0x55, int(p >> 4 & 3) * 0x55, int(p >> 2 & 3) * 0x55};
  }
};

class VideoBench {
 public:
  explicit VideoBench(std::uint32_t seed) : rng_(seed), mem_(std::size_t{1} << kVaw, 0xDEADBEEFu) {}

  // beyond_ok: the frame may run past the end of VRAM (its bytes there are not stored)
  void store(const Frame& f, bool beyond_ok = false) {
    if (!beyond_ok) {
      ASSERT_LE(f.addr + std::size_t(f.width * f.height * f.bpp()), mem_.size() * 4) << "the frame is beyond VRAM";
    }
    for (int i = 0; i < f.width * f.height; ++i)
      for (int k = 0; k < f.bpp(); ++k) {
        const std::uint32_t a = f.addr + static_cast<std::uint32_t>(i * f.bpp() + k);
        if (a / 4 >= mem_.size()) continue;
        const int shift = (f.bpp() - 1 - k) * 8;
        const std::uint32_t byte = f.pixels[static_cast<std::size_t>(i)] >> shift & 0xFF;
        std::uint32_t& w = mem_[a / 4];
        const int lane = (3 - int(a % 4)) * 8;
        w = (w & ~(0xFFu << lane)) | byte << lane;
      }
  }

  // runs `cycles` core clocks from reset with the scanout's counters; the swap of `f` is latched where
  // the scanout's vertical sync falls (end of visible line 479), as frame_start does on a board
  // frame_addr: what the scanout hands over with frame_start (default: the frame's address / 16)
  std::vector<Sample> run(const Frame& f, long pixels, std::uint32_t frame_addr = kAddrOfFrame) {
    if (kPclk) return run_two_clocks(f, pixels, frame_addr);
    const long cycles = pixels * kPixDiv;
    std::vector<Sample> out;
    const long line_clocks = long(kHTotal) * kPixDiv;
    const long vsync_cycle = (kVActive - 1) * line_clocks + line_clocks - 1;
    m_.rst = 1;
    m_.hcount = 0;
    m_.vcount = 0;
    for (int i = 0; i < 4; ++i) tick();
    m_.rst = 0;
    for (long k = 0; k < cycles; ++k) {
      m_.hcount = static_cast<std::uint16_t>(k % line_clocks);
      m_.vcount = static_cast<std::uint16_t>(k / line_clocks % kVTotal);
      m_.frame_start = k == vsync_cycle;
      const std::uint32_t latched = frame_addr == kAddrOfFrame ? f.addr / 16 : frame_addr;
      m_.frame_addr = k == vsync_cycle ? latched : 0xFFFFFFFu;  // valid with frame_start only
      m_.frame_format = static_cast<std::uint8_t>(f.format);
      m_.frame_width = static_cast<std::uint16_t>(f.width);
      m_.frame_height = static_cast<std::uint16_t>(f.height);
      const bool pix = m_.pix_en;
      tick();
      if (pix) out.push_back({m_.hsync != 0, m_.vsync != 0, m_.de != 0, m_.red, m_.green, m_.blue});
    }
    return out;
  }

  static constexpr std::uint32_t kAddrOfFrame = 0xFFFFFFFFu;  // not a 28-bit frame_addr
  long requests() const { return requests_; }
  long beyond_requests() const { return beyond_requests_; }
  // PCLK = 1: the least time from a pixel-domain line end to the core-domain line end after it (ps)
  long min_margin_ps() const { return min_margin_ps_; }
  long metastable_samples() const { return metastable_; }

 private:
  // PCLK = 1: core and pixel edges in time order (both at once where they meet), the scanout's
  // display counters in the core clock, advanced by `tick` (ld at reset and at the line's end)
  std::vector<Sample> run_two_clocks(const Frame& f, long pixels, std::uint32_t frame_addr) {
    std::vector<Sample> out;
#if GPUBRIDGE_VIDEO_PCLK
    auto& root = *m_.rootp;
    const std::uint32_t latched = frame_addr == kAddrOfFrame ? f.addr / 16 : frame_addr;
    long h = 0, v = 0, core_edges = 0;
    bool swapped = false;
    long tc = kCorePs, tp = kPixPs / 2 + dist_(rng_) * (kPixPs / 200);   // a phase of the seed's
    long last_pe = -kPixPs, last_sample_pe = -kPixPs;   // the last pixel edge, the last pixel line end
    bool toggle_before = false;                          // the pixel toggle before the last pixel edge
    m_.clk = 0;
    m_.pclk = 0;
    m_.rst = 1;
    m_.eval();
    while (long(out.size()) < pixels) {
      const long t = std::min(tc, tp);
      const bool ce = tc == t, pe = tp == t;
      bool line_end = false;
      if (ce) {
        m_.rst = core_edges < 16;   // video_out needs at least 12
        core_inputs();
        m_.eval();                  // tick, from the synchroniser's flip-flops
        const bool tk = m_.tick != 0;
        line_end = tk && h == kHTotal - 1;
        const bool vsync = line_end && v == kVActive - 1;
        m_.hcount = static_cast<std::uint16_t>(h);
        m_.vcount = static_cast<std::uint16_t>(v);
        m_.frame_start = vsync && !swapped;
        m_.frame_addr = m_.frame_start ? latched : 0xFFFFFFFu;
        m_.frame_format = static_cast<std::uint8_t>(f.format);
        m_.frame_width = static_cast<std::uint16_t>(f.width);
        m_.frame_height = static_cast<std::uint16_t>(f.height);
        m_.eval();
        memory_accepts();
        if (m_.frame_start) swapped = true;
        if (m_.rst) {
          h = v = 0;
        } else if (line_end) {
          h = 0;
          v = v == kVTotal - 1 ? 0 : v + 1;
        } else if (tk) {
          ++h;
        }
      }
      if (pe) {
        toggle_before = root.video_out__DOT__g_tick__DOT__ptoggle != 0;
        if (root.video_out__DOT__g_pclk__DOT__phc == kHTotal - 1) last_sample_pe = t;
        last_pe = t;
      }
      m_.clk = ce;
      m_.pclk = pe;
      m_.eval();
      if (ce) {
        // a core edge just after the toggle moved: the first stage resolves to either level
        auto& sync = root.video_out__DOT__g_tick__DOT__tsync;
        const bool seen = (sync & 1) != 0;
        if (t - last_pe < kAperturePs && seen != toggle_before) {
          ++metastable_;
          if (dist_(rng_) < 50) sync = static_cast<std::uint8_t>((sync & ~1u) | (toggle_before ? 1u : 0u));
        }
        // everything the pixel domain samples at its line end changes at this line end
        if (line_end) min_margin_ps_ = std::min(min_margin_ps_, t - last_sample_pe);
        ++now_;
        ++core_edges;
        tc += kCorePs;
      }
      if (pe) {
        out.push_back({m_.hsync != 0, m_.vsync != 0, m_.de != 0, m_.red, m_.green, m_.blue});
        tp += kPixPs;
      }
      m_.clk = 0;
      m_.pclk = 0;
      m_.eval();
    }
#else
    (void)f;
    (void)pixels;
    (void)frame_addr;
#endif
    return out;
  }

  // the memory's side of a core clock: it answers the oldest read whose latency has passed and
  // refuses requests at random
  void core_inputs() {
    m_.rsp_valid = 0;
    if (!inflight_.empty() && inflight_.front().due <= now_) {
      m_.rsp_valid = 1;
      m_.rsp_rdata = inflight_.front().data;
      inflight_.pop_front();
    }
    m_.req_ready = dist_(rng_) < 70;
  }

  void tick() {
    core_inputs();
    m_.clk = 0;
    m_.eval();
    memory_accepts();
    m_.clk = 1;
    m_.eval();
    ++now_;
  }

  // a request taken in this clock (inputs settled, before the edge)
  void memory_accepts() {
    if (m_.req_valid && m_.req_ready) {
      // a read at or beyond VRAM's end (2^VAW words) is answered with 0, in order, as the arbiter
      // does; the video asks for such a word only where the displayed buffer runs past VRAM
      const std::uint32_t a = m_.req_addr;
      EXPECT_LT(a, 2 * mem_.size()) << "a read address beyond VRAM other than 2^VAW + word";
      const long latency = 1 + dist_(rng_) % 4;
      const long due = std::max(now_ + latency, inflight_.empty() ? 0 : inflight_.back().due);
      inflight_.push_back({due, a < mem_.size() ? mem_[a] : 0});
      ++requests_;
      if (a >= mem_.size()) ++beyond_requests_;
    }
  }

  struct Read {
    long due;
    std::uint32_t data;
  };
  GPUBRIDGE_VIDEO_MODEL m_;
  std::mt19937 rng_;
  std::uniform_int_distribution<int> dist_{0, 99};
  std::vector<std::uint32_t> mem_;
  std::deque<Read> inflight_;
  long now_ = 0, requests_ = 0, beyond_requests_ = 0;
  long min_margin_ps_ = 1L << 40, metastable_ = 0;
};

int top_bits(int v8) { return v8 >> (8 - kBits); }

// checks two frames of samples: the first black (nothing swapped in before its vertical sync), the
// second the framebuffer, scaled and centred (or at the top left); its pixels from byte vram_bytes on (beyond VRAM) black
void check(const std::vector<Sample>& s, const Frame& f, std::size_t vram_bytes = SIZE_MAX) {
  // the pipeline's delay: the first data-enable sample is the first visible pixel
  std::size_t o = 0;
  while (o < s.size() && !s[o].de) ++o;
  ASSERT_LT(o, std::size_t{kHTotal}) << "no data enable in the first line";
  ASSERT_GE(s.size(), o + 2u * kHTotal * kVTotal);
  const int sw = std::min(kHActive, f.width * kScale), sh = std::min(kVActive, f.height * kScale);
  const int x0 = kCentre ? (kHActive - sw) / 2 : 0, y0 = kCentre ? (kVActive - sh) / 2 : 0;
  int mismatches = 0;
  for (std::size_t i = 0; i < 2u * kHTotal * kVTotal; ++i) {
    const Sample& v = s[o + i];
    const int p = int(i % kHTotal), l = int(i / kHTotal % kVTotal), frame = int(i / (kHTotal * kVTotal));
    const bool de = p < kHActive && l < kVActive;
    ASSERT_EQ(v.de, de) << "data enable at pixel " << p << " line " << l << " frame " << frame;
    ASSERT_EQ(v.hs, !(p >= 656 && p < 752)) << "hsync at pixel " << p << " line " << l;
    ASSERT_EQ(v.vs, !(l >= 490 && l < 492)) << "vsync at pixel " << p << " line " << l;
    Rgb want{0, 0, 0};
    if (frame == 1 && de && p >= x0 && p < x0 + sw && l >= y0 && l < y0 + sh) {
      const int x = (p - x0) / kScale, y = (l - y0) / kScale;
      const Rgb e = f.expanded(x, y);
      // pixels beyond VRAM and beyond the line buffer half (counted from the line's first word) are black
      const long line_first = (long(f.addr) + long(y) * f.width * f.bpp()) / 4;
      const long byte = long(f.addr) + (long(y) * f.width + x) * f.bpp();
      if (std::size_t(byte) < vram_bytes && byte / 4 - line_first < kLineWords)
        want = {top_bits(e.r), top_bits(e.g), top_bits(e.b)};
    }
    if (v.r != want.r || v.g != want.g || v.b != want.b) {
      if (++mismatches <= 5)
        ADD_FAILURE() << "pixel " << p << " line " << l << " frame " << frame << ": got " << v.r << "," << v.g << ","
                      << v.b << " want " << want.r << "," << want.g << "," << want.b;
    }
  }
  EXPECT_EQ(mismatches, 0);
}

Frame pattern(int format, int width, int height, std::uint32_t addr, std::uint32_t seed) {
  Frame f{format, width, height, addr, {}};
  std::mt19937 rng(seed);
  const std::uint32_t mask = format == 0 ? 0xFFFFFFFFu : format == 1 ? 0xFFFFu : 0xFFu;
  for (int i = 0; i < width * height; ++i) f.pixels.push_back(rng() & mask);
  return f;
}

// pixels: two frames from the first data enable, and the line before it
long two_frames_and_a_bit() { return (2L * kVTotal + 1) * kHTotal + 64; }

// PCLK = 1: the crossings' margins held in a run (see the file's head)
void check_crossings(const VideoBench& bench) {
  if (!kPclk) return;
  EXPECT_GE(bench.min_margin_ps(), 2 * kCorePs - kAperturePs)
      << "a core-domain line end came too soon after the pixel domain sampled its values";
  EXPECT_LT(bench.min_margin_ps(), 4 * kCorePs) << "the core's line end lags the pixels by more than the synchroniser";
  EXPECT_GT(bench.metastable_samples(), 100) << "the drifting phase must reach the aperture";
}

}  // namespace

// the board's own case: the largest buffer fills the screen exactly (iCEBreaker: 320 x 240 RGBA2222 shown
// 2x, two of them fit the 128 KiB; ULX3S: 640 x 480 RGB565)
TEST(VideoOut, FullScreen) {
  const Frame f = pattern(kScale == 2 ? 2 : 1, kHActive / kScale, kVActive / kScale, 0x40, 1);
  VideoBench bench(11);
  bench.store(f);
  check(bench.run(f, two_frames_and_a_bit()), f);
  check_crossings(bench);
}

// a smaller RGBA2222 buffer with an odd width, so lines start inside a word: centred (iCEBreaker: at the
// top left), black around
TEST(VideoOut, Rgba2222OddWidthPlaced) {
  const Frame f = pattern(2, 101, 37, 0x1230, 2);
  VideoBench bench(12);
  bench.store(f);
  check(bench.run(f, two_frames_and_a_bit()), f);
  check_crossings(bench);
}

// the smallest buffers: one line (on the iCEBreaker two screen lines, whose last line decision wraps
// below line 0 at the top left) and two lines
TEST(VideoOut, OneAndTwoLines) {
  const Frame a = pattern(2, 3, 1, 0x40, 7);
  VideoBench ba(17);
  ba.store(a);
  check(ba.run(a, two_frames_and_a_bit()), a);
  check_crossings(ba);
  const Frame b = pattern(1, 5, 2, 0x80, 8);
  VideoBench bb(18);
  bb.store(b);
  check(bb.run(b, two_frames_and_a_bit()), b);
  check_crossings(bb);
}

// RGB565 with an odd width (lines start on half words), and RGBA8888
TEST(VideoOut, Rgb565OddWidthAndRgba8888) {
  const Frame a = pattern(1, 77, 51, 0x800, 3);
  VideoBench ba(13);
  ba.store(a);
  check(ba.run(a, two_frames_and_a_bit()), a);
  check_crossings(ba);
  const Frame b = pattern(0, 64, 40, 0x100, 4);
  VideoBench bb(14);
  bb.store(b);
  check(bb.run(b, two_frames_and_a_bit()), b);
  check_crossings(bb);
}

// a buffer larger than the screen is cropped at the right and bottom (shown from its top-left), and
// only what is shown is read: one framebuffer line's shown words (plus the two a line's lead can add)
// once per frame, a frame and a few lines being read in this run
TEST(VideoOut, LargerThanTheScreenIsCropped) {
  const Frame f = pattern(2, kHActive / kScale + 24, kVActive / kScale + 10, 0x0, 5);
  VideoBench bench(15);
  bench.store(f);
  check(bench.run(f, two_frames_and_a_bit()), f);
  check_crossings(bench);
  EXPECT_LE(bench.requests(), long(kVActive / kScale + 3) * (kHActive / kScale / 4 + 2));
}

// FB_FORMAT's reset value, 640 x 480 RGBA8888 (1.2 MB), shown as it is: cropped to the screen, and on
// the iCEBreaker (128 KiB of VRAM) black from line 52 on, where its bytes lie beyond VRAM (docs/protocol.md
// section 6) — including lines whose offset passes 512 KiB (from line 205), which a line offset
// wrapping at 2^19 bytes showed as VRAM from its start
TEST(VideoOut, ResetSizeRgba8888BeyondVramIsBlack) {
  const Frame f = pattern(0, 640, 480, 0x0, 6);
  VideoBench bench(16);
  bench.store(f, true);
  check(bench.run(f, two_frames_and_a_bit()), f, std::size_t{4} << kVaw);
  check_crossings(bench);
  // where the buffer runs past VRAM (the iCEBreaker's 128 KiB), those words are asked of the arbiter,
  // which answers 0; the ULX3S's 32 MiB hold it all
  if (640L * 480 * 4 > (4L << kVaw))
    EXPECT_GT(bench.beyond_requests(), 0) << "lines beyond VRAM are asked of the arbiter, which answers 0";
  else
    EXPECT_EQ(bench.beyond_requests(), 0);
}

// a frame starting beyond VRAM is black whatever the low bits of the address the scanout hands over:
// the scanout sets the bits from VRAM's size up and passes the wrapped address's below them
// (docs/gateware.md fit-soc8), here a wrapped address inside VRAM holding a pattern
TEST(VideoOut, FrameBeyondVramIsBlackWhateverItsLowBits) {
  const Frame inside = pattern(2, 101, 37, 0x1230, 9);
  VideoBench bench(19);
  bench.store(inside);
  const std::uint32_t above = (0xFFFFFFFu << (kVaw - 2)) & 0xFFFFFFFu;
  const Frame f{inside.format, inside.width, inside.height, std::uint32_t{4} << kVaw, inside.pixels};
  check(bench.run(f, two_frames_and_a_bit(), above | inside.addr / 16), f, 0);
  check_crossings(bench);
}
