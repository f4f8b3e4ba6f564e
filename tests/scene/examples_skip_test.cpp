// Not sending triangles that cannot cover a pixel (ContextOptions::skip_invisible, on by default)
// changes no pixel: every example, on every class of device it has goldens for, renders frames
// 0..kGoldenFrame with and without it into two simulators, and after every swap the whole video
// memory (both colour buffers, the depth buffer, the textures) is byte for byte the same.
#include <gtest/gtest.h>

#include <algorithm>

#include "gpubridge/draw/sim_sink.hpp"
#include "gpubridge/examples/example.hpp"
#include "gpubridge/examples/golden.hpp"

namespace gpubridge::examples {
namespace {

struct Rendering {
  std::unique_ptr<Example> example;
  std::unique_ptr<draw::SimulatorSink> sink;
  std::optional<draw::Context> ctx;
};

Rendering start(const std::string& name, const GoldenClass& cls, bool skip) {
  Rendering r;
  r.example = make_example(name);
  EXPECT_TRUE(configure(*r.example, cls.device));
  auto sink = draw::SimulatorSink::create(cls.device.simulator_options());
  EXPECT_TRUE(sink);
  r.sink = std::move(*sink);
  auto options = r.example->options();
  options.skip_invisible = skip;
  auto ctx = draw::Context::create(*r.sink, options);
  EXPECT_TRUE(ctx) << ctx.error().message;
  r.ctx.emplace(std::move(*ctx));
  EXPECT_TRUE(r.example->setup(*r.ctx));
  return r;
}

class ExampleSkip : public ::testing::TestWithParam<std::string> {};

TEST_P(ExampleSkip, VideoMemoryIsTheSameWithAndWithoutSendingInvisibleTriangles) {
  for (const auto& cls : golden_classes()) {
    SCOPED_TRACE(cls.name);
    Rendering skipping = start(GetParam(), cls, true), sending = start(GetParam(), cls, false);
    ASSERT_TRUE(skipping.ctx && sending.ctx);
    for (unsigned n = 0; n <= kGoldenFrame; ++n) {
      for (Rendering* r : {&skipping, &sending}) {
        ASSERT_TRUE(r->example->frame(*r->ctx, n));
        ASSERT_TRUE(r->ctx->swap());
        ASSERT_TRUE(r->ctx->flush());
      }
      const auto a = skipping.sink->backend().device().memory(), b = sending.sink->backend().device().memory();
      ASSERT_EQ(a.size(), b.size());
      const auto diff = std::mismatch(a.begin(), a.end(), b.begin());
      ASSERT_TRUE(diff.first == a.end()) << "frame " << n << ": video memory differs at byte " << (diff.first - a.begin());
    }
    EXPECT_EQ(skipping.sink->backend().device().errors(), 0u);
    EXPECT_EQ(sending.sink->backend().device().errors(), 0u);
    // Both saw the same triangles; only the skipping one left some out, and sent that many fewer.
    const auto& s = skipping.ctx->stats();
    const auto& t = sending.ctx->stats();
    EXPECT_EQ(s.input, t.input);
    EXPECT_EQ(t.outside, 0u);
    EXPECT_EQ(s.emitted + s.outside, t.emitted);
    if (GetParam() == "terrain") {
      EXPECT_GT(s.outside * 3, s.emitted * 2);  // about as much of the terrain is beside the screen as on it
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllExamples, ExampleSkip, ::testing::ValuesIn(example_names()), [](const auto& p) {
  std::string n = p.param;
  std::replace(n.begin(), n.end(), '-', '_');
  return n;
});

}  // namespace
}  // namespace gpubridge::examples
