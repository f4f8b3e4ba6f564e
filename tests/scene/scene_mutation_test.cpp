// Hostile scene files: thousands of mutated versions of the example scenes (bytes flipped,
// numbers replaced by extreme values, truncations) must each either load and convert, or fail
// with an error naming the file — never crash, hang or trip the sanitizers.
#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "gpubridge/scene/scene.hpp"

namespace gpubridge::scene {
namespace {

std::string read_text(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(SceneMutation, MutatedScenesLoadOrFailCleanly) {
  std::mt19937_64 rng(2024);
  static const char* kReplacements[] = {"1e308", "-1e308", "1e999", "0", "-0", "1e-320", "4294967296", "-1",
                                        "2048", "3.5", "null", "\"x\"", "[]", "{}", "true", "1e7"};
  std::size_t loaded = 0, rejected = 0;
  for (const auto& entry : std::filesystem::directory_iterator(GPUBRIDGE_EXAMPLE_SCENES)) {
    if (entry.path().extension() != ".json") continue;
    const std::string original = read_text(entry.path());
    for (int n = 0; n < 300; ++n) {
      std::string text = original;
      const int kind = n % 3;
      std::uniform_int_distribution<std::size_t> pos(0, text.size() - 1);
      if (kind == 0) {
        text[pos(rng)] = static_cast<char>(rng() & 0xFF);  // a random byte
      } else if (kind == 1) {
        // Replace one number with an extreme or ill-typed value.
        std::size_t at = pos(rng);
        while (at < text.size() && !(std::isdigit(static_cast<unsigned char>(text[at])))) ++at;
        if (at >= text.size()) continue;
        std::size_t end = at;
        while (end < text.size() && (std::isdigit(static_cast<unsigned char>(text[end])) || text[end] == '.')) ++end;
        text.replace(at, end - at, kReplacements[rng() % std::size(kReplacements)]);
      } else {
        text.resize(pos(rng));  // truncated file
      }
      auto s = parse_scene(text, "mutant.json", entry.path().parent_path());
      if (s) {
        BuildOptions o;
        o.vram_bytes = 4u << 20;
        auto b = build_commands(*s, o);
        if (b) {
          ++loaded;
          continue;
        }
        EXPECT_EQ(b.error().message.rfind("mutant.json: ", 0), 0u) << b.error().message;
      } else {
        EXPECT_EQ(s.error().message.rfind("mutant.json: ", 0), 0u) << s.error().message;
      }
      ++rejected;
    }
  }
  // Both outcomes occur (the mutations are neither all harmless nor all fatal).
  EXPECT_GT(loaded, 100u);
  EXPECT_GT(rejected, 100u);
}

}  // namespace
}  // namespace gpubridge::scene
