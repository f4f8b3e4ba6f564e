// Fuzzes the streaming binary trace reader. Properties: no crash/UB; whatever it accepts writes
// back as a trace that reads to the same commands, and survives the text form unchanged.
#include <cstring>

#include "fuzz_check.hpp"
#include "gpubridge/protocol/text_trace.hpp"
#include "gpubridge/protocol/trace.hpp"

using namespace gpubridge::protocol;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto s = read_binary_trace(std::span(data, size), "fuzz.gbt");
  if (!s.ok()) {
    FUZZ_CHECK(s.error().message.rfind("fuzz.gbt: ", 0) == 0);
    return 0;
  }
  auto bytes = write_binary_trace(*s);
  FUZZ_CHECK(bytes.ok());
  auto again = read_binary_trace(*bytes, "again");
  FUZZ_CHECK(again.ok());
  FUZZ_CHECK(again->commands == s->commands);
  auto text = parse_text_trace(write_text_trace(*s), "fuzz.trace", {});
  FUZZ_CHECK(text.ok());
  FUZZ_CHECK(text->commands.size() == s->commands.size());
  for (std::size_t i = 0; i < s->commands.size(); ++i) FUZZ_CHECK(text->commands[i].command == s->commands[i].command);
  return 0;
}
