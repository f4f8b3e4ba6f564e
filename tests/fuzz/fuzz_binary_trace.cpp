// Fuzzes the streaming binary trace reader. Properties: no crash/UB; whatever it accepts writes
// back as a trace that reads to the same commands, and survives the text form unchanged; a DMC-1
// trace (metadata "device_kind": "dmc1") reads to words that write back to the same words, and
// the spigpu reader refuses it.
#include <algorithm>
#include <cstring>

#include "fuzz_check.hpp"
#include "gpubridge/protocol/text_trace.hpp"
#include "gpubridge/protocol/trace.hpp"

using namespace gpubridge::protocol;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (auto words = read_dmc1_trace(std::span(data, size), "fuzz.gbt"); words.ok()) {
    FUZZ_CHECK(!read_binary_trace(std::span(data, size), "fuzz.gbt").ok());
    std::vector<std::uint8_t> out;
    FUZZ_CHECK(append_trace_header("{\"device_kind\":\"dmc1\"}", out).ok());
    // In messages of at most kMaxPayload bytes, as the daemon's recorder receives them.
    constexpr std::size_t kPerMessage = kMaxPayload / kDmc1WordBytes;
    for (std::size_t at = 0; at < words->size(); at += kPerMessage) {
      std::vector<std::uint8_t> payload;
      append_dmc1_words(std::span(*words).subspan(at, std::min(kPerMessage, words->size() - at)), payload);
      append_trace_message(0, Message{1, Dmc1Words{payload}}, out);
    }
    auto again = read_dmc1_trace(out, "again");
    FUZZ_CHECK(again.ok() && *again == *words);
    return 0;
  } else {
    FUZZ_CHECK(words.error().message.rfind("fuzz.gbt: ", 0) == 0);
  }
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
