#include "gpubridge/examples/fit.hpp"

#include <algorithm>
#include <charconv>

#include <fmt/format.h>

#include "gpubridge/draw/vram_allocator.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::examples {
namespace {

using protocol::PixelFormat;

struct FeatureName {
  std::uint16_t bit;
  std::string_view name;
};
constexpr FeatureName kFeatureNames[] = {{kBilinear, "bilinear"}, {kBlend, "blend"},       {kDither, "dither"},
                                         {kRgb565, "rgb565"},     {kRgba2222, "rgba2222"}, {kTemporalDither, "temporal"},
                                         {kTexturing, "texture"}, {kDepthBuffer, "depth"}};

bool format_available(PixelFormat f, std::uint16_t features) {
  if (f == PixelFormat::RGB565) return (features & kRgb565) != 0;
  if (f == PixelFormat::RGBA2222) return (features & kRgba2222) != 0;
  return true;  // RGBA8888 is mandatory
}

std::uint16_t format_feature(PixelFormat f) { return f == PixelFormat::RGB565 ? kRgb565 : kRgba2222; }

// The formats to try for a wanted one, closest first: smaller ones save memory, a larger one
// stands in for a format the device lacks.
std::vector<PixelFormat> format_ladder(PixelFormat want, std::uint16_t features) {
  std::vector<PixelFormat> order;
  switch (want) {
    case PixelFormat::RGBA8888: order = {PixelFormat::RGBA8888, PixelFormat::RGB565, PixelFormat::RGBA2222}; break;
    case PixelFormat::RGB565: order = {PixelFormat::RGB565, PixelFormat::RGBA8888, PixelFormat::RGBA2222}; break;
    case PixelFormat::RGBA2222: order = {PixelFormat::RGBA2222, PixelFormat::RGB565, PixelFormat::RGBA8888}; break;
  }
  std::erase_if(order, [&](PixelFormat f) { return !format_available(f, features); });
  return order;
}

std::string format_label(PixelFormat f) { return std::string(protocol::to_string(f)); }

// The wanted texture as the device can take it (a format it has), before any memory saving.
TextureFit texture_on_device(const TextureWant& w, std::uint16_t features) {
  TextureFit t{w.name, w.width, w.height, w.format, w.bilinear && (features & kBilinear) != 0};
  if (!format_available(t.format, features))
    t.format = format_ladder(w.format, features).front();
  return t;
}

// One step smaller: RGBA8888 → RGB565 (half the bytes, little visible loss), then halving the
// size down to 8 texels, then RGBA2222. Returns false when nothing is left to give up.
bool shrink_texture(TextureFit& t, std::uint16_t features) {
  if (t.format == PixelFormat::RGBA8888 && format_available(PixelFormat::RGB565, features)) {
    t.format = PixelFormat::RGB565;
    return true;
  }
  if (t.width > 8 || t.height > 8) {
    t.width = std::max(8u, t.width / 2);
    t.height = std::max(8u, t.height / 2);
    return true;
  }
  if (t.format != PixelFormat::RGBA2222 && format_available(PixelFormat::RGBA2222, features)) {
    t.format = PixelFormat::RGBA2222;
    return true;
  }
  return false;
}

std::uint64_t texture_bytes(const TextureFit& t) {
  return std::uint64_t{t.width} * t.height * protocol::bytes_per_pixel(t.format);
}

// Video memory of one candidate, placed as draw::Context places it; 0 when it does not fit.
std::uint64_t placed_bytes(const DeviceCaps& device, const draw::ContextOptions& c, const std::vector<TextureFit>& textures) {
  draw::VramAllocator vram(device.vram_bytes);
  const std::uint64_t color = std::uint64_t{c.width} * c.height * protocol::bytes_per_pixel(c.format);
  for (int i = 0; i < (c.double_buffer ? 2 : 1); ++i)
    if (!vram.allocate(color)) return 0;
  if (c.depth_buffer && !vram.allocate(std::uint64_t{c.width} * c.height * 4)) return 0;
  for (const auto& t : textures)
    if (!vram.allocate(texture_bytes(t))) return 0;
  return vram.capacity() - vram.free_bytes();
}

std::string texture_label(const TextureFit& t) {
  return fmt::format("{}x{} {}{}", t.width, t.height, format_label(t.format), t.bilinear ? " bilinear" : "");
}

std::string thousands(std::uint64_t v) {
  std::string s = std::to_string(v);
  for (int i = static_cast<int>(s.size()) - 3; i > 0; i -= 3) s.insert(static_cast<std::size_t>(i), ",");
  return s;
}

}  // namespace

std::string_view feature_name(std::uint16_t bit) {
  for (const auto& f : kFeatureNames)
    if (f.bit == bit) return f.name;
  return "?";
}

std::optional<std::uint16_t> parse_feature(std::string_view name) {
  for (const auto& f : kFeatureNames)
    if (f.name == name) return f.bit;
  return std::nullopt;
}

std::string feature_names(std::uint16_t mask) {
  std::string out;
  for (const auto& f : kFeatureNames)
    if (mask & f.bit) out += (out.empty() ? "" : " ") + std::string(f.name);
  return out;
}

DeviceCaps DeviceCaps::from(const backends::DeviceInfo& info) {
  DeviceCaps d;
  d.name = info.board.empty() ? (info.backend.empty() ? "simulator" : info.backend) : info.board;
  d.vram_bytes = info.vram_bytes;
  d.max_width = info.max_width;
  d.max_height = info.max_height;
  if (info.caps != 0)
    d.features = static_cast<std::uint16_t>(protocol::describe(protocol::Reg::CAPS).field("FEATURES")->get(info.caps)) |
                 (protocol::protocol_minor(info.id) < 2 ? kTexturing : 0) |  // protocol 1.0/1.1: no bit 7, every device textures
                 (protocol::has_depth_buffer(info.id, info.caps2) ? kDepthBuffer : 0);  // CAPS2 bit 0, or before 1.4
  return d;
}

sim::DeviceOptions DeviceCaps::simulator_options() const {
  sim::DeviceOptions o;
  o.vram_bytes = std::clamp<std::uint64_t>(vram_bytes / 1024 * 1024, 64 * 1024, sim::kMaxVramBytes);
  o.max_width = std::clamp(max_width, 1u, protocol::kMaxFramebufferDim);
  o.max_height = std::clamp(max_height, 1u, protocol::kMaxFramebufferDim);
  o.features = static_cast<std::uint8_t>(features & sim::kAllFeatures);
  o.features2 = has(kDepthBuffer) ? sim::FEATURE2_DEPTH : 0;
  return o;
}

Result<std::pair<unsigned, unsigned>> parse_size(std::string_view text) {
  const auto bad = [&] {
    return make_error(fmt::format("size \"{}\": expected WIDTHxHEIGHT, each 1..{} (e.g. 320x240)", text,
                                  protocol::kMaxFramebufferDim));
  };
  const auto x = text.find('x');
  if (x == std::string_view::npos) return bad();
  unsigned w = 0, h = 0;
  const auto a = text.substr(0, x), b = text.substr(x + 1);
  if (std::from_chars(a.data(), a.data() + a.size(), w).ptr != a.data() + a.size() || a.empty()) return bad();
  if (std::from_chars(b.data(), b.data() + b.size(), h).ptr != b.data() + b.size() || b.empty()) return bad();
  if (w < 1 || h < 1 || w > protocol::kMaxFramebufferDim || h > protocol::kMaxFramebufferDim) return bad();
  return std::pair{w, h};
}

Image TextureFit::shrink(const Image& full) const {
  if (full.width == width && full.height == height) return full;
  // Box filter over whole blocks (the sizes are powers of two, so the blocks tile the image).
  const unsigned bx = std::max(1u, full.width / width), by = std::max(1u, full.height / height);
  Image out;
  out.width = width;
  out.height = height;
  out.rgba.resize(std::size_t{width} * height * 4);
  for (unsigned y = 0; y < height; ++y)
    for (unsigned x = 0; x < width; ++x)
      for (int c = 0; c < 4; ++c) {
        unsigned sum = 0;
        for (unsigned j = 0; j < by; ++j)
          for (unsigned i = 0; i < bx; ++i) sum += full.pixel(std::min(x * bx + i, full.width - 1), std::min(y * by + j, full.height - 1))[c];
        out.pixel(x, y)[c] = static_cast<std::uint8_t>((sum + bx * by / 2) / (bx * by));
      }
  return out;
}

draw::TextureOptions TextureFit::options(protocol::Wrap wrap_s, protocol::Wrap wrap_t) const {
  return {.format = format, .wrap_s = wrap_s, .wrap_t = wrap_t, .bilinear = bilinear};
}

std::string Fit::summary() const {
  return choice() + fmt::format("; {} of {} bytes", thousands(vram_bytes), thousands(device.vram_bytes));
}

std::string Fit::choice() const {
  std::string s = fmt::format("{}x{} {}{}, {}, {}", context.width, context.height, format_label(context.format),
                              dither ? " dithered" : "", context.double_buffer ? "double-buffered" : "single buffer",
                              context.depth_buffer ? "depth buffer" : "painter's order");
  if (!textures.empty()) {
    s += "; textures";
    for (std::size_t i = 0; i < textures.size(); ++i) s += (i ? ", " : " ") + texture_label(textures[i]);
  }
  return s;
}

Result<Fit> fit(const Wants& wants, const DeviceCaps& device, const FitRequest& request) {
  Fit f;
  f.device = device;
  f.features = device.features & static_cast<std::uint16_t>(~request.without);

  // Candidates per knob, best first.
  // Size: the wanted size, scaled (same aspect) to the device's largest, then smaller steps.
  std::vector<std::pair<unsigned, unsigned>> sizes;
  const double fit_scale = std::min({1.0, double(device.max_width) / wants.width, double(device.max_height) / wants.height});
  const unsigned w0 = std::max(1u, static_cast<unsigned>(wants.width * fit_scale));
  const unsigned h0 = std::max(1u, static_cast<unsigned>(wants.height * fit_scale));
  if (request.size) {
    const auto [w, h] = *request.size;
    if (w > device.max_width || h > device.max_height)
      return make_error(fmt::format("--size {}x{} is larger than {}'s largest framebuffer, {}x{}", w, h, device.name,
                                    device.max_width, device.max_height));
    sizes.push_back(*request.size);
  } else {
    for (const auto& [num, den] : {std::pair{1u, 1u}, {4u, 5u}, {3u, 5u}, {1u, 2u}, {2u, 5u}, {3u, 10u}, {1u, 5u}}) {
      const std::pair<unsigned, unsigned> s{std::max(1u, w0 * num / den), std::max(1u, h0 * num / den)};
      if (std::find(sizes.begin(), sizes.end(), s) == sizes.end()) sizes.push_back(s);
    }
  }
  std::vector<PixelFormat> formats;
  if (request.format) {
    if (!format_available(*request.format, f.features))
      return make_error(fmt::format("--format {}: {} cannot use it (its CAPS.FEATURES lack {})", format_label(*request.format),
                                    device.name, feature_name(format_feature(*request.format))));
    formats.push_back(*request.format);
  } else {
    formats = format_ladder(wants.format, f.features);
  }
  std::vector<bool> doubles{wants.double_buffer};
  if (wants.double_buffer) doubles.push_back(false);
  // A device without a depth buffer (CAPS2, protocol 1.4) draws in painter's order, as --no-depth does.
  const bool want_depth = wants.depth && !request.no_depth && f.has(kDepthBuffer);
  std::vector<bool> depths{want_depth};
  if (want_depth) depths.push_back(false);
  // Textures: level 0 is what the device can take; each further level gives up one step.
  std::vector<std::vector<TextureFit>> texture_levels;
  if (f.texturing()) {
    std::vector<TextureFit> level;
    for (const auto& t : wants.textures) level.push_back(texture_on_device(t, f.features));
    texture_levels.push_back(level);
    for (bool changed = !level.empty(); changed;) {
      changed = false;
      for (auto& t : level) changed |= shrink_texture(t, f.features);
      if (changed) texture_levels.push_back(level);
    }
  } else {
    texture_levels.emplace_back();
  }

  // Odometer over the knobs in `keep` order: the last knob turns fastest (given up first).
  const auto count = [&](Knob k) -> std::size_t {
    switch (k) {
      case Knob::Size: return sizes.size();
      case Knob::Format: return formats.size();
      case Knob::Textures: return texture_levels.size();
      case Knob::DoubleBuffer: return doubles.size();
      case Knob::Depth: return depths.size();
    }
    return 1;
  };
  std::array<std::size_t, 5> level{};  // indexed like wants.keep
  const auto pick = [&](Knob k) {
    for (std::size_t i = 0; i < wants.keep.size(); ++i)
      if (wants.keep[i] == k) return level[i];
    return std::size_t{0};
  };
  std::uint64_t smallest_need = 0;
  for (;;) {
    draw::ContextOptions c;
    std::tie(c.width, c.height) = sizes[pick(Knob::Size)];
    c.format = formats[pick(Knob::Format)];
    c.double_buffer = doubles[pick(Knob::DoubleBuffer)];
    c.depth_buffer = depths[pick(Knob::Depth)];
    const auto& textures = texture_levels[pick(Knob::Textures)];
    if (const auto used = placed_bytes(device, c, textures)) {
      f.context = c;
      f.textures = textures;
      f.vram_bytes = used;
      break;
    }
    // Advance the odometer.
    std::size_t i = wants.keep.size();
    while (i > 0) {
      --i;
      if (++level[i] < count(wants.keep[i])) break;
      level[i] = 0;
      if (i == 0) {
        // Everything tried: say what the smallest candidate needs.
        draw::ContextOptions small;
        std::tie(small.width, small.height) = sizes.back();
        small.format = formats.back();
        small.double_buffer = doubles.back();
        small.depth_buffer = depths.back();
        smallest_need = std::uint64_t{small.width} * small.height * protocol::bytes_per_pixel(small.format) *
                            (small.double_buffer ? 2 : 1) +
                        (small.depth_buffer ? std::uint64_t{small.width} * small.height * 4 : 0);
        for (const auto& t : texture_levels.back()) smallest_need += texture_bytes(t);
        return make_error(fmt::format("nothing fits in {}'s {} bytes of video memory: the smallest configuration "
                                      "({}x{} {}{}{}) needs {} bytes",
                                      device.name, device.vram_bytes, small.width, small.height, format_label(small.format),
                                      small.double_buffer ? ", double-buffered" : "", small.depth_buffer ? ", depth buffer" : "",
                                      smallest_need));
      }
    }
  }

  // Dither: wanted, or standing in for bits the format lost.
  const auto bits = [](PixelFormat p) { return protocol::bytes_per_pixel(p); };
  const bool reduced = bits(f.context.format) < bits(wants.format);
  f.dither = (wants.dither || reduced) && f.context.format != PixelFormat::RGBA8888 && f.has(kDither);

  // What was given up, and why.
  const auto why_feature = [&](std::uint16_t bit) {
    return (request.without & bit) ? fmt::format("--without {}", feature_name(bit))
                                   : fmt::format("{} has no {}", device.name, feature_name(bit));
  };
  if (std::pair{f.context.width, f.context.height} != std::pair{wants.width, wants.height}) {
    const char* why = request.size ? "--size"
                      : (f.context.width == w0 && f.context.height == h0)
                          ? "the device's largest"
                          : "video memory";
    f.gave_up.push_back(fmt::format("framebuffer {}x{} -> {}x{} ({})", wants.width, wants.height, f.context.width,
                                    f.context.height, why));
  }
  if (f.context.format != wants.format) {
    const char* why = request.format                                ? "--format"
                      : !format_available(wants.format, f.features) ? nullptr
                                                                    : "video memory";
    f.gave_up.push_back(fmt::format("{} -> {}{} ({})", format_label(wants.format), format_label(f.context.format),
                                    f.dither ? " with the Bayer dither" : "",
                                    why ? std::string(why) : why_feature(format_feature(wants.format))));
  }
  if (wants.double_buffer && !f.context.double_buffer)
    f.gave_up.push_back("double buffering -> one buffer, drawn while it is shown (video memory)");
  if (wants.depth && !f.context.depth_buffer)
    f.gave_up.push_back(fmt::format("depth buffer -> {} ({})", wants.without_depth,
                                    request.no_depth                  ? std::string("--no-depth")
                                    : (request.without & kDepthBuffer) ? std::string("--without depth")
                                    : !f.has(kDepthBuffer)             ? device.name + " has no depth buffer (CAPS2)"
                                                                       : std::string("video memory")));
  if (f.texturing())
    for (std::size_t i = 0; i < wants.textures.size(); ++i) {
      const auto& w = wants.textures[i];
      const auto& t = f.textures[i];
      const TextureFit device_level = texture_on_device(w, f.features);
      if (t.width == w.width && t.height == w.height && t.format == w.format) continue;
      std::string why;
      if (device_level.format != w.format) why = why_feature(format_feature(w.format));
      if (!(t.width == device_level.width && t.height == device_level.height && t.format == device_level.format))
        why += std::string(why.empty() ? "" : ", ") + "video memory";
      f.gave_up.push_back(fmt::format("texture {} {}x{} {} -> {}x{} {} ({})", w.name, w.width, w.height,
                                      format_label(w.format), t.width, t.height, format_label(t.format), why));
    }
  for (const auto& [bit, instead] : wants.without_feature)
    if (!f.has(bit)) f.gave_up.push_back(fmt::format("{}: {} ({})", feature_name(bit), instead, why_feature(bit)));
  return f;
}

}  // namespace gpubridge::examples
