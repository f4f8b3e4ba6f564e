// Fuzzes the DMC-1 stream parsers (.dmc1 text and tinygpus timestamp,b0..b7 lines) and runs what
// they accept on the DMC-1. Properties: no crash/UB on any input, in the parsers or anywhere in the
// simulator (every 64-bit word is a command); errors carry NAME:LINE; accepted streams survive
// format-then-parse unchanged; the output does not depend on the thread count.
#include <memory>
#include <string_view>
#include <vector>

#include "fuzz_check.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "gpubridge/dmc1/stream.hpp"

using namespace gpubridge::dmc1;

namespace {

// A small texture image with headers pointing anywhere (the first texel bytes double as headers).
std::shared_ptr<const TextureMemory> textures() {
  static const auto mem = [] {
    std::vector<std::uint8_t> image(64 << 10);
    for (std::size_t i = 0; i < image.size(); ++i) image[i] = static_cast<std::uint8_t>(i * 131 + (i >> 7) * 17);
    return *TextureMemory::from_image(image);
  }();
  return mem;
}

// One device per thread count for every input, back to its reset state each time. Both see the
// same inputs in the same order, so their screens (the panel keeps columns across a reset) agree
// as long as the thread count changes nothing.
std::vector<std::uint16_t> run(std::span<const std::uint64_t> words, unsigned threads) {
  static const auto devices = [] {
    Palette p;
    for (unsigned i = 0; i < 256; ++i) p.set(i, static_cast<std::uint8_t>(i & 63), static_cast<std::uint8_t>((i >> 2) & 63), 63);
    std::vector<std::unique_ptr<Device>> d;
    for (unsigned t : {1u, 3u}) {
      DeviceOptions o;
      o.threads = t;
      auto dev = Device::create(o, textures(), p);
      FUZZ_CHECK(dev.ok());
      d.push_back(std::move(dev).value());
    }
    return d;
  }();
  Device& dev = *devices[threads == 1 ? 0 : 1];
  dev.reset();
  dev.submit(words);
  dev.flush();
  return {dev.screen().begin(), dev.screen().end()};
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (const StreamFormat f : {StreamFormat::Text, StreamFormat::Lines}) {
    auto words = parse_stream(text, f, "f");
    if (!words.ok()) {
      FUZZ_CHECK(words.error().message.rfind("f:", 0) == 0);
      continue;
    }
    const std::string again = f == StreamFormat::Text ? format_text_stream(*words) : format_line_stream(*words);
    auto back = parse_stream(again, f, "g");
    FUZZ_CHECK(back.ok());
    FUZZ_CHECK(*back == *words);
    const std::span<const std::uint64_t> some(words->data(), std::min<std::size_t>(words->size(), 2048));
    FUZZ_CHECK(run(some, 1) == run(some, 3));
  }
  return 0;
}
