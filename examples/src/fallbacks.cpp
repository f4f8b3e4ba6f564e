#include "fallbacks.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace gpubridge::examples {
namespace {

// Box-filtered halvings of an image, level 0 first, down to 1x1.
std::vector<Image> mip_chain(const Image& img) {
  std::vector<Image> levels{img};
  while (levels.back().width > 1 || levels.back().height > 1) {
    const Image& a = levels.back();
    Image b;
    b.width = std::max(1u, a.width / 2);
    b.height = std::max(1u, a.height / 2);
    b.rgba.resize(std::size_t{b.width} * b.height * 4);
    for (unsigned y = 0; y < b.height; ++y)
      for (unsigned x = 0; x < b.width; ++x)
        for (int c = 0; c < 4; ++c) {
          const unsigned x1 = std::min(2 * x + 1, a.width - 1), y1 = std::min(2 * y + 1, a.height - 1);
          const unsigned sum = a.pixel(2 * x, 2 * y)[c] + a.pixel(x1, 2 * y)[c] + a.pixel(2 * x, y1)[c] + a.pixel(x1, y1)[c];
          b.pixel(x, y)[c] = static_cast<std::uint8_t>((sum + 2) / 4);
        }
    levels.push_back(std::move(b));
  }
  return levels;
}

int wrap_index(long i, unsigned size, protocol::Wrap w) {
  const long n = static_cast<long>(size);
  if (w == protocol::Wrap::Clamp) return static_cast<int>(std::clamp(i, 0L, n - 1));
  return static_cast<int>(((i % n) + n) % n);
}

// Bilinear sample of one level at (u, v) in texture units, RGBA in 0..1.
geometry::Vec4 sample(const Image& img, double u, double v, protocol::Wrap ws, protocol::Wrap wt) {
  const double x = u * img.width - 0.5, y = v * img.height - 0.5;
  const double fx = std::floor(x), fy = std::floor(y);
  const double tx = x - fx, ty = y - fy;
  geometry::Vec4 out;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) {
      const auto* p = img.pixel(wrap_index(static_cast<long>(fx) + i, img.width, ws),
                                wrap_index(static_cast<long>(fy) + j, img.height, wt));
      const double w = (i ? tx : 1 - tx) * (j ? ty : 1 - ty);
      out = out + geometry::Vec4{p[0] / 255.0, p[1] / 255.0, p[2] / 255.0, p[3] / 255.0} * w;
    }
  return out;
}

}  // namespace

std::vector<std::uint32_t> far_to_near(std::span<const std::uint32_t> indices, std::span<const double> distance) {
  std::vector<std::uint32_t> order(indices.size() / 3);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return distance[a] > distance[b]; });
  std::vector<std::uint32_t> out;
  out.reserve(order.size() * 3);
  for (const auto t : order)
    for (int k = 0; k < 3; ++k) out.push_back(indices[std::size_t{t} * 3 + k]);
  return out;
}

std::vector<double> centroid_depths(std::span<const draw::Vertex> vertices, std::span<const std::uint32_t> indices,
                                    const geometry::Mat4& mvp) {
  std::vector<double> d(indices.size() / 3);
  for (std::size_t t = 0; t < d.size(); ++t) {
    geometry::Vec3 c;
    for (int k = 0; k < 3; ++k) c = c + vertices[indices[t * 3 + k]].position * (1.0 / 3);
    d[t] = (mvp * geometry::Vec4{c.x, c.y, c.z, 1}).w;
  }
  return d;
}

Mesh bake_texture(const Mesh& mesh, const Image& texture, unsigned n, bool decal, protocol::Wrap wrap_s, protocol::Wrap wrap_t) {
  n = std::max(1u, n);
  const auto mips = mip_chain(texture);
  Mesh out;
  for (std::size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const draw::Vertex& a = mesh.vertices[mesh.indices[t]];
    const draw::Vertex& b = mesh.vertices[mesh.indices[t + 1]];
    const draw::Vertex& c = mesh.vertices[mesh.indices[t + 2]];
    // Texels one small triangle spans (its longest side in the texture), so its corners sample
    // the mip level that averages over about that many.
    const auto extent = [&](geometry::Vec2 p, geometry::Vec2 q) {
      return std::max(std::fabs(p.x - q.x) * texture.width, std::fabs(p.y - q.y) * texture.height);
    };
    const double span = std::max({extent(a.uv, b.uv), extent(b.uv, c.uv), extent(c.uv, a.uv)}) / n;
    const auto level = static_cast<std::size_t>(std::clamp(std::floor(std::log2(std::max(span, 1.0))), 0.0, double(mips.size() - 1)));
    // Corners (i, j) with i + j <= n at barycentric (1 - i/n - j/n, i/n, j/n).
    const auto base = static_cast<std::uint32_t>(out.vertices.size());
    const auto at = [&](unsigned i, unsigned j) { return base + j * (n + 1) - j * (j - 1) / 2 + i; };
    for (unsigned j = 0; j <= n; ++j)
      for (unsigned i = 0; i + j <= n; ++i) {
        const double wb = double(i) / n, wc = double(j) / n, wa = 1 - wb - wc;
        draw::Vertex v;
        v.position = a.position * wa + b.position * wb + c.position * wc;
        v.uv = a.uv * wa + b.uv * wb + c.uv * wc;
        const geometry::Vec4 color = a.color * wa + b.color * wb + c.color * wc;
        const geometry::Vec4 texel = sample(mips[level], v.uv.x, v.uv.y, wrap_s, wrap_t);
        v.color = decal ? texel : geometry::Vec4{color.x * texel.x, color.y * texel.y, color.z * texel.z, color.w * texel.w};
        out.vertices.push_back(v);
      }
    // Same winding as the original: (i, j), (i+1, j), (i, j+1) and the flipped one between.
    for (unsigned j = 0; j < n; ++j)
      for (unsigned i = 0; i + j < n; ++i) {
        for (auto k : {at(i, j), at(i + 1, j), at(i, j + 1)}) out.indices.push_back(k);
        if (i + j + 1 < n)
          for (auto k : {at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)}) out.indices.push_back(k);
      }
  }
  return out;
}

}  // namespace gpubridge::examples
