// Every RTL golden, bit for bit, every frame, at several thread counts; the frame picture matches
// the golden PNGs (orientation and channel expansion); the timing model is within 1% of the RTL's
// cycle counts.
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "gpubridge/common/image.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "golden_data.hpp"

namespace gpubridge::dmc1::test {
namespace {

struct Rendered {
  std::vector<std::uint16_t> pixels;  // all frames back to back
  std::vector<std::uint64_t> cycles;
};

Rendered render(const std::string& name, unsigned threads, std::size_t chunk = 0) {
  DeviceOptions opt;
  opt.threads = threads;
  auto dev = Device::create(opt, golden_textures(), golden_palette());
  EXPECT_TRUE(dev.ok());
  Rendered out;
  (*dev)->set_frame_callback([&](const Frame& f) {
    EXPECT_EQ(f.number, out.cycles.size());
    out.pixels.insert(out.pixels.end(), f.rgb565.begin(), f.rgb565.end());
    out.cycles.push_back(f.gpu_cycles);
  });
  const auto words = golden_stream(name);
  if (chunk == 0) {
    (*dev)->submit(words);
  } else {  // the way a socket delivers it: arbitrary pieces
    for (std::size_t i = 0; i < words.size(); i += chunk)
      (*dev)->submit(std::span(words).subspan(i, std::min(chunk, words.size() - i)));
  }
  (*dev)->flush();
  return out;
}

// Where the first difference is, for a readable failure.
std::string first_difference(const std::vector<std::uint16_t>& got, const std::vector<std::uint16_t>& want) {
  for (std::size_t i = 0; i < std::min(got.size(), want.size()); ++i)
    if (got[i] != want[i]) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "frame %zu column %zu row %zu: got %04x, golden %04x", i / kFramePixels,
                    i / kRows % kColumns, i % kRows, got[i], want[i]);
      return buf;
    }
  return got.size() == want.size() ? "none" : "sizes differ";
}

class Golden : public ::testing::TestWithParam<const char*> {};

TEST_P(Golden, BitExactAtOneTwoAndThreeThreads) {
  const auto want = golden_pixels(GetParam());
  ASSERT_EQ(want.size() % kFramePixels, 0u);
  for (unsigned threads : {1u, 2u, 3u}) {
    const Rendered got = render(GetParam(), threads);
    ASSERT_EQ(got.pixels.size(), want.size()) << threads << " thread(s)";
    EXPECT_TRUE(got.pixels == want) << threads << " thread(s): " << first_difference(got.pixels, want);
  }
}

TEST_P(Golden, BitExactWhenTheStreamArrivesInPieces) {
  const auto want = golden_pixels(GetParam());
  const Rendered got = render(GetParam(), 2, 97);  // 97 words: pieces cut commands' columns anywhere
  EXPECT_TRUE(got.pixels == want) << first_difference(got.pixels, want);
}

TEST_P(Golden, PictureMatchesTheGoldenPng) {
  const Rendered got = render(GetParam(), 1);
  ASSERT_GE(got.pixels.size(), kFramePixels);
  const auto png = load_png(kDataDir / "golden" / (std::string(GetParam()) + ".f0.png"));
  ASSERT_TRUE(png.ok()) << png.error().message;
  const Image mine = frame_image(std::span(got.pixels).first(kFramePixels));
  ASSERT_EQ(mine.width, png->width);
  ASSERT_EQ(mine.height, png->height);
  EXPECT_TRUE(mine == *png);
}

TEST_P(Golden, TimingWithinOnePercentOfTheRtl) {
  const auto want = golden_cycles(GetParam());
  const Rendered got = render(GetParam(), 1);
  ASSERT_EQ(got.cycles.size(), want.size());
  for (std::size_t f = 0; f < want.size(); ++f) {
    const double err = (static_cast<double>(got.cycles[f]) - static_cast<double>(want[f])) / static_cast<double>(want[f]);
    EXPECT_LT(std::fabs(err), 0.01) << "frame " << f << ": predicted " << got.cycles[f] << ", RTL " << want[f];
  }
}

INSTANTIATE_TEST_SUITE_P(Dmc1, Golden, ::testing::ValuesIn(kGoldenStreams));

}  // namespace
}  // namespace gpubridge::dmc1::test
