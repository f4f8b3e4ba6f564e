#include "gpubridge/draw/context.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace gpubridge::draw {
namespace {

using protocol::Reg;

Result<void> check_image_data(const Image& image, const char* what) {
  if (image.rgba.size() != std::size_t{image.width} * image.height * 4)
    return make_error(fmt::format("{} image data holds {} bytes, not {}x{}x4", what, image.rgba.size(), image.width,
                                  image.height));
  return {};
}

}  // namespace

// The buffers, at creation (no textures yet, so the allocator's advice to release some does not apply).
Result<std::uint32_t> Context::allocate(std::uint64_t bytes, const char* what) {
  auto a = vram_.allocate(bytes);
  if (!a)
    return make_error(fmt::format("not enough video memory for the {} ({} bytes, {} bytes left; the device has {} bytes): "
                                  "use a smaller framebuffer or format, or no depth buffer / double buffering",
                                  what, bytes, vram_.largest_free_block(), sink_->vram_bytes()));
  return *a;
}

const Texture* Context::live(const Texture& texture) const {
  const auto it = textures_.find(texture.id);
  if (it == textures_.end() || it->second.address != texture.address || !(it->second.format == texture.format))
    return nullptr;
  return &it->second;
}

Result<Context> Context::create(CommandSink& sink, const ContextOptions& options) {
  Context c(sink, options);
  auto fb = geometry::fb_format_word(options.width, options.height, options.format);
  if (!fb) return fb.error();
  // The device would clamp the size and raise ERR_BAD_VALUE (docs/protocol.md, FB_FORMAT).
  if (const auto d = sink.device(); options.width > d.max_width || options.height > d.max_height)
    return make_error(fmt::format("framebuffer {}x{} is larger than the device's largest, {}x{}: use a smaller size",
                                  options.width, options.height, d.max_width, d.max_height));
  const std::uint64_t color_bytes = std::uint64_t{options.width} * options.height * protocol::bytes_per_pixel(options.format);
  for (int i = 0; i < (options.double_buffer ? 2 : 1); ++i) {
    auto a = c.allocate(color_bytes, "colour buffer");
    if (!a) return a.error();
    c.color_[i] = *a;
  }
  if (!options.double_buffer) c.color_[1] = c.color_[0];
  if (options.depth_buffer) {
    auto a = c.allocate(std::uint64_t{options.width} * options.height * 4, "depth buffer");
    if (!a) return a.error();
    c.depth_ = *a;
  }
  c.write(Reg::FB_FORMAT, *fb);
  c.write(Reg::FB_DRAW, c.back_buffer());
  if (c.depth_) c.write(Reg::FB_Z, *c.depth_);
  c.reset_scissor();
  if (auto r = c.send_pending(); !r) return r.error();
  return c;
}

void Context::write(protocol::Reg reg, std::uint64_t data) { pending_.push_back(protocol::write_frame(reg, data)); }

Result<void> Context::send_pending() {
  if (pending_.empty()) return {};
  wire_.clear();
  wire_.reserve(pending_.size() * protocol::kFrameBytes);
  for (const auto& f : pending_) protocol::append(wire_, f);
  pending_.clear();
  return sink_->write_frames(protocol::FrameView{wire_});
}

void Context::set_cull(geometry::CullMode mode, geometry::FrontFace front) {
  cull_ = mode;
  front_ = front;
}

Result<void> Context::set_scissor(unsigned x0, unsigned y0, unsigned x1, unsigned y1) {
  auto w = geometry::scissor_word(x0, y0, x1, y1);
  if (!w) return w.error();
  if (*w != scissor_) write(Reg::SCISSOR, *w);
  scissor_ = *w;
  scissor_rect_ = geometry::visible_rect(options_.width, options_.height, x0, y0, x1, y1);
  return {};
}

void Context::reset_scissor() {
  const auto full = *geometry::scissor_word(0, 0, protocol::kMaxFramebufferDim, protocol::kMaxFramebufferDim);
  if (full != scissor_) write(Reg::SCISSOR, full);  // scissor_ starts at 0, so creation writes it
  scissor_ = full;
  scissor_rect_ = geometry::visible_rect(options_.width, options_.height, 0, 0, protocol::kMaxFramebufferDim,
                                         protocol::kMaxFramebufferDim);
}

Result<Texture> Context::create_texture(const Image& image, const TextureOptions& o) {
  Texture t;
  t.format = geometry::TextureFormat{image.width, image.height, o.format, o.wrap_s, o.wrap_t, o.bilinear};
  if (auto w = geometry::tex_fmt_word(t.format); !w) return w.error();
  if (auto r = check_image_data(image, "texture"); !r) return r.error();
  // The allocator's message already says "video memory full: N bytes requested, largest free
  // block M; release textures or use a smaller format".
  auto a = vram_.allocate(std::uint64_t{image.width} * image.height * protocol::bytes_per_pixel(o.format));
  if (!a) return make_error(fmt::format("texture {}x{}: {}", image.width, image.height, a.error().message));
  t.address = *a;
  if (auto r = send_pending(); !r) {  // keep uploads ordered with register writes
    vram_.release(t.address);
    return r.error();
  }
  const auto bytes = device_from_image(o.format, image);
  if (auto r = sink_->upload(t.address, bytes); !r) {
    vram_.release(t.address);
    return r.error();
  }
  t.id = next_texture_id_++;
  textures_.emplace(t.id, t);
  return t;
}

// Why a handle is not live, for bind_texture and update_texture.
static Error stale_handle(const char* what, const Texture& texture) {
  return make_error(fmt::format("{}: texture {} (address 0x{:x}) was released, changed by hand, or not created by this "
                                "context; use the handle create_texture or load_texture returned",
                                what, texture.id, texture.address));
}

Result<void> Context::update_texture(const Texture& handle, const Image& image) {
  const Texture* texture = live(handle);
  if (!texture) return stale_handle("update_texture", handle);
  if (image.width != texture->format.width || image.height != texture->format.height)
    return make_error(fmt::format("update_texture: the image is {}x{} but the texture is {}x{} (updates keep the size; "
                                  "create a new texture for another size)",
                                  image.width, image.height, texture->format.width, texture->format.height));
  if (auto r = check_image_data(image, "update_texture:"); !r) return r;
  if (auto r = send_pending(); !r) return r;  // draws issued so far sample the old contents
  return sink_->upload(texture->address, device_from_image(texture->format.format, image));
}

bool Context::release_texture(Texture& texture) {
  const bool was_live = live(texture);
  if (was_live) {
    if (texture_ && texture_->id == texture.id) texture_.reset();
    textures_.erase(texture.id);
    vram_.release(texture.address);
  }
  texture = Texture{};
  return was_live;
}

Result<Texture> Context::load_texture(const std::filesystem::path& png, const TextureOptions& options) {
  // Refused from the PNG's header when larger than any texture (1024 texels per side).
  auto img = load_png(png, PngLimits{1u << protocol::kMaxTextureLog2, 0, "a texture"});
  if (!img) return img.error();
  auto t = create_texture(*img, options);
  if (!t) return make_error(fmt::format("{}: {}", png.string(), t.error().message));
  return t;
}

Result<void> Context::bind_texture(const Texture& handle) {
  const Texture* texture = live(handle);
  if (!texture) return stale_handle("bind_texture", handle);
  texture_ = *texture;
  return {};
}

Result<void> Context::clear(geometry::Vec4 color) {
  auto c = geometry::color_to_rgba8(color);
  if (!c) return make_error("clear colour: " + c.error().message);
  write(Reg::CLEAR_COLOR, *c);
  write(Reg::CLEAR, 0);
  return {};
}

Result<void> Context::clear_depth(double z) {
  if (!depth_) return make_error("clear_depth: this context has no depth buffer (ContextOptions::depth_buffer)");
  auto v = geometry::depth_to_z24(z);
  if (!v) return make_error("clear_depth: " + v.error().message);
  write(Reg::CLEAR_DEPTH, *v);
  write(Reg::CLEAR_Z, 0);
  return {};
}

Result<void> Context::apply_state(geometry::PipelineOptions& opt) {
  if ((state_.z_test || state_.z_write) && !depth_)
    return make_error("depth test/write requested but this context has no depth buffer (ContextOptions::depth_buffer)");
  geometry::RenderState s = state_;
  s.textured = texture_.has_value();
  const std::uint64_t mode = geometry::tri_mode_word(s);
  if (sent_tri_mode_ != mode) write(Reg::TRI_MODE, mode);
  sent_tri_mode_ = mode;
  opt.cull = cull_;
  opt.front_face = front_;
  opt.textured = s.textured;
  if (options_.skip_invisible) opt.visible = scissor_rect_;
  if (texture_) {
    const std::uint64_t fmt = *geometry::tex_fmt_word(texture_->format);  // validated at creation
    if (sent_tex_base_ != texture_->address) write(Reg::TEX_BASE, texture_->address);
    if (sent_tex_fmt_ != fmt) write(Reg::TEX_FMT, fmt);
    sent_tex_base_ = texture_->address;
    sent_tex_fmt_ = fmt;
    opt.tex = {texture_->format.wrap_s, texture_->format.wrap_t};
    opt.texture_size = std::max(texture_->format.width, texture_->format.height);
  }
  write(Reg::PRIM, static_cast<unsigned>(protocol::PrimType::List));
  return {};
}

Result<void> Context::emit(const Result<void>& r, const geometry::PipelineOptions& opt, std::size_t first_index) {
  if (!r) return make_error(fmt::format("triangle at index {}: {}", first_index, r.error().message));
  for (const auto& t : scratch_) geometry::encode_triangle(t, opt.textured, pending_);
  if (pending_.size() >= options_.batch_frames) return send_pending();
  return {};
}

Result<void> Context::draw_indexed(std::span<const Vertex> vertices, std::span<const std::uint32_t> indices) {
  if (indices.size() % 3 != 0)
    return make_error(fmt::format("draw_indexed: {} indices is not a multiple of 3 (a triangle list)", indices.size()));
  for (std::size_t i = 0; i < indices.size(); ++i)
    if (indices[i] >= vertices.size())
      return make_error(fmt::format("draw_indexed: index {} at position {} is out of range ({} vertices)", indices[i], i,
                                    vertices.size()));
  geometry::PipelineOptions opt;
  if (auto r = apply_state(opt); !r) return r;
  const geometry::Viewport vp = viewport_.value_or(
      geometry::Viewport{0, 0, static_cast<double>(options_.width), static_cast<double>(options_.height)});
  const geometry::Mat4 m = geometry::viewport_matrix(vp) * mvp_;
  transformed_.resize(vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i)
    transformed_[i] = geometry::Vertex{m * geometry::point(vertices[i].position), vertices[i].color, vertices[i].uv};
  for (std::size_t i = 0; i < indices.size(); i += 3) {
    const geometry::Triangle tri{transformed_[indices[i]], transformed_[indices[i + 1]], transformed_[indices[i + 2]]};
    scratch_.clear();
    const auto r = geometry::process_triangle(tri, opt, scratch_, &stats_);
    if (auto sent = emit(r, opt, i); !sent) return sent;
  }
  return {};
}

Result<void> Context::draw_screen(std::span<const geometry::ScreenVertex> vertices) {
  if (vertices.size() % 3 != 0)
    return make_error(fmt::format("draw_screen: {} vertices is not a multiple of 3 (a triangle list)", vertices.size()));
  geometry::PipelineOptions opt;
  if (auto r = apply_state(opt); !r) return r;
  for (std::size_t i = 0; i < vertices.size(); i += 3) {
    for (std::size_t k = i; k < i + 3; ++k)
      if (!(vertices[k].w > 0))
        return make_error(fmt::format("draw_screen: vertex {}: w = {} must be > 0", k, vertices[k].w));
    scratch_.clear();
    const auto r = geometry::process_screen_triangle({vertices[i], vertices[i + 1], vertices[i + 2]}, opt, scratch_,
                                                     &stats_);
    if (auto sent = emit(r, opt, i); !sent) return sent;
  }
  return {};
}

Result<void> Context::swap() {
  write(Reg::FB_DISPLAY, back_buffer());
  if (options_.double_buffer) {
    back_ = 1 - back_;
    write(Reg::FB_DRAW, back_buffer());
  }
  if (auto r = send_pending(); !r) return r;
  if (options_.frames_in_flight == 0) return {};
  return sink_->end_frame(options_.frames_in_flight);
}

Result<void> Context::flush() {
  if (auto r = send_pending(); !r) return r;
  return sink_->flush();
}

Result<Image> Context::read_display() {
  if (auto r = flush(); !r) return r.error();
  const std::uint32_t bytes = options_.width * options_.height * protocol::bytes_per_pixel(options_.format);
  auto data = sink_->readback(front_buffer(), bytes);
  if (!data) return data.error();
  if (data->size() != bytes)
    return make_error(fmt::format("readback returned {} bytes instead of {}", data->size(), bytes));
  return image_from_device(options_.format, options_.width, options_.height, *data);
}

}  // namespace gpubridge::draw
