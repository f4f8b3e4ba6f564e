// Fuzzes PNG decoding (decode_png, libpng's simplified API). libpng is the system library and not
// coverage-instrumented, and it rejects any chunk whose CRC is wrong, so plain mutation would
// rarely get past the chunk layer. The first byte therefore picks how the rest becomes a PNG:
//   0  the bytes as they are;
//   1  the bytes with every chunk CRC recomputed, so mutated headers and chunk data reach libpng;
//   2  built here: IHDR fields (width, height, depth, colour type, interlace), an optional PLTE
//      and tRNS, and the remaining bytes as raw scanlines deflated into one IDAT.
// Properties: a refusal names the input; a decoded image has 1..kMaxImageDim pixels per side and
// exactly width*height*4 bytes; encoding it and decoding the result gives back the same pixels.
#include <zlib.h>

#include <cstring>
#include <span>
#include <vector>

#include "fuzz_check.hpp"
#include "gpubridge/common/image.hpp"

namespace {

using namespace gpubridge;
using Bytes = std::vector<std::uint8_t>;

constexpr std::uint8_t kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};

std::uint32_t be32(const std::uint8_t* p) {
  return std::uint32_t{p[0]} << 24 | std::uint32_t{p[1]} << 16 | std::uint32_t{p[2]} << 8 | p[3];
}
void put_be32(Bytes& out, std::uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(static_cast<std::uint8_t>(v >> s));
}
std::uint32_t chunk_crc(const std::uint8_t* type_and_data, std::size_t n) {
  return static_cast<std::uint32_t>(crc32(0, type_and_data, static_cast<uInt>(n)));
}

// Recomputes the CRC of every complete chunk after the signature; stops at the first chunk that
// does not fit.
Bytes with_fixed_crcs(std::span<const std::uint8_t> in) {
  Bytes b(in.begin(), in.end());
  std::size_t p = 8;
  while (p + 12 <= b.size()) {
    const std::uint32_t len = be32(&b[p]);
    if (len > b.size() - p - 12) break;
    const std::uint32_t crc = chunk_crc(&b[p + 4], 4 + std::size_t{len});
    for (int i = 0; i < 4; ++i) b[p + 8 + len + i] = static_cast<std::uint8_t>(crc >> (24 - 8 * i));
    p += 12 + len;
  }
  return b;
}

void put_chunk(Bytes& out, const char* type, std::span<const std::uint8_t> data) {
  put_be32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  put_be32(out, chunk_crc(&out[start], 4 + data.size()));
}

// [width u16][height u16][depth][colour type][interlace][palette entries][tRNS entries][palette
// and tRNS bytes][scanlines...]: small dimensions so the raw data can plausibly fill them.
Bytes synthesized(std::span<const std::uint8_t> in) {
  if (in.size() < 9) return {};
  Bytes png(kSignature, kSignature + 8);
  Bytes ihdr;
  put_be32(ihdr, std::uint32_t{in[0]} << 8 | in[1]);
  put_be32(ihdr, std::uint32_t{in[2]} << 8 | in[3]);
  ihdr.insert(ihdr.end(), {in[4], in[5], 0, 0, static_cast<std::uint8_t>(in[6] & 1)});
  put_chunk(png, "IHDR", ihdr);
  std::size_t p = 9;
  const std::size_t plte = std::min<std::size_t>(3 * std::size_t{in[7]}, in.size() - p);
  if (plte) put_chunk(png, "PLTE", in.subspan(p, plte));
  p += plte;
  const std::size_t trns = std::min<std::size_t>(in[8], in.size() - p);
  if (trns) put_chunk(png, "tRNS", in.subspan(p, trns));
  p += trns;
  const auto raw = in.subspan(p);
  uLongf packed = compressBound(static_cast<uLong>(raw.size()));
  Bytes idat(packed);
  if (compress2(idat.data(), &packed, raw.data(), static_cast<uLong>(raw.size()), 1) != Z_OK) return {};
  idat.resize(packed);
  put_chunk(png, "IDAT", idat);
  put_chunk(png, "IEND", {});
  return png;
}

void check(std::span<const std::uint8_t> bytes) {
  auto img = decode_png(bytes, "fuzz.png");
  if (!img) {
    FUZZ_CHECK(img.error().message.rfind("fuzz.png: ", 0) == 0);
    return;
  }
  FUZZ_CHECK(img->width >= 1 && img->width <= kMaxImageDim);
  FUZZ_CHECK(img->height >= 1 && img->height <= kMaxImageDim);
  FUZZ_CHECK(img->rgba.size() == std::size_t{img->width} * img->height * 4);
  auto png = encode_png(*img);
  FUZZ_CHECK(png.ok());
  auto back = decode_png(*png, "re-encoded");
  FUZZ_CHECK(back.ok());
  FUZZ_CHECK(*back == *img);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::span<const std::uint8_t> rest(data + 1, size - 1);
  switch (data[0] % 3) {
    case 0: check(rest); break;
    case 1: check(with_fixed_crcs(rest)); break;
    case 2: check(synthesized(rest)); break;
  }
  return 0;
}
