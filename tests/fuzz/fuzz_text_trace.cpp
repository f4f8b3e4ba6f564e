// Fuzzes the text trace reader (with an in-memory asset loader). Properties: no crash/UB; errors
// carry FILE:LINE:COL; accepted traces reach the canonical text form in one step (writing,
// reading and writing again changes nothing) and survive the binary form.
#include <string_view>

#include "fuzz_check.hpp"
#include "gpubridge/protocol/text_trace.hpp"
#include "gpubridge/protocol/trace.hpp"

using namespace gpubridge::protocol;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  // Assets are bytes derived from the path, or an error for paths starting with "x".
  AssetLoader loader = [](const TraceAsset& a) -> gpubridge::Result<std::vector<std::uint8_t>> {
    if (!a.path.empty() && a.path[0] == 'x') return gpubridge::make_error(a.path + ": no such file");
    return std::vector<std::uint8_t>(a.path.begin(), a.path.end());
  };
  auto s = parse_text_trace(text, "f.trace", loader);
  if (!s.ok()) {
    FUZZ_CHECK(s.error().message.rfind("f.trace:", 0) == 0);
    return 0;
  }
  const std::string canonical = write_text_trace(*s);
  auto back = parse_text_trace(canonical, "canonical.trace", {});
  FUZZ_CHECK(back.ok());
  FUZZ_CHECK(back->commands == s->commands);
  FUZZ_CHECK(write_text_trace(*back) == canonical);
  auto bytes = write_binary_trace(*s);
  FUZZ_CHECK(bytes.ok());
  auto bin = read_binary_trace(*bytes, "b");
  FUZZ_CHECK(bin.ok());
  FUZZ_CHECK(bin->commands == s->commands);
  return 0;
}
