#include "examples_internal.hpp"

namespace gpubridge::examples {

draw::ContextOptions Example::options() const {
  draw::ContextOptions o;
  o.width = 320;
  o.height = 240;
  return o;
}

std::vector<std::unique_ptr<Example>> make_examples() {
  std::vector<std::unique_ptr<Example>> all;
  all.push_back(make_tetrahedron());
  all.push_back(make_terrain());
  all.push_back(make_torus());
  all.push_back(make_voxels());
  all.push_back(make_room());
  all.push_back(make_cubes());
  all.push_back(make_lightmap());
  return all;
}

std::unique_ptr<Example> make_example(std::string_view name) {
  for (auto& e : make_examples())
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
