#include "gpubridge/dmc1/texture_memory.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <new>

#include <sys/mman.h>

#include <zlib.h>

#include "gpubridge/common/regular_file.hpp"

namespace gpubridge::dmc1 {
namespace {

bool is_gzip(std::span<const std::uint8_t> b) { return b.size() >= 2 && b[0] == 0x1F && b[1] == 0x8B; }

// Inflates a gzip member into at most `limit` bytes.
Result<std::vector<std::uint8_t>> gunzip(std::span<const std::uint8_t> in, std::size_t limit, const std::string& name) {
  z_stream z{};
  if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK) return make_error(name + ": cannot start the gzip decoder");
  std::vector<std::uint8_t> out(std::min<std::size_t>(limit, in.size() * 4 + 1024));
  z.next_in = const_cast<Bytef*>(in.data());  // zlib's API is not const-correct; it does not write
  z.avail_in = static_cast<uInt>(in.size());
  std::size_t have = 0;
  int rc = Z_OK;
  while (rc != Z_STREAM_END) {
    if (have == out.size()) {
      if (out.size() >= limit) {
        inflateEnd(&z);
        return make_error(name + ": the decompressed texture image exceeds " + std::to_string(limit) +
                          " bytes, the most the DMC-1's 24-bit address space holds above 0x200000");
      }
      out.resize(std::min(limit, out.size() * 2));
    }
    z.next_out = out.data() + have;
    z.avail_out = static_cast<uInt>(out.size() - have);
    rc = inflate(&z, Z_NO_FLUSH);
    have = out.size() - z.avail_out;
    if (rc == Z_BUF_ERROR && z.avail_in == 0) rc = Z_DATA_ERROR;  // input ended before the stream did
    if (rc != Z_OK && rc != Z_STREAM_END) {
      inflateEnd(&z);
      return make_error(name + ": corrupt or truncated gzip data (" + (z.msg ? z.msg : "inflate failed") +
                        "); re-copy the file or pass the uncompressed image");
    }
  }
  inflateEnd(&z);
  out.resize(have);
  return out;
}

}  // namespace

void TextureMemory::Free::operator()(std::uint8_t* p) const { std::free(p); }

TextureMemory::TextureMemory() {
  constexpr std::size_t kHugePage = 2u << 20;
  auto* p = static_cast<std::uint8_t*>(std::aligned_alloc(kHugePage, kSize));
  if (!p) throw std::bad_alloc();
  madvise(p, kSize, MADV_HUGEPAGE);  // advice only: without huge pages it still works
  std::memset(p, 0, kSize);
  bytes_.reset(p);
}

Result<std::shared_ptr<const TextureMemory>> TextureMemory::from_image(std::span<const std::uint8_t> image) {
  if (image.size() > kMaxImageBytes)
    return make_error("texture image of " + std::to_string(image.size()) + " bytes does not fit: the DMC-1 reads " +
                      "24-bit addresses and the image starts at 0x200000, so at most " +
                      std::to_string(kMaxImageBytes) + " bytes");
  auto m = std::make_shared<TextureMemory>();
  std::memcpy(m->bytes_.get() + kImageBase, image.data(), image.size());
  m->image_bytes_ = image.size();
  return std::shared_ptr<const TextureMemory>(std::move(m));
}

TextureBinding TextureMemory::binding(unsigned tid) const {
  const std::uint32_t h = kImageBase + 8 * (tid & 1023);
  const std::uint8_t size = read(h + 3);
  return TextureBinding{static_cast<std::uint32_t>(read(h) | read(h + 1) << 8 | read(h + 2) << 16),
                        static_cast<std::uint8_t>(size & 15), static_cast<std::uint8_t>(size >> 4)};
}

Result<std::vector<std::uint8_t>> read_texture_image(const std::filesystem::path& path) {
  auto text = read_regular_file(path, TextureMemory::kMaxImageBytes, "texture image");
  if (!text) {
    return make_error(text.error().message +
                      " (a DMC-1 texture image is at most 14 MiB: it is mapped at 0x200000 in a 24-bit address space)");
  }
  const std::span<const std::uint8_t> bytes(reinterpret_cast<const std::uint8_t*>(text->data()), text->size());
  if (is_gzip(bytes)) return gunzip(bytes, TextureMemory::kMaxImageBytes, path.string());
  return std::vector<std::uint8_t>(bytes.begin(), bytes.end());
}

Result<std::shared_ptr<const TextureMemory>> load_texture_memory(const std::filesystem::path& path) {
  auto image = read_texture_image(path);
  if (!image) return image.error();
  auto m = TextureMemory::from_image(*image);
  if (!m) return make_error(path.string() + ": " + m.error().message);
  return m;
}

}  // namespace gpubridge::dmc1
