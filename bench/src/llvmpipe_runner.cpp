// llvmpipe side of the bench (see llvmpipe_runner.hpp).
#include "llvmpipe_runner.hpp"

#include <malloc.h>

#include <chrono>

#include <nlohmann/json.hpp>

#include "gpubridge/accuracy/texel_probe.hpp"
#include "gpubridge/bench/llvmpipe_peer.hpp"

namespace gpubridge::bench {
namespace {

std::vector<GlVertex> vertices_of(const Scene& s, std::size_t count) {
  std::vector<GlVertex> v(std::min(count, s.triangles.size()) * 3);
  for (std::size_t i = 0; i * 3 < v.size(); ++i) to_gl(s.triangles[i], &v[i * 3]);
  return v;
}

GlDrawState throughput_state(const Scene& s) {
  GlDrawState st;
  if (s.state.z_test) {
    st.depth = s.state.z_func == protocol::DepthFunc::LessEqual ? GlDrawState::Depth::LessEqual
               : s.state.z_func == protocol::DepthFunc::Always  ? GlDrawState::Depth::Always
                                                                : GlDrawState::Depth::Less;
  }
  st.blend = s.state.blend == protocol::BlendMode::Alpha ? GlDrawState::Blend::Alpha
             : s.state.blend == protocol::BlendMode::Add ? GlDrawState::Blend::Add
                                                         : GlDrawState::Blend::Off;
  st.output = s.textured ? GlDrawState::Output::TextureDecal : GlDrawState::Output::Color;
  return st;
}

nlohmann::json error_json(const ErrorStats& e) {
  return {{"pixels", e.pixels}, {"coverage_mismatches", e.coverage_mismatches}, {"colour_max", e.color_max},
          {"colour_mean", e.color_mean}, {"z_max", e.z_max}, {"texel_max", e.texel_max},
          {"texel_mean", e.texel_mean}, {"has_colour", e.has_color}, {"has_texel", e.has_texel}};
}
ErrorStats error_from_json(const nlohmann::json& j) {
  ErrorStats e;
  e.pixels = j.at("pixels");
  e.coverage_mismatches = j.at("coverage_mismatches");
  e.color_max = j.at("colour_max");
  e.color_mean = j.at("colour_mean");
  e.z_max = j.at("z_max");
  e.texel_max = j.at("texel_max");
  e.texel_mean = j.at("texel_mean");
  e.has_color = j.at("has_colour");
  e.has_texel = j.at("has_texel");
  return e;
}

ErrorStats llvmpipe_error(LlvmpipePeer& peer, const Scene& s, const ReferenceFrame& ref) {
  auto verts = vertices_of(s, s.error_subset);
  RenderedFrame got;
  // Hit counts: additive blending of a flat red = 1/255 (exact in RGBA8).
  peer.set_vertices(verts, GlDrawState::Output::FlatColor);
  peer.render({.depth = GlDrawState::Depth::Off,
               .blend = GlDrawState::Blend::Add,
               .output = GlDrawState::Output::FlatColor,
               .flat_rgba = {1.0f / 255.0f, 0.0f, 0.0f, 0.0f}});
  const auto counts = peer.read_color();
  got.count.resize(counts.size() / 4);
  for (std::size_t i = 0; i < got.count.size(); ++i) got.count[i] = counts[i * 4];
  // Values: depth ALWAYS + write, no blending, the last triangle owns each pixel; drawn by the
  // program the scene's throughput run uses, so Z comes from that program's vertex stage.
  const auto values = s.textured ? GlDrawState::Output::TextureDecal : GlDrawState::Output::Color;
  peer.set_vertices(verts, values);
  peer.render({.depth = GlDrawState::Depth::Always, .output = values});
  got.rgba = peer.read_color();
  got.depth = peer.read_depth24();
  if (s.textured) {
    peer.set_vertices(verts, GlDrawState::Output::TexelCoordinates);
    peer.render({.depth = GlDrawState::Depth::Always, .output = GlDrawState::Output::TexelCoordinates});
    got.texel_coordinates = peer.read_texel_coordinates();
  }
  return measure_error(s, ref, got);
}

}  // namespace

Result<LlvmpipeResult> run_llvmpipe(const std::vector<Scene>& scenes, const std::vector<ReferenceFrame>& refs,
                                    unsigned lp_threads, const FrameBudget& budget, bool measure) {
  auto text = run_isolated(lp_threads, [&]() -> Result<std::string> {
    // The malloc thresholds of bench/llvmpipe/minimal_gl.c (see there): llvmpipe frees and
    // reallocates its binned scene every frame, and whether glibc trims and re-faults it each time
    // must not depend on what this process allocated before.
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 64 << 20);
    auto peer_r = LlvmpipePeer::create(640, 480);
    if (!peer_r) return peer_r.error();
    auto& peer = **peer_r;
    const auto tex = accuracy::make_probe_texture(kTextureLog2, kTextureLog2);
    peer.set_texture(tex, 1u << kTextureLog2, 1u << kTextureLog2, true);
    nlohmann::json out{{"renderer", peer.renderer()}, {"scenes", nlohmann::json::array()}};
    for (std::size_t k = 0; k < scenes.size(); ++k) {
      const Scene& s = scenes[k];
      if (s.width != 640 || s.height != 480) return make_error("llvmpipe peer: scenes must be 640x480");
      const GlDrawState st = throughput_state(s);
      peer.set_vertices(vertices_of(s, s.triangles.size()), st.output);  // outside the timed frames
      const double best = best_frame_seconds(budget, [&] {
        const auto t0 = std::chrono::steady_clock::now();
        peer.render(st);
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      });
      unsigned long long sum = 0;  // compared with the minimal GL program's frame (same picture?)
      for (std::uint8_t b : peer.read_color()) sum += b;
      nlohmann::json js{{"seconds", best}, {"pixel_sum", sum}};
      if (measure) js["error"] = error_json(llvmpipe_error(peer, s, refs[k]));
      out["scenes"].push_back(js);
    }
    return out.dump();
  });
  if (!text) return text.error();
  LlvmpipeResult res;
  try {
    const auto j = nlohmann::json::parse(*text);
    res.renderer = j.at("renderer");
    for (const auto& s : j.at("scenes")) {
      res.seconds.push_back(s.at("seconds"));
      res.pixel_sum.push_back(s.at("pixel_sum"));
      res.error.push_back(s.contains("error") ? std::optional(error_from_json(s.at("error"))) : std::nullopt);
    }
  } catch (const std::exception& e) {
    return make_error(std::string("llvmpipe peer: unreadable result from the child process: ") + e.what());
  }
  return res;
}

}  // namespace gpubridge::bench
