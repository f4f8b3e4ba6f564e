#include "reference_model.hpp"

#include <deque>
#include <optional>

namespace gpubridge::dmc1::test {
namespace {

using i64 = std::int64_t;
std::int32_t sx(std::uint64_t v, int bits) {
  const std::uint64_t m = 1ull << (bits - 1);
  v &= (1ull << bits) - 1;
  return static_cast<std::int32_t>(static_cast<i64>(v ^ m) - static_cast<i64>(m));
}
std::int32_t w24(i64 v) { return sx(static_cast<std::uint64_t>(v), 24); }
std::int32_t w32(i64 v) { return static_cast<std::int32_t>(static_cast<std::uint32_t>(v)); }
std::uint32_t inv_y(std::uint32_t n) {
  n &= 2047;
  return n < 2 ? 65535u : 65536u / n;
}

}  // namespace

ReferenceModel::ReferenceModel(std::shared_ptr<const TextureMemory> textures, const Palette& palette)
    : mem_(std::move(textures)), palette_(palette) {}

void ReferenceModel::run(std::span<const std::uint64_t> words) {
  for (const std::uint64_t w : words) command(w);
}

std::uint8_t ReferenceModel::read_texel(std::uint32_t u, std::uint32_t v) const {
  u &= (1u << binding_.wp2) - 1;
  v &= (1u << binding_.hp2) - 1;
  return mem_->read(binding_.base + (u | (v << binding_.wp2)));
}

void ReferenceModel::end_of_column() {
  for (unsigned r = 0; r < 240; ++r) {  // the column sender: palette, then light per channel
    const std::uint16_t e = colbuf_[buffer_][r];
    const std::uint32_t light = e >> 8, p = palette_.entry(e & 255);
    const std::uint32_t r6 = ((p >> 12 & 63) * light) >> 8, g6 = ((p >> 6 & 63) * light) >> 8, b6 = ((p & 63) * light) >> 8;
    out_.push_back(static_cast<std::uint16_t>((r6 >> 1) << 11 | g6 << 5 | (b6 >> 1)));
  }
  buffer_ ^= 1;
}

void ReferenceModel::command(std::uint64_t c) {
  const auto t1 = static_cast<std::uint32_t>(c), t0 = static_cast<std::uint32_t>(c >> 32);
  const unsigned tag = t1 >> 30;
  if (tag == 3) {
    if (t1 & 1) return end_of_column();
    switch (t0 >> 30) {
      case 0: cos_ = sx(t0, 13); sin_ = sx(t0 >> 14, 13); break;
      case 1: v_off_ = sx(t0, 24); u_off_ = sx(t1 >> 1, 24); lightmap_ = (t1 >> 25) & 1; break;
      case 2:
        ny_ = sx(t0, 10); uy_ = sx(t0 >> 10, 10); vy_ = sx(t0 >> 20, 10);
        dot_u_ = w24(i64{sx(t1 >> 1, 14)} * 256); dot_v_ = w24(i64{sx(t1 >> 15, 14)} * 256);
        break;
      default: view_z_ = sx(t0, 16); break;
    }
    return;
  }
  const unsigned start = (t1 >> 10) & 255, raw_end = (t1 >> 18) & 255;
  if (start > raw_end) return;
  span(t0, t1, tag, start, raw_end > 239 ? 239 : raw_end);
}

// One span, event by event, as the span drawer's always block runs it.
void ReferenceModel::span(std::uint32_t t0, std::uint32_t t1, unsigned tag, unsigned start, unsigned col_end) {
  const bool wall = tag == 0, plane = tag == 1, terrain = tag == 2;
  const unsigned tid = t1 & 1023, light = (t1 >> 26) & 15;
  if (tid != sampler_id_ && tid != 0) binding_ = mem_->binding(tid);
  sampler_id_ = tid;
  const bool bkg = tid == 0;
  unsigned current = start, end = terrain ? start : col_end;
  unsigned skip = 3;
  bool tcol_rdy = false, pick_done = false;
  const std::int32_t d19 = w24(sx(std::uint64_t{(t0 >> 16) & 2047} << 8, 19));
  std::int32_t tc_v = d19, tcol = d19, prev = d19;
  const std::uint32_t wc_u = t0 >> 24, wc_inc = t0 & 0x3FFF;
  std::int32_t wc_v = w24(sx(std::uint64_t{(t0 >> 16) & 255} << 11, 19));
  if (plane) {
    ded_ = sx(t0, 16);
    dot_ray_ = w24(i64{sx(t0 >> 16, 16)} * 256);
  }
  const std::uint32_t wall_dist = static_cast<std::uint32_t>(sx(t0, 16)) & 0x7FFFFFFF;
  const unsigned end_distance = t0 & 2047;
  // Register history: index i holds the value after event i - 1 (index 0: at the span start).
  std::vector<std::int32_t> hr{dot_ray_}, hu{dot_u_}, hv{dot_v_};
  auto ray_t = [&](std::int32_t dr) {
    const std::uint32_t mag = dr < 0 ? static_cast<std::uint32_t>(-i64{dr}) & 0xFFFFFF : static_cast<std::uint32_t>(dr);
    const std::int32_t a = static_cast<std::int16_t>(inv_y((mag >> 8) & 2047));
    return w32(w32(i64{a} * ded_) >> 6);
  };
  // Fetches in flight: the one issued after event k is seen at event k + 2.
  std::deque<std::optional<std::uint8_t>> in_flight;
  std::uint8_t data = 0;
  auto issue = [&](int k) {
    std::optional<std::uint8_t> f;
    if (!bkg && (current < end || terrain || (skip & 1))) {
      if (wall) {
        f = read_texel(wc_u, static_cast<std::uint32_t>(wc_v >> 11) & 255);
      } else if (plane) {  // coordinates use dot_u/dot_v one event behind, dot_ray two
        const int iu = k < 0 ? 0 : k;
        const int ir = iu - 1 < 0 ? 0 : iu - 1;
        const std::int32_t t = ray_t(hr[static_cast<std::size_t>(ir)]);
        const std::int32_t uu = w24(i64{w32(i64{t} * hu[static_cast<std::size_t>(iu)]) >> 10} + u_off_);
        const std::int32_t vv = w24(i64{w32(i64{t} * hv[static_cast<std::size_t>(iu)]) >> 10} + v_off_);
        const unsigned sh = lightmap_ ? 14 : 10;
        f = read_texel(static_cast<std::uint32_t>(uu >> sh) & 255, static_cast<std::uint32_t>(vv >> sh) & 255);
      } else {
        const std::uint32_t td = ((tcol_rdy ? static_cast<std::uint32_t>(tcol) : static_cast<std::uint32_t>(tc_v)) >> 8) & 2047;
        const std::int32_t tru = w24(i64{w32(i64{td} * cos_) >> 2} + u_off_);
        const std::int32_t trv = w24(i64{w32(i64{td} * sin_) >> 2} + v_off_);
        f = read_texel((static_cast<std::uint32_t>(tru) >> 12) & 1023,
                       ((static_cast<std::uint32_t>(trv) >> 12) & 1023) | ((current < end ? 1u : 0u) << 10));
      }
    }
    in_flight.push_back(f);
  };
  issue(-1);
  for (int k = 0;; ++k) {
    if (in_flight.size() >= 2) {
      if (in_flight.front()) data = *in_flight.front();
      in_flight.pop_front();
    }
    const std::uint8_t texel = bkg ? 99 : data;
    std::uint32_t dist;
    if (terrain) {
      dist = (static_cast<std::uint32_t>(tcol) >> 5) & 0x7FFFF;
    } else if (plane) {  // ray_t holds the value computed after the previous event
      const int ir = k - 1 < 0 ? 0 : k - 1;
      dist = (static_cast<std::uint32_t>(ray_t(hr[static_cast<std::size_t>(ir)])) << 1) & 0x7FFFFFFF;
    } else {
      dist = wall_dist;
    }
    const bool current_done = current >= end;
    const std::uint32_t tbits = static_cast<std::uint32_t>(tcol) & 0xFFFFFF;
    const bool drawing = terrain ? !(((tbits >> 8) & 2047) > end_distance || ((tbits >> 19) & 1)) : (!current_done || (skip & 1));
    if (!tcol_rdy && !(skip & 1) && (texel != 255 || lightmap_) && current < 240) {
      const std::uint32_t stored = depth_[current];
      if ((stored >> 31) != buffer_ || dist <= (stored & 0x7FFFFFFF)) {
        std::uint32_t obscure = dist >= 65536 ? 15 : (dist >> 12) & 15;
        if (obscure > 10) obscure = 10;
        const int l4 = bkg ? 15 : (static_cast<int>(light) - static_cast<int>(obscure) < 0 ? 0 : static_cast<int>(light - obscure));
        std::uint16_t& e = colbuf_[buffer_][current];
        e = lightmap_ ? static_cast<std::uint16_t>((e & 0xFF) | texel << 8) : static_cast<std::uint16_t>(l4 << 12 | texel);
        depth_[current] = buffer_ << 31 | dist;
      }
    }
    if (tcol_rdy) {
      const std::int32_t res = w32(i64{inv_y((tbits >> 8) & 2047)} * (i64{texel} - view_z_));
      const std::int32_t scrh = sx(static_cast<std::uint64_t>((res >> 8) + 120), 16);
      const unsigned next_end = scrh < 0 ? 0 : (scrh < static_cast<std::int32_t>(col_end) ? static_cast<unsigned>(scrh) : col_end);
      scrh_diff_ = static_cast<std::uint8_t>(next_end - current);
      tcol_rdy = false;
      tc_v = prev;
      end = next_end;
      if ((t0 >> 31) && !pick_done) picked_height_ = texel;
      pick_done = true;
    } else {
      const bool next_rdy = terrain && current_done;
      const std::uint32_t shift = (tbits >> 17) & 3;
      const std::uint32_t inc =
          (((((tbits >> 8) & 2047) - ((static_cast<std::uint32_t>(prev) >> 8) & 2047)) & 2047) * inv_y(scrh_diff_) & 0xFFFFFF) >> 8;
      if (next_rdy) {
        prev = tcol;
        tcol = w24(i64{tcol} + (2048 << shift));
      }
      tcol_rdy = next_rdy;
      if (!(current_done || (skip & 1))) current = (current + 1) & 255;
      if (!(skip & 1)) tc_v = w24(i64{tc_v} + (inc & 0x3FFF));
      if (!(skip & 2)) wc_v = w24(i64{wc_v} + wc_inc);
      dot_ray_ = w24(i64{dot_ray_} + ny_);
      dot_u_ = w24(i64{dot_u_} + uy_);
      dot_v_ = w24(i64{dot_v_} + vy_);
      skip = (skip & 2) ? (skip >> 1) : (terrain && current_done ? 1 : 0);
    }
    hr.push_back(dot_ray_);
    hu.push_back(dot_u_);
    hv.push_back(dot_v_);
    if (!drawing) break;
    issue(k);
  }
}

}  // namespace gpubridge::dmc1::test
