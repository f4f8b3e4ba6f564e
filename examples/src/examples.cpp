#include "examples_internal.hpp"

namespace gpubridge::examples {

const Fit& Example::config() const {
  if (!fit_) {
    const DeviceCaps large;
    auto f = fit(wants(large.features), large);
    if (f) {
      fit_ = std::move(*f);
    } else {
      // Only an example wanting more than the default simulator holds gets here; its context
      // creation then says what did not fit.
      Fit wanted;
      const auto w = wants(large.features);
      wanted.device = large;
      wanted.features = large.features;
      wanted.context.width = w.width;
      wanted.context.height = w.height;
      wanted.context.format = w.format;
      fit_ = std::move(wanted);
    }
  }
  return *fit_;
}

Result<void> begin_frame(draw::Context& ctx, const Fit& fit, geometry::Vec4 clear_color) {
  if (auto r = ctx.clear(clear_color); !r) return r;
  ctx.state() = {};
  if (!fit.painter()) {
    if (auto r = ctx.clear_depth(1.0); !r) return r;
    ctx.state().z_test = ctx.state().z_write = true;
  }
  ctx.state().dither = fit.dither;
  return {};
}

Result<Fit> configure(Example& ex, const DeviceCaps& device, const FitRequest& request) {
  const std::uint16_t features = device.features & static_cast<std::uint16_t>(~request.without);
  auto f = fit(ex.wants(features), device, request);
  if (!f) return make_error(ex.info().name + ": " + f.error().message);
  ex.configure(*f);
  return f;
}

std::vector<unsigned> Example::golden_frames() const { return {kGoldenFrame}; }

std::vector<std::unique_ptr<Example>> make_examples(const ExampleParams& params) {
  std::vector<std::unique_ptr<Example>> all;
  all.push_back(make_tetrahedron());
  all.push_back(make_terrain());
  all.push_back(make_torus());
  all.push_back(make_torus({.temporal = true}));
  all.push_back(make_torus({.cordic_iterations = params.cordic_iterations}));
  all.push_back(make_voxels());
  all.push_back(make_room());
  all.push_back(make_cubes());
  all.push_back(make_lightmap());
  return all;
}

std::unique_ptr<Example> make_example(std::string_view name, const ExampleParams& params) {
  for (auto& e : make_examples(params))
    if (e->info().name == name) return std::move(e);
  return nullptr;
}

std::vector<std::string> example_names() {
  std::vector<std::string> out;
  for (const auto& e : make_examples()) out.push_back(e->info().name);
  return out;
}

Result<void> run_frames(Example& ex, draw::Context& ctx, unsigned first, unsigned count,
                        const std::function<Result<void>(unsigned)>& after_swap) {
  if (auto r = ex.setup(ctx); !r) return make_error(ex.info().name + ": setup: " + r.error().message);
  for (unsigned n = first; n < first + count; ++n) {
    if (auto r = ex.frame(ctx, n); !r) return make_error(ex.info().name + ": frame " + std::to_string(n) + ": " + r.error().message);
    if (auto r = ctx.swap(); !r) return r;
    if (after_swap)
      if (auto r = after_swap(n); !r) return r;
  }
  return {};
}

}  // namespace gpubridge::examples
