// Each example's golden frame, rendered on the exact simulator, matches the committed PNG bit
// for bit. On a mismatch the test writes the actual frame and a diff summary naming the pixels.
// Regenerate (only when the renderer legitimately changed):
//   gpubridge-demo goldens --dir examples/golden --write
#include <gtest/gtest.h>

#include <filesystem>

#include "gpubridge/examples/example.hpp"
#include "gpubridge/examples/golden.hpp"

namespace gpubridge::examples {
namespace {

class ExampleGolden : public ::testing::TestWithParam<std::string> {};

TEST_P(ExampleGolden, MatchesCommittedPng) {
  auto ex = make_example(GetParam());
  ASSERT_NE(ex, nullptr);
  auto actual = render_golden_frame(*ex);
  ASSERT_TRUE(actual) << actual.error().message;
  auto golden = load_png(golden_path(GPUBRIDGE_GOLDEN_DIR, GetParam()));
  ASSERT_TRUE(golden) << golden.error().message;
  const auto diff = compare_images(*golden, *actual);
  if (!diff.identical()) {
    std::filesystem::create_directories(GPUBRIDGE_GOLDEN_OUT);
    const auto out = golden_path(GPUBRIDGE_GOLDEN_OUT, GetParam());
    (void)save_png(out, *actual);
    ADD_FAILURE() << GetParam() << ": " << diff.summary() << "\nactual frame written to " << out.string()
                  << "\nif the renderer legitimately changed: gpubridge-demo goldens --dir examples/golden --write";
  }
}

INSTANTIATE_TEST_SUITE_P(AllExamples, ExampleGolden, ::testing::ValuesIn(example_names()),
                         [](const auto& p) { return p.param; });

TEST(ExampleFrames, IdenticalWithSeveralRasteriserThreads) {
  // The goldens are rendered with one thread; banded rendering must give the same bytes.
  sim::DeviceOptions threaded;
  threaded.threads = 3;
  for (const auto& name : example_names()) {
    auto a = make_example(name), b = make_example(name);
    auto ia = render_golden_frame(*a), ib = render_golden_frame(*b, threaded);
    ASSERT_TRUE(ia && ib);
    EXPECT_TRUE(compare_images(*ia, *ib).identical()) << name << ": " << compare_images(*ia, *ib).summary();
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
