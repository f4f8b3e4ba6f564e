#include "gpubridge/sim/timing.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>

namespace gpubridge::sim {

namespace {

// The gateware-shaped terms of section 19: setup, row and pixel cycles by render-state class,
// rejected setups, clears by rectangle, row and pixel, MEM_DATA writes.
double structure_cycles(const DeviceStats& w, const BoardTiming& b, unsigned color_bpp) {
  double c = double(w.triangles_rejected) * b.cycles_per_rejected_triangle + double(w.clears) * b.cycles_per_clear +
             double(w.clear_rows) * b.cycles_per_clear_row + double(w.clear_pixels) * b.cycles_per_clear_pixel +
             double(w.mem_data_writes) * b.cycles_per_mem_write + double(w.texel_bytes) * b.cycles_per_texel_byte +
             double(w.pixels_depth_passed) * color_bpp * b.cycles_per_color_byte;
  for (unsigned m = 0; m < DeviceStats::kModeClasses; ++m)
    c += double(w.by_mode[m].triangles) * b.setup_cycles[m] + double(w.by_mode[m].rows) * b.row_cycles[m] +
         double(w.by_mode[m].columns) * b.column_cycles[m] + double(w.by_mode[m].pixels) * b.pixel_cycles[m];
  return c;
}

}  // namespace

std::uint64_t depth_writes(const DeviceStats& w) {
  // pixels of the classes without depth pass whatever they cover
  std::uint64_t plain = 0;
  for (unsigned m = 0; m < DeviceStats::kModeClasses; ++m)
    if (!(m & 2)) plain += w.by_mode[m].pixels;
  return w.pixels_depth_passed - std::min(w.pixels_depth_passed, plain);
}

double refresh_stretch(const BoardTiming& b) {
  if (b.refresh_interval_cycles <= 0 || b.cycles_per_refresh <= 0) return 1.0;
  // a refresh every interval of the board's time, the work in the rest: t = work + t·cost/interval
  const double share = std::min(b.cycles_per_refresh / b.refresh_interval_cycles, 0.9);
  return 1.0 / (1.0 - share);
}

SdramRows::Outcome SdramRows::access(std::uint64_t address, std::uint64_t count) {
  const std::uint64_t row = address >> g_.row_bits;
  const std::size_t bank = static_cast<std::size_t>(row & ((std::uint64_t{1} << g_.bank_bits) - 1));
  const std::uint64_t held = open_[bank];
  open_[bank] = row;
  if (count > 1) hits_ += count - 1;
  if (held == row) {
    ++hits_;
    return Outcome::Hit;
  }
  if (held == kClosed) {
    ++opens_;
    return Outcome::Open;
  }
  ++misses_;
  if (textured_) ++textured_misses_;
  return Outcome::Miss;
}

void SdramRows::touch(std::uint64_t address) {
  const std::uint64_t row = address >> g_.row_bits;
  open_[static_cast<std::size_t>(row & ((std::uint64_t{1} << g_.bank_bits) - 1))] = row;
}

void SdramRows::touch_range(std::uint64_t address, std::uint64_t bytes) {
  const std::uint64_t end = address + bytes;
  for (std::uint64_t a = address; a < end; a = ((a >> g_.row_bits) + 1) << g_.row_bits) touch(a);
}

void SdramRows::refresh() { std::fill(open_.begin(), open_.end(), kClosed); }

void access_span(SdramRows& rows, const SpanAccess& span) {
  const SdramGeometry& g = rows.geometry();
  const std::uint64_t zn = (span.z_read ? 1u : 0u) + (span.z_write ? 1u : 0u);  // per pixel
  const std::uint64_t cn = (span.color_read ? 1u : 0u) + (span.color_write ? 1u : 0u);  // per word
  const std::uint64_t n = span.pixels, bpp = span.bpp;
  if (n == 0 || bpp == 0 || (zn == 0 && cn == 0)) return;
  const std::uint64_t row_bytes = std::uint64_t{1} << g.row_bits;
  const std::uint64_t bank_mask = (std::uint64_t{1} << g.bank_bits) - 1;
  auto word = [&](std::uint64_t i) { return (span.color + bpp * i) >> 2; };
  // the last pixel of the span in colour word w: the combiner sends the word after it
  auto last_pixel = [&](std::uint64_t w) { return std::min(n, ((w + 1) * 4 - span.color + bpp - 1) / bpp) - 1; };
  RowRunEmitter out(rows);
  std::uint64_t a = 0;  // first pixel of the segment
  while (a < n) {
    // a segment [a, b): both streams stay in one row each
    const std::uint64_t za = span.depth + 4 * a, ca = span.color + bpp * a;
    std::uint64_t b = n;
    if (zn != 0) b = std::min(b, a + ((za | (row_bytes - 1)) + 1 - za + 3) / 4);
    if (cn != 0) b = std::min(b, a + ((ca | (row_bytes - 1)) + 1 - ca + bpp - 1) / bpp);
    // the colour words sent in the segment: those whose last pixel lies in it
    const std::uint64_t w0 = word(a);
    const std::uint64_t w1 = last_pixel(word(b - 1)) == b - 1 ? word(b - 1) + 1 : word(b - 1);
    const std::uint64_t zrow = za >> g.row_bits, crow = ca >> g.row_bits;
    const bool conflict = zn != 0 && cn != 0 && zrow != crow && (zrow & bank_mask) == (crow & bank_mask);
    if (!conflict) {
      // different banks, one row or one stream: each bank keeps its row through the segment
      out.emit(za, zn * (b - a));
      if (w1 > w0) out.emit(w0 * 4, cn * (w1 - w0));
    } else {
      // one bank, two rows: the depth accesses up to a colour word's last pixel, then the word
      std::uint64_t p = a;
      for (std::uint64_t w = w0; w < w1; ++w) {
        const std::uint64_t end = last_pixel(w) + 1;
        out.emit(span.depth + 4 * p, zn * (end - p));
        out.emit(w * 4, cn);
        p = end;
      }
      out.emit(span.depth + 4 * p, zn * (b - p));
    }
    a = b;
  }
}

const char* mode_class_name(unsigned index) {
  static constexpr const char* kNames[DeviceStats::kModeClasses] = {"flat", "gouraud",     "z",     "gouraud_z",
                                                                    "tex",  "tex_gouraud", "tex_z", "tex_gouraud_z"};
  return index < DeviceStats::kModeClasses ? kNames[index] : "?";
}

TimingEstimate estimate_timing(const DeviceStats& w, const BoardTiming& b, unsigned color_bpp, bool depth_buffer) {
  TimingEstimate e;
  e.pipeline_cycles = double(w.queued_executed) * b.cycles_per_command +
                      double(w.triangles_rasterised) * b.cycles_per_triangle +
                      double(w.pixels_scanned) * b.cycles_per_scanned_pixel +
                      double(w.pixels_depth_passed) * b.cycles_per_pixel +
                      double(w.pixels_textured) * b.cycles_per_textured_pixel +
                      double(w.pixels_blended) * b.cycles_per_blended_pixel +
                      double(w.clear_bytes) / b.clear_bytes_per_cycle + structure_cycles(w, b, color_bpp) +
                      double(w.texel_footprint_bytes) * b.cycles_per_texel_footprint_byte +
                      double(w.texel_fetches) * b.cycles_per_texel_fetch +
                      double(w.sdram_accesses) * b.cycles_per_sdram_access + double(w.row_opens) * b.cycles_per_row_open +
                      double(w.row_misses - std::min(w.row_misses, w.textured_row_misses)) * b.cycles_per_row_miss +
                      double(w.textured_row_misses) * b.cycles_per_textured_row_miss +
                      double(depth_writes(w)) * b.cycles_per_depth_write -
                      double(w.depth_tail_pixels) * b.drained_cycles_per_tail_pixel;
  e.pipeline_cycles = std::max(e.pipeline_cycles, 0.0);  // a credit never makes time
  e.pipeline_cycles *= refresh_stretch(b);
  // Memory: depth read + write (4 + 4) for every covered pixel (an upper bound: not every draw
  // tests or writes Z), colour write, destination read when blending, texels fetched, clears,
  // uploads (8 bytes per MEM_DATA). No depth buffer, no depth traffic.
  e.memory_bytes = (depth_buffer ? w.pixels_covered * 8 : 0) + w.pixels_depth_passed * color_bpp + w.pixels_blended * color_bpp +
                   w.texel_bytes + w.clear_bytes + w.mem_data_writes * 8;
  e.memory_cycles = double(e.memory_bytes) / b.memory_bytes_per_cycle;
  e.board_cycles = b.memory_bound ? std::max(e.pipeline_cycles, e.memory_cycles) : e.pipeline_cycles;
  e.board_ms = e.board_cycles / (b.clock_mhz * 1e3);
  e.spi_ms = spi_link_ms(double(w.frames_received), b);
  e.frame_ms = std::max(e.board_ms, e.spi_ms);
  e.fps = e.frame_ms > 0 ? 1000.0 / e.frame_ms : 0;
  return e;
}

double spi_link_ms(double frames, const BoardTiming& b) {
  const double bursts = std::ceil(frames / std::max(1u, b.frames_per_burst));
  return frames * 72.0 / (b.spi_clock_mhz * 1e3) + bursts * b.cs_gap_us / 1e3;
}

DeviceStats stats_difference(const DeviceStats& a, const DeviceStats& b) {
  DeviceStats d;
  d.frames_received = a.frames_received - b.frames_received;
  d.frames_aborted = a.frames_aborted - b.frames_aborted;
  d.queued_executed = a.queued_executed - b.queued_executed;
  d.triangles_kicked = a.triangles_kicked - b.triangles_kicked;
  d.triangles_rasterised = a.triangles_rasterised - b.triangles_rasterised;
  d.pixels_scanned = a.pixels_scanned - b.pixels_scanned;
  d.pixels_covered = a.pixels_covered - b.pixels_covered;
  d.pixels_depth_passed = a.pixels_depth_passed - b.pixels_depth_passed;
  d.pixels_textured = a.pixels_textured - b.pixels_textured;
  d.pixels_blended = a.pixels_blended - b.pixels_blended;
  d.texel_bytes = a.texel_bytes - b.texel_bytes;
  d.clear_bytes = a.clear_bytes - b.clear_bytes;
  d.mem_data_writes = a.mem_data_writes - b.mem_data_writes;
  d.swaps = a.swaps - b.swaps;
  for (unsigned m = 0; m < DeviceStats::kModeClasses; ++m) {
    d.by_mode[m].triangles = a.by_mode[m].triangles - b.by_mode[m].triangles;
    d.by_mode[m].rows = a.by_mode[m].rows - b.by_mode[m].rows;
    d.by_mode[m].columns = a.by_mode[m].columns - b.by_mode[m].columns;
    d.by_mode[m].pixels = a.by_mode[m].pixels - b.by_mode[m].pixels;
  }
  d.triangles_rejected = a.triangles_rejected - b.triangles_rejected;
  d.clears = a.clears - b.clears;
  d.clear_rows = a.clear_rows - b.clear_rows;
  d.clear_pixels = a.clear_pixels - b.clear_pixels;
  d.texel_footprint_bytes = a.texel_footprint_bytes - b.texel_footprint_bytes;
  d.texel_fetches = a.texel_fetches - b.texel_fetches;
  d.sdram_accesses = a.sdram_accesses - b.sdram_accesses;
  d.row_opens = a.row_opens - b.row_opens;
  d.row_misses = a.row_misses - b.row_misses;
  d.textured_row_misses = a.textured_row_misses - b.textured_row_misses;
  d.depth_tail_pixels = a.depth_tail_pixels - b.depth_tail_pixels;
  return d;
}

Result<BoardTiming> timing_preset(std::string_view name) {
  BoardTiming b;
  if (name == "ecp5-50mhz") return b;
  if (name == "up5k" || name == "ecp5") {
    // The gateware profiles (gateware/rtl/spigpu_top.v) at their co-simulated clocks; every cycle
    // term from `gpubridge bench rtl --fit` (docs/gateware.md "Timing model", 2026-11-26): the
    // staged least-squares fit on the RTL's setup, rasteriser and remaining clocks of every example,
    // scene and calibration frame. Classes: flat, gouraud, z, gouraud_z, tex, tex_gouraud, tex_z,
    // tex_gouraud_z. The terms hold the memory's time: no byte bound.
    b.name = std::string(name);
    b.cycles_per_scanned_pixel = b.cycles_per_pixel = b.cycles_per_textured_pixel = 0;
    b.memory_bound = false;
  }
  if (name == "up5k") {
    // iCEBreaker: 25.125 MHz core (its PLL), 128 KiB SPRAM (one 32-bit access per clock), SPI 7.5 MHz,
    // no BUSY pin. The setup is a bit-serial program (gen_setup_prog.py: 227 cycles flat .. 883 Gouraud, 1,126 Gouraud + Z on
    // the core bench); the one time-shared stepper costs a cycle per interpolated attribute per
    // rasteriser move (rows, boundary columns and pixels); clears are drawn as rectangles.
    b.clock_mhz = 25.125;
    b.spi_clock_mhz = 7.5;
    b.memory_bytes_per_cycle = 4.0;
    // Flat and Gouraud refitted after the fifth-session gateware rounds (fit-core4's 45-bit colour
    // divisions, protocol 1.4 without a depth buffer, the 46-bit setup of DEPTH = 0): `gpubridge bench
    // rtl --fit --profile up5k`, worst error 0.6 % on the scenes, 0.4 % on the calibration frames.
    // The z classes keep the earlier fit of the core with its depth stage (the core bench still
    // builds it); the up5k profile refuses Z, so they are unused.
    b.setup_cycles = {228.1, 884.6, 510.1, 1292.0, 0.0, 0.0, 0.0, 0.0};  // no texture unit
    b.row_cycles = {2.029, 2.752, 0.7314, 3.853, 0.0, 0.0, 0.0, 0.0};
    b.column_cycles = {0.6607, 2.528, 1.257, 3.189, 0.0, 0.0, 0.0, 0.0};
    b.pixel_cycles = {1.013, 4.001, 4.077, 5.271, 0.0, 0.0, 0.0, 0.0};
    b.cycles_per_command = 0.6937;
    b.cycles_per_triangle = 4.126;
    b.cycles_per_blended_pixel = 0.0;  // no blending
    b.cycles_per_rejected_triangle = 88.59;
    b.cycles_per_clear = 888.1;
    b.cycles_per_clear_row = 0.0;
    b.cycles_per_clear_pixel = 1.001;  // colour clears only (1.4 with CLEAR_Z's 4-byte writes)
    b.cycles_per_mem_write = 4.8;
    b.cycles_per_color_byte = 0.001284;
    b.clear_bytes_per_cycle = 1e9;  // a clear costs by pixel (one SPRAM write each), not by byte
    return b;
  }
  if (name == "ecp5") {
    // ULX3S: 50 MHz core, 16-bit SDR SDRAM (a 32-bit word per 2 clocks at best), SPI 15 MHz. Parallel
    // setup (38 cycles flat .. 336 textured Gouraud + Z on the core bench), one pixel a clock on
    // spans, memory stalls per depth read, colour byte, texel fetch and SDRAM row miss, clears a word
    // per 2 clocks beside the rasteriser.
    b.clock_mhz = 50.0;
    b.spi_clock_mhz = 15.0;
    b.memory_bytes_per_cycle = 2.0;
    // Fitted with the SDRAM row model, the texel cache's reads in it, the textured draws' row
    // misses apart, the depth writes and the depth stage's tail (`gpubridge bench rtl --fit
    // --profile ecp5`, 2026-11-27 on the gateware of the ninth session: reads first with write
    // runs in the memory port, the texture unit sharing a texel read the pixel ahead waits for;
    // 14 scenes and 48 calibration frames; docs/gateware.md "Timing model"): a depth write costs
    // 6.674 clocks beyond its pixel, a row miss 2.394 in an untextured draw and 1.199 in a textured
    // one (the texture unit's wait hides part of it), a texel read 1.176, a byte of texture
    // footprint 0.3025, a byte sampled 0.001906; each of a depth triangle's last 4 pixels gives
    // back 12.87 (drained under the next setup); a row open and an access nothing beyond the
    // per-pixel terms.
    b.setup_cycles = {42.75, 170.5, 98.04, 200.8, 164.2, 275.4, 202.5, 310.0};
    b.row_cycles = {1.322, 0.5602, 0.9725, 0.3464, 0.7485, 0.6328, 3.598, 3.297};
    b.column_cycles = {0.4277, 0.0, 0.0, 0.0, 0.0, 0.0, 0.6138, 0.7006};
    b.pixel_cycles = {0.4376, 0.6412, 0.3418, 0.3117, 1.282, 1.123, 0.0, 0.04504};
    b.cycles_per_command = 3.039;
    b.cycles_per_triangle = 0.0;
    b.cycles_per_blended_pixel = 2.527;
    b.cycles_per_rejected_triangle = 0.0;
    b.cycles_per_clear = 7.204;
    b.cycles_per_clear_row = 0.0;
    b.cycles_per_clear_pixel = 0.0;
    b.cycles_per_mem_write = 11.31;
    b.cycles_per_texel_byte = 0.001906;
    b.cycles_per_color_byte = 0.329;
    b.cycles_per_texel_footprint_byte = 0.3025;
    b.cycles_per_texel_fetch = 1.176;
    b.cycles_per_sdram_access = 0.0;
    b.cycles_per_row_open = 0.0;
    b.cycles_per_row_miss = 2.394;
    b.cycles_per_textured_row_miss = 1.199;
    b.cycles_per_depth_write = 6.674;
    b.drained_cycles_per_tail_pixel = 12.87;
    b.clear_bytes_per_cycle = 2.007;
    // The SDRAM (sdram_ctrl.v with the Alliance AS4C32M16SB-7's timing): an auto refresh every
    // tREFI = 7.8 us costs precharge all (tRP 21 ns), tRFC (63 ns) and the first row opened again
    // (tRCD 21 ns), in whole clocks; the fit keeps these and fits the rest.
    const auto clocks = [&](double ns) { return std::ceil(ns * b.clock_mhz / 1000.0); };
    b.refresh_interval_cycles = clocks(7800);
    b.cycles_per_refresh = clocks(21) + clocks(63) + clocks(21);
    return b;
  }
  return make_error("unknown timing profile '" + std::string(name) + "' (ecp5-50mhz, up5k, ecp5)");
}

Result<void> apply_timing_setting(BoardTiming& b, std::string_view setting) {
  struct Key {
    std::string_view name;
    double BoardTiming::*field;
  };
  static constexpr Key kKeys[] = {
      {"clock_mhz", &BoardTiming::clock_mhz},
      {"cycles_per_command", &BoardTiming::cycles_per_command},
      {"cycles_per_triangle", &BoardTiming::cycles_per_triangle},
      {"cycles_per_scanned_pixel", &BoardTiming::cycles_per_scanned_pixel},
      {"cycles_per_pixel", &BoardTiming::cycles_per_pixel},
      {"cycles_per_textured_pixel", &BoardTiming::cycles_per_textured_pixel},
      {"cycles_per_blended_pixel", &BoardTiming::cycles_per_blended_pixel},
      {"clear_bytes_per_cycle", &BoardTiming::clear_bytes_per_cycle},
      {"memory_bytes_per_cycle", &BoardTiming::memory_bytes_per_cycle},
      {"spi_clock_mhz", &BoardTiming::spi_clock_mhz},
      {"cs_gap_us", &BoardTiming::cs_gap_us},
      {"cycles_per_rejected_triangle", &BoardTiming::cycles_per_rejected_triangle},
      {"cycles_per_clear", &BoardTiming::cycles_per_clear},
      {"cycles_per_clear_row", &BoardTiming::cycles_per_clear_row},
      {"cycles_per_clear_pixel", &BoardTiming::cycles_per_clear_pixel},
      {"cycles_per_mem_write", &BoardTiming::cycles_per_mem_write},
      {"cycles_per_texel_byte", &BoardTiming::cycles_per_texel_byte},
      {"cycles_per_color_byte", &BoardTiming::cycles_per_color_byte},
      {"cycles_per_sdram_access", &BoardTiming::cycles_per_sdram_access},
      {"cycles_per_texel_footprint_byte", &BoardTiming::cycles_per_texel_footprint_byte},
      {"cycles_per_texel_fetch", &BoardTiming::cycles_per_texel_fetch},
      {"cycles_per_row_open", &BoardTiming::cycles_per_row_open},
      {"cycles_per_row_miss", &BoardTiming::cycles_per_row_miss},
      {"cycles_per_textured_row_miss", &BoardTiming::cycles_per_textured_row_miss},
      {"cycles_per_depth_write", &BoardTiming::cycles_per_depth_write},
      {"drained_cycles_per_tail_pixel", &BoardTiming::drained_cycles_per_tail_pixel},
      {"refresh_interval_cycles", &BoardTiming::refresh_interval_cycles},
      {"cycles_per_refresh", &BoardTiming::cycles_per_refresh},
  };
  const auto eq = setting.find('=');
  if (eq == std::string_view::npos) return make_error("timing setting '" + std::string(setting) + "' is not KEY=VALUE");
  const std::string_view name = setting.substr(0, eq);
  if (name == "profile") {
    auto p = timing_preset(setting.substr(eq + 1));
    if (!p) return p.error();
    b = *p;
    return {};
  }
  const std::string text(setting.substr(eq + 1));
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  const bool ok = !text.empty() && end == text.c_str() + text.size() && std::isfinite(v) && v >= 0 && v <= 1e9;
  if (name == "memory_bound") {
    if (text != "0" && text != "1") return make_error("timing memory_bound=" + text + ": expected 0 or 1");
    b.memory_bound = text == "1";
    return {};
  }
  if (name == "frames_per_burst") {
    if (!ok || v < 1 || v != std::floor(v)) return make_error("timing frames_per_burst=" + text + ": expected an integer >= 1");
    b.frames_per_burst = static_cast<unsigned>(v);
    return {};
  }
  // per-class keys: setup_cycles_CLASS, row_cycles_CLASS, pixel_cycles_CLASS
  struct ClassKey {
    std::string_view prefix;
    std::array<double, DeviceStats::kModeClasses> BoardTiming::*field;
  };
  static constexpr ClassKey kClassKeys[] = {
      {"setup_cycles_", &BoardTiming::setup_cycles},
      {"row_cycles_", &BoardTiming::row_cycles},
      {"column_cycles_", &BoardTiming::column_cycles},
      {"pixel_cycles_", &BoardTiming::pixel_cycles},
  };
  for (const auto& k : kClassKeys) {
    if (name.substr(0, k.prefix.size()) != k.prefix) continue;
    for (unsigned m = 0; m < DeviceStats::kModeClasses; ++m) {
      if (name.substr(k.prefix.size()) != mode_class_name(m)) continue;
      if (!ok) return make_error("timing " + std::string(name) + "=" + text + ": expected a finite number >= 0");
      (b.*k.field)[m] = v;
      return {};
    }
  }
  for (const auto& k : kKeys) {
    if (k.name != name) continue;
    const bool positive_needed = name != "cs_gap_us" && name.substr(0, 7) != "cycles_" && name != "refresh_interval_cycles";
    if (!ok || (positive_needed && v <= 0))
      return make_error("timing " + std::string(name) + "=" + text + ": expected a finite number" +
                        (positive_needed ? " > 0" : " >= 0"));
    b.*k.field = v;
    return {};
  }
  return make_error("unknown timing key '" + std::string(name) + "'");
}

}  // namespace gpubridge::sim
