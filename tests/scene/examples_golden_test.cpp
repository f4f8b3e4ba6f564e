// Each example's golden frame, rendered on the exact simulator for each class of device it fits
// itself to (large, up5k, up5k-min), matches the committed PNG bit for bit. On a mismatch the test
// writes the actual frame and a diff summary naming the pixels. Regenerate (only when the
// renderer legitimately changed):
//   gpubridge-demo goldens --dir examples/golden --write
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "gpubridge/examples/example.hpp"
#include "gpubridge/examples/golden.hpp"

namespace gpubridge::examples {
namespace {

struct Case {
  std::string cls, example;
};

std::vector<Case> all_cases() {
  std::vector<Case> out;
  for (const auto& c : golden_classes())
    for (const auto& e : example_names()) out.push_back({c.name, e});
  return out;
}

class ExampleGolden : public ::testing::TestWithParam<Case> {};

TEST_P(ExampleGolden, MatchesCommittedPng) {
  const auto& [cls_name, name] = GetParam();
  const GoldenClass* cls = find_golden_class(cls_name);
  ASSERT_NE(cls, nullptr);
  auto ex = make_example(name);
  ASSERT_NE(ex, nullptr);
  auto frames = render_golden_frames(*ex, *cls);
  ASSERT_TRUE(frames) << frames.error().message;
  ASSERT_EQ(frames->size(), ex->golden_frames().size());
  for (const auto& [frame, actual] : *frames) {
    auto golden = load_png(golden_path(GPUBRIDGE_GOLDEN_DIR, *cls, name, frame));
    ASSERT_TRUE(golden) << golden.error().message;
    const auto diff = compare_images(*golden, actual);
    if (!diff.identical()) {
      const auto out = golden_path(GPUBRIDGE_GOLDEN_OUT, *cls, name, frame);
      std::filesystem::create_directories(out.parent_path());
      (void)save_png(out, actual);
      ADD_FAILURE() << cls_name << " " << name << " frame " << frame << ": " << diff.summary()
                    << "\nactual frame written to " << out.string()
                    << "\nif the renderer legitimately changed: gpubridge-demo goldens --dir examples/golden --write";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(AllExamples, ExampleGolden, ::testing::ValuesIn(all_cases()), [](const auto& p) {
  std::string n = p.param.cls + "_" + p.param.example;
  for (auto& c : n)
    if (c == '-') c = '_';
  return n;
});

// The temporal dither's golden frames differ from each other (the pattern moves every frame) and
// from the ordered dither's frame.
TEST(ExampleFrames, TemporalDitherFramesDifferFromEachOtherAndFromTheOrderedDither) {
  auto temporal = make_example("torus-temporal"), ordered = make_example("torus");
  ASSERT_TRUE(temporal && ordered);
  const GoldenClass* large = find_golden_class("large");
  ASSERT_NE(large, nullptr);
  auto frames = render_golden_frames(*temporal, *large);
  auto still = render_golden_frame(*ordered, *large);
  ASSERT_TRUE(frames && still);
  ASSERT_EQ(frames->size(), 4u);
  EXPECT_FALSE(compare_images(*still, frames->front().image).identical());
  for (std::size_t i = 1; i < frames->size(); ++i)
    EXPECT_FALSE(compare_images((*frames)[i - 1].image, (*frames)[i].image).identical()) << (*frames)[i].frame;
}

TEST(ExampleGolden, LargeClassIsWhatEveryExampleWants) {
  // The large goldens are the examples as written: nothing given up on the default simulator,
  // and a freshly made example is configured that way before anyone fits it.
  const GoldenClass* large = find_golden_class("large");
  ASSERT_NE(large, nullptr);
  for (auto& ex : make_examples()) {
    auto f = configure(*ex, large->device);
    ASSERT_TRUE(f) << f.error().message;
    EXPECT_TRUE(f->gave_up.empty()) << ex->info().name << " gave up " << f->gave_up.front();
    EXPECT_EQ(make_example(ex->info().name)->config().summary(), f->summary());
  }
}

TEST(ExampleGolden, SmallClassesGiveSomethingUp) {
  // The up5k goldens show a different configuration from the large ones for every example
  // (otherwise they would not cover the small device).
  for (const char* cls : {"up5k", "up5k-min"})
    for (auto& ex : make_examples()) {
      auto f = configure(*ex, find_golden_class(cls)->device);
      ASSERT_TRUE(f) << f.error().message;
      EXPECT_FALSE(f->gave_up.empty()) << cls << " " << ex->info().name << ": " << f->summary();
      EXPECT_LE(f->vram_bytes, 128u * 1024) << cls << " " << ex->info().name;
    }
}

TEST(ExampleFrames, IdenticalWithSeveralRasteriserThreads) {
  // The goldens are rendered with one thread; banded rendering must give the same bytes.
  for (const auto& cls : golden_classes())
    for (const auto& name : example_names()) {
      auto a = make_example(name), b = make_example(name);
      auto fa = render_golden_frames(*a, cls), fb = render_golden_frames(*b, cls, 3);
      ASSERT_TRUE(fa && fb);
      ASSERT_EQ(fa->size(), fb->size());
      for (std::size_t i = 0; i < fa->size(); ++i)
        EXPECT_TRUE(compare_images((*fa)[i].image, (*fb)[i].image).identical())
            << cls.name << " " << name << " frame " << (*fa)[i].frame << ": "
            << compare_images((*fa)[i].image, (*fb)[i].image).summary();
    }
}

TEST(ImageDiff, ReportsDifferingPixels) {
  Image a;
  a.width = 4;
  a.height = 2;
  a.rgba.assign(4 * 2 * 4, 10);
  Image b = a;
  b.pixel(3, 1)[2] = 50;
  const auto d = compare_images(a, b);
  EXPECT_FALSE(d.identical());
  EXPECT_EQ(d.differing_pixels, 1u);
  EXPECT_EQ(d.max_difference, 40);
  ASSERT_EQ(d.first_differences.size(), 1u);
  EXPECT_EQ(d.first_differences[0], (std::pair<unsigned, unsigned>{3, 1}));
  EXPECT_NE(d.summary().find("(3, 1)"), std::string::npos);
  b.width = 2;
  EXPECT_TRUE(compare_images(a, b).size_mismatch);
}

}  // namespace
}  // namespace gpubridge::examples
