// donut ASIC: a torus lit per vertex on the host and dithered down to 2 bits per channel.
#include <cmath>
#include <numbers>

#include "examples_internal.hpp"
#include "fallbacks.hpp"
#include "mesh.hpp"

namespace gpubridge::examples {
namespace {

constexpr int kMajor = 40, kMinor = 20;
constexpr double kR = 1.0, kr = 0.45;

class Torus final : public Example {
 public:
  ExampleInfo info() const override {
    return {"torus", "donut ASIC", "a spinning torus lit per vertex, ordered-dithered to RGBA2222"};
  }
  Wants wants(std::uint16_t) const override {
    Wants w;
    w.format = protocol::PixelFormat::RGBA2222;
    w.dither = true;
    // Two bits per channel, dithered, is the idea: the format is held longest.
    w.keep = {Knob::Format, Knob::Size, Knob::Textures, Knob::DoubleBuffer, Knob::Depth};
    w.without_depth = "triangles drawn far to near by their centres (back faces culled)";
    w.without_feature = {{kDither, "colour bands instead of the ordered dither"}};
    return w;
  }

  Result<void> setup(draw::Context&) override {
    positions_.clear();
    normals_.clear();
    indices_.clear();
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
    return {};
  }

  Result<void> frame(draw::Context& ctx, unsigned n) override {
    if (auto r = begin_frame(ctx, config(), {0, 0, 0, 1}); !r) return r;
    ctx.set_cull(geometry::CullMode::Back);
    const double t = n * 0.07;
    const auto model = geometry::rotate_x(0.9 + t) * geometry::rotate_z(t * 0.6);
    // Light in world space; lighting per vertex on the host (the ASIC shades each sample).
    const geometry::Vec3 light = geometry::normalize({-0.4, 0.8, 0.6});
    std::vector<draw::Vertex> v(positions_.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
      const auto nw = model * geometry::Vec4{normals_[i].x, normals_[i].y, normals_[i].z, 0};
      const double diffuse = std::max(0.0, nw.x * light.x + nw.y * light.y + nw.z * light.z);
      const double spec = std::pow(std::max(0.0, nw.z * 0.6 + nw.y * 0.8), 24) * 0.6;
      const double l = 0.12 + 0.88 * diffuse;
      v[i] = draw::Vertex(positions_[i], {clamp01(1.0 * l + spec), clamp01(0.62 * l + spec), clamp01(0.25 * l + spec), 1});
    }
    const auto mvp = projection(ctx, 0.8, 0.5, 20) * geometry::look_at({0, 0, 4}, {0, 0, 0}, {0, 1, 0}) * model;
    ctx.set_transform(mvp);
    ctx.unbind_texture();
    if (!config().painter()) return ctx.draw_indexed(v, indices_);
    return ctx.draw_indexed(v, far_to_near(indices_, centroid_depths(v, indices_, mvp)));
  }

 private:
  std::vector<geometry::Vec3> positions_, normals_;
  std::vector<std::uint32_t> indices_;
};

}  // namespace

std::unique_ptr<Example> make_torus() { return std::make_unique<Torus>(); }

}  // namespace gpubridge::examples
