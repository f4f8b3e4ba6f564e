// Hard case 25 (issue 15): vertices exactly on a snapping tie with w ≠ 1, through the two host
// paths users draw screen-space triangles with: scene files (scene::build_commands) and
// draw::Context::draw_screen. docs/protocol.md 16.2: a vertex given in screen space is snapped with
// floor(16·x + 0.5) from the x given, whatever its w (the window-homogeneous form x·w is only for
// clipping; x·w / w is not always x, and on a tie one ulp is 1/16 px).
//
// The expected device triangles are formed here from the documented rules in integer arithmetic
// (every x is an odd multiple of 1/32, so X = (32x + 1) / 2); the simulator draws what the host path
// sent, and every pixel is compared with the double reference rasterising the expected triangles:
// coverage (hit counts), owner (which triangle wrote the pixel) and attributes (Z and colour within
// 0.5 LSB). A property test checks the snapped X and Y of random (x, w) pairs against the rule's
// definition.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <sstream>
#include <variant>

#include "gpubridge/draw/context.hpp"
#include "gpubridge/scene/scene.hpp"
#include "sim_harness.hpp"

namespace gpubridge::accuracy {
namespace {

using geometry::DeviceTriangle;
using geometry::DeviceVertex;
using geometry::ScreenVertex;
constexpr double kHalfLsb = 0.5 + 1e-6;

// The register values of every triangle in a command stream: per vertex COLOR (Q, RGBA), optional
// TEXCOORD, then VERTEX (X, Y, Z), three vertices per LIST triangle.
std::vector<DeviceTriangle> sent_triangles(const protocol::CommandStream& stream) {
  std::vector<DeviceTriangle> tris;
  DeviceTriangle t{};
  DeviceVertex v{};
  int n = 0;
  for (const auto& c : stream.commands) {
    const auto* f = std::get_if<protocol::FramesCmd>(&c.command);
    if (!f) continue;
    for (std::size_t i = 0; i < f->size(); ++i) {
      const protocol::Frame fr = f->view()[i];
      switch (static_cast<protocol::Reg>(fr.index)) {
        case protocol::Reg::PRIM: n = 0; break;
        case protocol::Reg::COLOR:
          v.rgba = static_cast<std::uint32_t>(fr.data);
          v.q = static_cast<std::uint32_t>(fr.data >> 32);
          break;
        case protocol::Reg::VERTEX:
          v.x = static_cast<std::int16_t>(fr.data & 0xFFFF);
          v.y = static_cast<std::int16_t>((fr.data >> 16) & 0xFFFF);
          v.z = static_cast<std::uint32_t>((fr.data >> 32) & 0xFFFFFF);
          t[n++] = v;
          if (n == 3) {
            tris.push_back(t);
            n = 0;
          }
          break;
        default: break;
      }
    }
  }
  return tris;
}

// What the scene loader sends for one untextured draw of these vertices.
std::vector<DeviceTriangle> through_scene(const std::vector<ScreenVertex>& vertices, unsigned size) {
  scene::Scene s;
  s.width = s.height = size;
  scene::Draw d;
  d.vertices = vertices;
  s.draws.push_back(d);
  auto built = scene::build_commands(s);
  EXPECT_TRUE(built) << built.error().message;
  return built ? sent_triangles(built->stream) : std::vector<DeviceTriangle>{};
}

// What draw::Context::draw_screen sends for the same vertices.
std::vector<DeviceTriangle> through_draw_screen(const std::vector<ScreenVertex>& vertices, unsigned size) {
  draw::RecordingSink sink;
  // Every triangle sent, also those beside the framebuffer: this compares snapping, not visibility.
  auto ctx = draw::Context::create(sink, {.width = size, .height = size, .depth_buffer = false, .skip_invisible = false});
  EXPECT_TRUE(ctx) << ctx.error().message;
  if (!ctx) return {};
  auto r = ctx->draw_screen(vertices);
  EXPECT_TRUE(r) << r.error().message;
  EXPECT_TRUE(ctx->flush());
  return sent_triangles(sink.stream());
}

// A vertex on a tie: x = x32 / 32 with x32 odd, so 16·x = k + 1/2 and the rule gives X = (x32 + 1) / 2.
struct TieVertex {
  int x32 = 1, y32 = 1;
  double z = 0, w = 1;
  std::uint32_t rgba = 0xFFFFFFFFu;
};

ScreenVertex screen(const TieVertex& t) {
  ScreenVertex s;
  s.x = t.x32 / 32.0;
  s.y = t.y32 / 32.0;
  s.z = t.z;
  s.w = t.w;
  s.color = {(t.rgba >> 24) / 255.0, ((t.rgba >> 16) & 0xFF) / 255.0, ((t.rgba >> 8) & 0xFF) / 255.0,
             (t.rgba & 0xFF) / 255.0};
  return s;
}

// The device vertex docs/protocol.md 16.2-16.4 define for it, from integers only (Z: 16.3's
// floor(z·16777215 + 0.5); colours are exact multiples of 1/255).
DeviceVertex documented(const TieVertex& t, std::uint32_t q) {
  DeviceVertex d;
  d.x = static_cast<std::int16_t>((t.x32 + 1) / 2);
  d.y = static_cast<std::int16_t>((t.y32 + 1) / 2);
  d.z = static_cast<std::uint32_t>(std::floor(t.z * 16777215.0 + 0.5));
  d.rgba = t.rgba;
  d.q = q;
  return d;
}

// Q of 16.4 (normalised 1/w per triangle): the same for every path, taken from the host's
// conversion so that only positions and Z are under test here.
std::vector<DeviceTriangle> documented_triangles(const std::vector<TieVertex>& verts, const std::vector<DeviceTriangle>& sent) {
  std::vector<DeviceTriangle> out;
  for (std::size_t i = 0; i + 2 < verts.size(); i += 3) {
    DeviceTriangle t;
    for (int k = 0; k < 3; ++k) t[k] = documented(verts[i + k], i / 3 < sent.size() ? sent[i / 3][k].q : 0xFFFFFFFFu);
    out.push_back(t);
  }
  return out;
}

// Snaps x (any double) to a tie: the odd multiple of 1/32 nearest to it, offset by `phase`
// (1 or 3: x ≡ 1/32 or 3/32 mod 1/8 px, the two tie positions between 1/8-pixel grid lines).
int tie32(double x, int phase) {
  const int eighths = static_cast<int>(std::floor(x * 8.0));
  return eighths * 4 + phase;
}

enum class WClass { PowerOfTwo, Other };

double random_w(std::mt19937& rng, WClass c) {
  if (c == WClass::PowerOfTwo) {
    static constexpr double kPowers[] = {0.25, 0.5, 2.0, 4.0, 8.0};
    return kPowers[std::uniform_int_distribution<int>(0, 4)(rng)];
  }
  for (;;) {  // between 0.25 and 8, never a power of two (never 1)
    const double w = std::uniform_real_distribution<double>(0.25, 8.0)(rng);
    int e = 0;
    if (std::frexp(w, &e) != 0.5) return w;
  }
}

TieVertex random_tie_vertex(std::mt19937& rng, double x, double y, int phase, WClass c) {
  TieVertex t;
  t.x32 = tie32(x, phase);
  t.y32 = tie32(y, phase);
  t.z = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
  t.w = random_w(rng, c);
  t.rgba = static_cast<std::uint32_t>(rng());
  return t;
}

// A fan of triangles around a centre whose shared spokes all point into one octant, every vertex
// on a tie: centre and spoke ends are shared between neighbouring triangles, so an owner change
// along any spoke shows.
std::vector<TieVertex> octant_fan(std::mt19937& rng, int octant, int phase, WClass c) {
  constexpr int kSpokes = 7;
  constexpr double cx = 48.3, cy = 47.6;
  const TieVertex centre = random_tie_vertex(rng, cx, cy, phase, c);
  std::vector<TieVertex> ends;
  for (int k = 0; k < kSpokes; ++k) {
    const double a = (octant + 0.06 + 0.88 * k / (kSpokes - 1)) * std::numbers::pi / 4;
    const double r = std::uniform_real_distribution<double>(20.0, 40.0)(rng);
    ends.push_back(random_tie_vertex(rng, cx + r * std::cos(a), cy + r * std::sin(a), phase, c));
  }
  std::vector<TieVertex> tris;
  for (int k = 0; k + 1 < kSpokes; ++k) tris.insert(tris.end(), {centre, ends[k], ends[k + 1]});
  return tris;
}

// A jittered grid mesh (the case): every vertex on a tie, per-vertex w, both diagonals.
std::vector<TieVertex> tie_mesh(std::mt19937& rng, int phase, WClass c) {
  constexpr int kCells = 11;
  constexpr double kCell = 8.0;
  std::uniform_real_distribution<double> jitter(-0.4, 0.4);
  std::vector<TieVertex> grid;
  for (int j = 0; j <= kCells; ++j)
    for (int i = 0; i <= kCells; ++i)
      grid.push_back(random_tie_vertex(rng, 2 + i * kCell + jitter(rng), 2 + j * kCell + jitter(rng), phase, c));
  auto at = [&](int i, int j) { return grid[j * (kCells + 1) + i]; };
  std::vector<TieVertex> tris;
  std::bernoulli_distribution diag(0.5);
  for (int j = 0; j < kCells; ++j)
    for (int i = 0; i < kCells; ++i) {
      if (diag(rng)) {
        tris.insert(tris.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)});
      } else {
        tris.insert(tris.end(), {at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      }
    }
  return tris;
}

// Per pixel: 1 + the index of the last triangle covering it (draw order), 0 when none does.
std::vector<int> reference_owner(const std::vector<DeviceTriangle>& tris, const PixelRect& clip, unsigned width) {
  std::vector<int> owner(std::size_t(clip.x1) * clip.y1);
  for (std::size_t i = 0; i < tris.size(); ++i)
    for (const auto& s : rasterize(to_fixed(tris[i]), clip)) owner[std::size_t(s.y) * width + s.x] = int(i) + 1;
  return owner;
}

std::vector<int> device_owner(SimHarness& h, const std::vector<DeviceTriangle>& tris) {
  h.clear(0x00000000u);
  geometry::RenderState flat;
  flat.gouraud = false;
  h.state(flat);
  auto ids = tris;
  for (std::size_t i = 0; i < ids.size(); ++i)
    for (auto& v : ids[i]) v.rgba = static_cast<std::uint32_t>(i + 1) << 8;  // id in G and B, R = A = 0
  h.draw(ids);
  std::vector<int> owner(std::size_t{h.width()} * h.height());
  for (unsigned y = 0; y < h.height(); ++y)
    for (unsigned x = 0; x < h.width(); ++x) {
      const auto c = h.color(int(x), int(y));
      owner[std::size_t{y} * h.width() + x] = (c.g << 8) | c.b;
    }
  return owner;
}

struct Differences {
  int vertices = 0, coverage = 0, owner = 0, attributes = 0;
  double worst_z = 0, worst_color = 0;
  std::string first;  // the first difference, readable
  bool none() const { return vertices + coverage + owner + attributes == 0; }
};

// Draws what a host path sent and compares it, pixel by pixel, with the reference of the
// documented triangles.
Differences compare(SimHarness& h, const std::vector<TieVertex>& verts, const std::vector<DeviceTriangle>& sent) {
  Differences d;
  const auto want = documented_triangles(verts, sent);
  if (sent.size() != want.size()) {
    d.vertices = 1;
    d.first = "sent " + std::to_string(sent.size()) + " triangles, expected " + std::to_string(want.size());
    return d;
  }
  auto note = [&](const std::string& s) {
    if (d.first.empty()) d.first = s;
  };
  for (std::size_t i = 0; i < want.size(); ++i)
    for (int k = 0; k < 3; ++k)
      if (sent[i][k].x != want[i][k].x || sent[i][k].y != want[i][k].y || sent[i][k].z != want[i][k].z) {
        ++d.vertices;
        const TieVertex& t = verts[i * 3 + k];
        std::ostringstream s;
        s.precision(17);
        s << "triangle " << i << " vertex " << k << ": x = " << t.x32 / 32.0 << ", y = " << t.y32 / 32.0
          << ", z = " << t.z << ", w = " << t.w << " was sent as X = " << sent[i][k].x << ", Y = " << sent[i][k].y
          << ", Z = " << sent[i][k].z << "; floor(16x + 0.5) = " << want[i][k].x << ", " << want[i][k].y
          << ", Z = " << want[i][k].z;
        note(s.str());
      }
  const PixelRect full = h.full_rect();
  const auto hits = h.hit_counts(sent), want_hits = reference_hit_counts(want, full, h.width(), h.height());
  for (std::size_t p = 0; p < hits.size(); ++p) d.coverage += hits[p] != want_hits[p];
  const auto owner = device_owner(h, sent), want_owner = reference_owner(want, full, h.width());
  for (std::size_t p = 0; p < owner.size(); ++p)
    if (owner[p] != want_owner[p]) {
      ++d.owner;
      note("pixel (" + std::to_string(p % h.width()) + ", " + std::to_string(p / h.width()) + ") owned by triangle " +
           std::to_string(owner[p] - 1) + ", documented " + std::to_string(want_owner[p] - 1));
    }
  // Attributes: Z (depth always passes, written) and Gouraud colour against the exact value of the
  // documented triangle that owns the pixel.
  h.clear(0, 0xFFFFFF);
  geometry::RenderState st;
  st.z_test = true;
  st.z_func = protocol::DepthFunc::Always;
  st.z_write = true;
  h.state(st);
  h.draw(sent);
  for (unsigned y = 0; y < h.height(); ++y)
    for (unsigned x = 0; x < h.width(); ++x) {
      const int o = want_owner[std::size_t{y} * h.width() + x];
      if (o == 0) continue;
      const RefSample ref = sample_at(to_fixed(want[o - 1]), int(x), int(y));
      const double dz = std::fabs(double(h.depth(int(x), int(y))) - ref.z);
      const auto c = h.color(int(x), int(y));
      const double got[4] = {double(c.r), double(c.g), double(c.b), double(c.a)};
      double dc = 0;
      for (int k = 0; k < 4; ++k) dc = std::max(dc, std::fabs(got[k] - ref.rgba[k]));
      d.worst_z = std::max(d.worst_z, dz);
      d.worst_color = std::max(d.worst_color, dc);
      if (dz > kHalfLsb || dc > kHalfLsb) {
        ++d.attributes;
        note("pixel (" + std::to_string(x) + ", " + std::to_string(y) + "): Z off by " + std::to_string(dz) +
             " LSB, colour by " + std::to_string(dc) + " LSB from the documented triangle");
      }
    }
  return d;
}

std::string describe(const Differences& d) {
  return std::to_string(d.vertices) + " vertices off the rule, " + std::to_string(d.coverage) + " coverage, " +
         std::to_string(d.owner) + " owner and " + std::to_string(d.attributes) +
         " attribute differences (worst Z " + std::to_string(d.worst_z) + " LSB, colour " +
         std::to_string(d.worst_color) + " LSB); first: " + d.first;
}

const char* name(WClass c) { return c == WClass::PowerOfTwo ? "w a power of two" : "w not a power of two"; }

// Bound: 0 vertices off the rule and 0 pixels differing from the reference in coverage, owner,
// Z or colour (beyond 0.5 LSB), for fans with shared spokes in each of the 8 octants, ties at 1/32
// and 3/32, and per-vertex w from 0.25 to 8 (powers of two and not), through both host paths.
TEST(SnapTies, OctantFansTiesNonUnitW_BothHostPathsMatchDocumentedRule) {
  SimHarness h({.width = 96, .height = 96});
  std::mt19937 rng(25);
  for (WClass c : {WClass::PowerOfTwo, WClass::Other})
    for (int phase : {1, 3})
      for (int octant = 0; octant < 8; ++octant) {
        const auto verts = octant_fan(rng, octant, phase, c);
        std::vector<ScreenVertex> sv;
        for (const auto& t : verts) sv.push_back(screen(t));
        const std::string where =
            std::string(name(c)) + ", ties at " + std::to_string(phase) + "/32, octant " + std::to_string(octant);
        const auto scene_diff = compare(h, verts, through_scene(sv, 96));
        EXPECT_TRUE(scene_diff.none()) << "scene file, " << where << ": " << describe(scene_diff);
        const auto draw_diff = compare(h, verts, through_draw_screen(sv, 96));
        EXPECT_TRUE(draw_diff.none()) << "draw_screen, " << where << ": " << describe(draw_diff);
      }
}

// Bound: as above for the jittered mesh (11x11 cells, random diagonals) with every vertex on
// a tie and its own w; the interior is covered exactly once.
TEST(SnapTies, JitteredTieMeshNonUnitW_MatchesDocumentedRuleEverywhere) {
  SimHarness h({.width = 96, .height = 96});
  std::mt19937 rng(15);
  for (WClass c : {WClass::PowerOfTwo, WClass::Other})
    for (int phase : {1, 3}) {
      const auto verts = tie_mesh(rng, phase, c);
      std::vector<ScreenVertex> sv;
      for (const auto& t : verts) sv.push_back(screen(t));
      const std::string where = std::string(name(c)) + ", ties at " + std::to_string(phase) + "/32";
      const auto sent = through_scene(sv, 96);
      const auto d = compare(h, verts, sent);
      EXPECT_TRUE(d.none()) << "scene file, " << where << ": " << describe(d);
      const auto counts = h.hit_counts(sent);
      for (int y = 4; y < 2 + 11 * 8 - 2; ++y)
        for (int x = 4; x < 2 + 11 * 8 - 2; ++x)
          ASSERT_EQ(counts[std::size_t(y) * 96 + x], 1) << where << ": pixel " << x << "," << y;
    }
}

// floor(16·x + 0.5) by its definition: the integer n with n − 1/2 ≤ 16x < n + 1/2 (16x and n ± 1/2
// are exact doubles in the 12.4 range).
bool is_documented_snap(double x, int n) {
  const double s = 16.0 * x;
  return double(n) - 0.5 <= s && s < double(n) + 0.5;
}

// x values that stress the rule: exact ties, one ulp either side of a tie, and arbitrary reals.
double random_x(std::mt19937_64& rng, double lo, double hi) {
  const double tie = (std::floor(std::uniform_real_distribution<double>(lo, hi)(rng) * 16.0) + 0.5) / 16.0;
  switch (std::uniform_int_distribution<int>(0, 3)(rng)) {
    case 0: return tie;
    case 1: return std::nextafter(tie, -1e300);
    case 2: return std::nextafter(tie, 1e300);
    default: return std::uniform_real_distribution<double>(lo, hi)(rng);
  }
}

// Property (docs/protocol.md 16.2): for random (x, w) pairs — x a tie, one ulp off a tie or any
// real in [-1000, 1000], w log-uniform over the scene format's [1e-6, 1e6] — the X and Y both host
// paths send are floor(16·x + 0.5) and floor(16·y + 0.5) of the x and y given.
TEST(SnapTies, RandomXAndW_SnappedPositionIsFloorOf16xPlusHalf) {
  std::mt19937_64 rng(1515);
  std::uniform_real_distribution<double> log_w(std::log(1e-6), std::log(1e6));
  std::vector<ScreenVertex> sv;
  for (int i = 0; i < 4000; ++i) {
    // Three vertices a few pixels apart (never collinear after snapping, never clipped).
    const double x = random_x(rng, -1000, 1000), y = random_x(rng, -1000, 1000);
    const double dx[3] = {0, 3.5, 0.75}, dy[3] = {0, 0.5, 5.25};
    for (int k = 0; k < 3; ++k) {
      ScreenVertex v;
      v.x = k == 0 ? x : random_x(rng, x + dx[k], x + dx[k] + 0.5);
      v.y = k == 0 ? y : random_x(rng, y + dy[k], y + dy[k] + 0.5);
      v.z = std::uniform_real_distribution<double>(0.0, 1.0)(rng);
      v.w = std::clamp(std::exp(log_w(rng)), 1e-6, 1e6);
      sv.push_back(v);
    }
  }
  for (const char* path : {"scene file", "draw_screen"}) {
    const auto sent = std::string(path) == "scene file" ? through_scene(sv, 64) : through_draw_screen(sv, 64);
    ASSERT_EQ(sent.size(), sv.size() / 3) << path << ": every triangle must be sent unclipped";
    int wrong = 0;
    std::string first;
    for (std::size_t i = 0; i < sv.size(); ++i) {
      const auto& got = sent[i / 3][i % 3];
      if (is_documented_snap(sv[i].x, got.x) && is_documented_snap(sv[i].y, got.y)) continue;
      if (wrong++ == 0) {
        std::ostringstream s;
        s.precision(17);
        s << "x = " << sv[i].x << ", y = " << sv[i].y << ", w = " << sv[i].w << " sent as X = " << got.x
          << ", Y = " << got.y << " (16x = " << 16 * sv[i].x << ", 16y = " << 16 * sv[i].y << ")";
        first = s.str();
      }
    }
    EXPECT_EQ(wrong, 0) << path << ": " << wrong << " of " << sv.size() << " vertices not snapped per "
                        << "floor(16x + 0.5); first: " << first;
  }
}

}  // namespace
}  // namespace gpubridge::accuracy
