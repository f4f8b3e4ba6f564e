// donut ASIC: a torus lit per vertex on the host and dithered down to 2 bits per channel, with the
// seed's temporal dither and shift-and-add (CORDIC) arithmetic as options (torus.hpp).
#include "gpubridge/examples/torus.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "examples_internal.hpp"
#include "fallbacks.hpp"
#include "mesh.hpp"

namespace gpubridge::examples {
namespace {

constexpr int kMajor = 40, kMinor = 20;  // rings around the hole, steps around the tube
constexpr double kR = 1.0, kr = 0.45;    // ring and tube radii

// The model rotation of frame n: rotate_x(kTiltA + n·kSpinA) · rotate_z(n·kSpinB).
constexpr double kSpin = 0.07;
double angle_a(unsigned n) { return 0.9 + n * kSpin; }
double angle_b(unsigned n) { return n * kSpin * 0.6; }

// The light (world space) and the highlight direction the specular term uses.
const geometry::Vec3 kLight = geometry::normalize({-0.4, 0.8, 0.6});
constexpr geometry::Vec3 kHighlight = {0, 0.8, 0.6};

// Per-vertex shading from the two dot products (normal · light, normal · highlight).
geometry::Vec4 shade(double diffuse_dot, double highlight_dot) {
  const double diffuse = std::max(0.0, diffuse_dot);
  const double spec = std::pow(std::max(0.0, highlight_dot), 24) * 0.6;
  const double l = 0.12 + 0.88 * diffuse;
  return {clamp01(1.0 * l + spec), clamp01(0.62 * l + spec), clamp01(0.25 * l + spec), 1};
}

// v · K(n) as shift-adds of K's binary digits (16 fraction bits), as gates scale by a constant.
struct GainScaler {
  std::vector<unsigned> shifts;  // K = 1 + sum 2^-s
  explicit GainScaler(double k) {
    const auto frac = static_cast<std::uint32_t>(std::lround((k - 1) * 65536));
    for (unsigned s = 1; s <= 16; ++s)
      if (frac & (1u << (16 - s))) shifts.push_back(s);
  }
  std::int32_t operator()(std::int32_t v) const {
    std::int32_t acc = v;
    for (unsigned s : shifts) acc += v >> s;
    return acc;
  }
};

}  // namespace

geometry::Mat4 TorusGeometry::view() { return geometry::look_at({0, 0, 4}, {0, 0, 0}, {0, 1, 0}); }

TorusGeometry::TorusGeometry(unsigned cordic_iterations) : iterations_(cordic_iterations) {
  for (int i = 0; i < kMajor; ++i)
    for (int j = 0; j < kMinor; ++j) {
      const double a = 2 * std::numbers::pi * i / kMajor, b = 2 * std::numbers::pi * j / kMinor;
      const geometry::Vec3 n{std::cos(a) * std::cos(b), std::sin(b), std::sin(a) * std::cos(b)};
      positions_.push_back({std::cos(a) * kR + n.x * kr, n.y * kr, std::sin(a) * kR + n.z * kr});
      normals_.push_back(n);
    }
  for (int i = 0; i < kMajor; ++i)
    for (int j = 0; j < kMinor; ++j) {
      const auto at = [](int ii, int jj) { return static_cast<std::uint32_t>((ii % kMajor) * kMinor + (jj % kMinor)); };
      const std::uint32_t a = at(i, j), b = at(i + 1, j), c = at(i, j + 1), d = at(i + 1, j + 1);
      // Outward-facing counter-clockwise order.
      for (std::uint32_t k : {a, c, b, b, c, d}) indices_.push_back(k);
    }
  if (iterations_ == 0) return;
  // Gains are folded into the inputs once (see frame_cordic for where each K comes from).
  const double k = cordic::gain(iterations_);
  for (const auto& p : positions_) {
    pos_xy_.push_back({cordic::to_fixed(p.x / (k * k)), cordic::to_fixed(p.y / (k * k))});
    pos_z_.push_back(cordic::to_fixed(p.z / k));
  }
  for (int i = 0; i < kMajor; ++i) ring_angle_.push_back(cordic::to_angle(2 * std::numbers::pi * i / kMajor));
  for (int j = 0; j < kMinor; ++j) tube_angle_.push_back(cordic::to_angle(2 * std::numbers::pi * j / kMinor));
  const double k3 = k * k * k, k4 = k3 * k;
  const geometry::Vec3 dirs[2] = {kLight, kHighlight};
  std::int32_t* out[2] = {light_, highlight_};
  for (int d = 0; d < 2; ++d) {
    out[d][0] = cordic::to_fixed(dirs[d].x / k3);
    out[d][1] = cordic::to_fixed(dirs[d].y / k4);
    out[d][2] = cordic::to_fixed(dirs[d].z / k4);
  }
}

void TorusGeometry::frame(unsigned n, Frame& out) const {
  if (iterations_ == 0) frame_float(n, out);
  else frame_cordic(n, out);
}

void TorusGeometry::frame_float(unsigned n, Frame& out) const {
  out.model = geometry::rotate_x(angle_a(n)) * geometry::rotate_z(angle_b(n));
  out.vertices.resize(positions_.size());
  for (std::size_t i = 0; i < positions_.size(); ++i) {
    const auto nw = out.model * geometry::Vec4{normals_[i].x, normals_[i].y, normals_[i].z, 0};
    const double d = nw.x * kLight.x + nw.y * kLight.y + nw.z * kLight.z;
    out.vertices[i] = draw::Vertex(positions_[i], shade(d, nw.z * kHighlight.z + nw.y * kHighlight.y));
  }
}

// Every product below is a CORDIC rotation or a shift-add by the constant gain K = K(n):
//  - position: (x, y) turned by B, then (y, z) by A (model = rotate_x(A) · rotate_z(B)); x and y
//    enter at 1/K², z at 1/K, so y and z leave at 1, and x, which meets one rotation, is scaled by K;
//  - normal · light = n · L' with L' = rotate_z(-B) · rotate_x(-A) · L (the light in model space,
//    once per frame), and for the mesh normal n = (cos a cos b, sin b, sin a cos b) that dot is
//    (L'x, L'z) turned by -a, whose x with L'y turned by -b gives the product: one rotation per
//    ring and one per vertex, no multiply (the donut ASIC's trick of rotating the light instead of
//    the normal). The directions enter at 1/K^4 (x at 1/K^3) and leave at 1;
//  - the same for the highlight direction of the specular term.
void TorusGeometry::frame_cordic(unsigned n, Frame& out) const {
  const unsigned k = iterations_;
  const GainScaler times_k(cordic::gain(k));
  const cordic::Angle a = cordic::to_angle(angle_a(n)), b = cordic::to_angle(angle_b(n));
  struct ModelDir {
    std::int32_t x, y, z;  // x and z at 1/K^2 (for the ring rotation), y at 1/K (for the vertex one)
  };
  auto to_model = [&](const std::int32_t* v) {
    const cordic::Vec2 yz = cordic::rotate({v[1], v[2]}, 0u - a, k);  // y, z: 1/K^4 -> 1/K^3
    const cordic::Vec2 xy = cordic::rotate({v[0], yz.x}, 0u - b, k);  // x, y: 1/K^3 -> 1/K^2
    return ModelDir{xy.x, times_k(xy.y), times_k(yz.y)};
  };
  const ModelDir light = to_model(light_), high = to_model(highlight_);
  out.model = geometry::identity();
  out.vertices.resize(pos_xy_.size());
  for (int i = 0; i < kMajor; ++i) {
    const cordic::Angle ring = 0u - ring_angle_[static_cast<std::size_t>(i)];
    const std::int32_t lx = cordic::rotate({light.x, light.z}, ring, k).x;  // 1/K
    const std::int32_t hx = cordic::rotate({high.x, high.z}, ring, k).x;
    for (int j = 0; j < kMinor; ++j) {
      const std::size_t v = static_cast<std::size_t>(i * kMinor + j);
      const cordic::Angle tube = 0u - tube_angle_[static_cast<std::size_t>(j)];
      const std::int32_t d = cordic::rotate({lx, light.y}, tube, k).x;  // 1
      const std::int32_t h = cordic::rotate({hx, high.y}, tube, k).x;
      const cordic::Vec2 xy = cordic::rotate(pos_xy_[v], b, k);          // 1/K
      const cordic::Vec2 yz = cordic::rotate({xy.y, pos_z_[v]}, a, k);   // 1
      out.vertices[v] = draw::Vertex({cordic::from_fixed(times_k(xy.x)), cordic::from_fixed(yz.x), cordic::from_fixed(yz.y)},
                                     shade(cordic::from_fixed(d), cordic::from_fixed(h)));
    }
  }
}

namespace {

class Torus final : public Example {
 public:
  explicit Torus(const TorusOptions& o) : opt_(o) {}

  ExampleInfo info() const override {
    if (opt_.cordic_iterations != 0)
      return {"torus-cordic", "donut ASIC",
              "the torus rotated and lit with " + std::to_string(opt_.cordic_iterations) +
                  "-step shift-and-add (CORDIC) rotations instead of floating point"};
    if (opt_.temporal)
      return {"torus-temporal", "donut ASIC", "the torus with the temporal dither: the Bayer pattern changes every frame"};
    return {"torus", "donut ASIC", "a spinning torus lit per vertex, ordered-dithered to RGBA2222"};
  }
  Wants wants(std::uint16_t) const override {
    Wants w;
    // RGBA8888 without dither only for error measurements and reference figures (TorusOptions).
    w.format = opt_.rgba8888 ? protocol::PixelFormat::RGBA8888 : protocol::PixelFormat::RGBA2222;
    w.dither = !opt_.rgba8888;
    // Two bits per channel, dithered, is the idea: the format is held longest.
    w.keep = {Knob::Format, Knob::Size, Knob::Textures, Knob::DoubleBuffer, Knob::Depth};
    w.without_depth = "triangles drawn far to near by their centres (back faces culled)";
    w.without_feature = {{kDither, "colour bands instead of the ordered dither"}};
    if (opt_.temporal) w.without_feature.push_back({kTemporalDither, "the ordered dither, the same pattern every frame"});
    return w;
  }

  // The temporal dither's frames differ by design: four consecutive frames (phases 12..15, an
  // aligned run of four) have goldens.
  std::vector<unsigned> golden_frames() const override {
    if (!opt_.temporal) return Example::golden_frames();
    return {kGoldenFrame, kGoldenFrame + 1, kGoldenFrame + 2, kGoldenFrame + 3};
  }

  Result<void> setup(draw::Context&) override {
    geometry_ = std::make_unique<TorusGeometry>(opt_.cordic_iterations);
    return {};
  }

  Result<void> frame(draw::Context& ctx, unsigned n) override {
    if (auto r = begin_frame(ctx, config(), {0, 0, 0, 1}); !r) return r;
    // The temporal dither where the device has it (CAPS bit 6), else the ordered dither.
    const bool temporal = opt_.temporal && config().dither && config().has(kTemporalDither);
    ctx.state().temporal = temporal;
    ctx.state().dither_phase = n;  // DITHER_PHASE = frame number mod 16 (sent only with TEMPORAL)
    ctx.set_cull(geometry::CullMode::Back);
    // Lighting per vertex on the host (the ASIC shades each sample).
    geometry_->frame(opt_.pose.value_or(n), frame_);
    const auto mvp = projection(ctx, TorusGeometry::kFovY, TorusGeometry::kNear, TorusGeometry::kFar) *
                     TorusGeometry::view() * frame_.model;
    ctx.set_transform(mvp);
    ctx.unbind_texture();
    if (!config().painter()) return ctx.draw_indexed(frame_.vertices, geometry_->indices());
    return ctx.draw_indexed(frame_.vertices,
                            far_to_near(geometry_->indices(), centroid_depths(frame_.vertices, geometry_->indices(), mvp)));
  }

 private:
  TorusOptions opt_;
  std::unique_ptr<TorusGeometry> geometry_;
  TorusGeometry::Frame frame_;
};

}  // namespace

std::unique_ptr<Example> make_torus(const TorusOptions& options) { return std::make_unique<Torus>(options); }

}  // namespace gpubridge::examples
