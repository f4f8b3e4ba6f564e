// The library's closed-form, multi-threaded renderer against the event-level reference model on
// random streams of every command kind, several frames long (state carried across frames), fed
// whole and in pieces.
#include <random>

#include <gtest/gtest.h>

#include "gpubridge/dmc1/command.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "gpubridge/examples/dmc1_level.hpp"
#include "golden_data.hpp"
#include "reference_model.hpp"

namespace gpubridge::dmc1::test {
namespace {

// Random in-contract commands: every column draws at least one span; planes never use texture 0.
std::vector<std::uint64_t> random_stream(std::uint32_t seed, unsigned columns) {
  std::mt19937 rng(seed);
  auto below = [&](unsigned n) { return static_cast<unsigned>(rng() % n); };
  auto any_bits = [&](unsigned bits) { return static_cast<std::int64_t>(rng() & ((1u << bits) - 1)); };
  std::vector<std::uint64_t> s;
  for (unsigned c = 0; c < columns; ++c) {
    if (below(3)) s.push_back(wall({0, below(8) ? 239u : below(256), below(16), 0}, below(4) ? 0xFFFF : below(65536), 0, 0));
    else s.push_back(wall({below(240), 239, below(16), 0}, static_cast<std::uint16_t>(below(65536)), 0, 0));
    const unsigned n = 1 + below(9);
    for (unsigned i = 0; i < n; ++i) {
      const unsigned a = below(240), b = below(4) ? a + below(60) : below(256);  // some dropped, some end > 239
      const SpanRows rows{a, b, below(16), 1 + below(699)};
      switch (below(10)) {
        case 0: s.push_back(uv_offset(static_cast<std::int32_t>(any_bits(24)), static_cast<std::int32_t>(any_bits(24)), below(3) == 0)); break;
        case 1: s.push_back(plane_a(static_cast<int>(any_bits(10)), static_cast<int>(any_bits(10)), static_cast<int>(any_bits(10)),
                                    static_cast<int>(any_bits(14)), static_cast<int>(any_bits(14)))); break;
        case 2: s.push_back(ray_cs(static_cast<int>(any_bits(14)), static_cast<int>(any_bits(14)))); break;
        case 3: s.push_back(view_z(static_cast<std::int16_t>(any_bits(16)))); break;
        case 4: s.push_back(terrain({a, below(256), below(16), below(4) ? 663u : 1 + below(699)}, below(1200), below(2048), below(2))); break;
        case 5: case 6:
          s.push_back(plane(rows, static_cast<std::int16_t>(any_bits(16)), static_cast<std::int16_t>(below(4) ? any_bits(16) : any_bits(3))));
          break;
        default: s.push_back(wall(rows, static_cast<std::uint16_t>(below(3) ? below(0x3000) : below(65536)),
                                  static_cast<std::uint8_t>(below(256)), static_cast<std::uint8_t>(below(256))));
      }
    }
    s.push_back(end_of_column());
  }
  return s;
}

std::vector<std::uint16_t> device_output(const std::vector<std::uint64_t>& words, unsigned threads, std::size_t chunk,
                                         std::uint8_t* picked_height = nullptr) {
  DeviceOptions opt;
  opt.threads = threads;
  auto dev = Device::create(opt, golden_textures(), golden_palette());
  EXPECT_TRUE(dev.ok());
  std::vector<std::uint16_t> out;
  (*dev)->set_frame_callback([&](const Frame& f) { out.insert(out.end(), f.rgb565.begin(), f.rgb565.end()); });
  for (std::size_t i = 0; i < words.size(); i += chunk)
    (*dev)->submit(std::span(words).subspan(i, std::min(chunk, words.size() - i)));
  (*dev)->flush();
  // Columns of an unfinished frame are on the screen.
  const unsigned partial = (*dev)->column();
  const auto screen = (*dev)->screen();
  out.insert(out.end(), screen.begin(), screen.begin() + std::size_t{partial} * kRows);
  if (picked_height) *picked_height = (*dev)->picked_height();
  return out;
}

TEST(Equivalence, RandomStreamsMatchTheEventLevelModel) {
  for (std::uint32_t seed = 1; seed <= 6; ++seed) {
    const auto words = random_stream(seed, 2 * kColumns + 57);  // two frames and part of a third
    ReferenceModel ref(golden_textures(), golden_palette());
    ref.run(words);
    const std::size_t chunk = seed % 2 ? words.size() : 1 + seed * 37;
    for (unsigned threads : {1u, 2u, 5u}) {
      std::uint8_t picked = 0;
      const auto got = device_output(words, threads, chunk, &picked);
      // The height the last picking terrain span latched (the SOC's user_data 23:16).
      EXPECT_EQ(picked, ref.picked_height()) << "seed " << seed << ", " << threads << " thread(s)";
      ASSERT_EQ(got.size(), ref.output().size()) << "seed " << seed;
      std::size_t bad = 0, first = 0;
      for (std::size_t i = 0; i < got.size(); ++i)
        if (got[i] != ref.output()[i] && bad++ == 0) first = i;
      EXPECT_EQ(bad, 0u) << "seed " << seed << ", " << threads << " thread(s): first difference at column " << first / kRows
                         << " row " << first % kRows;
    }
  }
}

// The example client's frames: coherent, every span kind, PLANE_A per span, terrain at the window.
TEST(Equivalence, TheExampleLevelMatchesTheEventLevelModel) {
  const auto words = examples::dmc1_level::path_commands(examples::dmc1_level::hall(), 6);
  ReferenceModel ref(golden_textures(), golden_palette());
  ref.run(words);
  for (unsigned threads : {1u, 2u}) EXPECT_TRUE(device_output(words, threads, words.size()) == ref.output()) << threads;
}

// Every level frame stays inside what the RTL goldens cover: each column draws (its sky filler
// first), wall depths keep their v step exact (below 0x4000), planes never use texture 0.
TEST(ExampleLevel, FramesStayInContract) {
  const auto lv = examples::dmc1_level::hall();
  for (unsigned f = 0; f < examples::dmc1_level::kPathFrames; f += 4) {
    const auto words = examples::dmc1_level::frame_commands(lv, examples::dmc1_level::camera_path(lv, f / 64.0));
    unsigned columns = 0, spans_in_column = 0;
    for (const std::uint64_t w : words) {
      const CommandKind k = kind_of(w);
      if (k == CommandKind::EndOfColumn) {
        EXPECT_GT(spans_in_column, 0u) << "frame " << f << " column " << columns;
        ++columns;
        spans_in_column = 0;
        continue;
      }
      if (!is_span(k)) continue;
      ++spans_in_column;
      const unsigned start = (w >> 10) & 255, end = (w >> 18) & 255, tid = w & 1023;
      EXPECT_LE(start, end) << describe(w);
      EXPECT_LT(end, kRows) << describe(w);
      if (k == CommandKind::Plane) {
        EXPECT_NE(tid, 0u) << describe(w);
      }
      if (k == CommandKind::Wall && tid != 0) {
        EXPECT_LT((w >> 32) & 0xFFFF, 0x4000u) << describe(w);
      }
    }
    EXPECT_EQ(columns, kColumns);
  }
}

TEST(Equivalence, GoldenStreamsMatchTheEventLevelModel) {
  for (const char* name : kGoldenStreams) {
    ReferenceModel ref(golden_textures(), golden_palette());
    ref.run(golden_stream(name));
    EXPECT_TRUE(ref.output() == golden_pixels(name)) << name;
  }
}

}  // namespace
}  // namespace gpubridge::dmc1::test
