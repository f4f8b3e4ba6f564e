// The spigpu v1 register table. Every behavioural statement here is normative and mirrored
// (generated) in docs/protocol.md; change both through this file.
#include "gpubridge/protocol/registers.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdio>

namespace gpubridge::protocol {
namespace {

using K = FieldKind;

constexpr EnumValue kPrimValues[] = {{"LIST", 0}, {"STRIP", 1}, {"FAN", 2}};
constexpr EnumValue kDepthFuncValues[] = {{"NEVER", 0},   {"LESS", 1},     {"EQUAL", 2},  {"LEQUAL", 3},
                                          {"GREATER", 4}, {"NOTEQUAL", 5}, {"GEQUAL", 6}, {"ALWAYS", 7}};
constexpr EnumValue kBlendValues[] = {{"OFF", 0}, {"ALPHA", 1}, {"ADD", 2}, {"MULTIPLY", 3}};
constexpr EnumValue kFormatValues[] = {{"RGBA8888", 0}, {"RGB565", 1}, {"RGBA2222", 2}};
constexpr EnumValue kWrapValues[] = {{"REPEAT", 0}, {"CLAMP", 1}, {"MIRROR", 2}};

constexpr Field F(std::string_view name, unsigned lsb, unsigned width, FieldKind kind, std::string_view doc,
                  std::span<const EnumValue> values = {}, unsigned frac = 0) {
  return Field{name, static_cast<std::uint8_t>(lsb), static_cast<std::uint8_t>(width), kind, values,
               static_cast<std::uint8_t>(frac), doc};
}

constexpr Field kColor[] = {
    F("Q", 32, 32, K::Unsigned, "Q = 1/W of the next vertex, unsigned 0.32, normalised per triangle by the host", {}, 32),
    F("R", 24, 8, K::Unsigned, "red"),
    F("G", 16, 8, K::Unsigned, "green"),
    F("B", 8, 8, K::Unsigned, "blue"),
    F("A", 0, 8, K::Unsigned, "alpha"),
};
constexpr Field kTexcoord[] = {
    F("S", 32, 32, K::Signed, "S = U*Q, signed 8.24 (U in texture widths)", {}, 24),
    F("T", 0, 32, K::Signed, "T = V*Q, signed 8.24 (V in texture heights)", {}, 24),
};
constexpr Field kVertex[] = {
    F("Z", 32, 24, K::Unsigned, "depth, 0 = near, 0xFFFFFF = far"),
    F("Y", 16, 16, K::Signed, "screen y, signed 12.4 pixels, row 0 at the top", {}, 4),
    F("X", 0, 16, K::Signed, "screen x, signed 12.4 pixels", {}, 4),
};
constexpr Field kPrim[] = {
    F("TYPE", 0, 2, K::Enum, "how VERTEX writes form triangles; writing PRIM restarts the primitive", kPrimValues),
};
constexpr Field kTriMode[] = {
    F("DITHER_PHASE", 16, 4, K::Unsigned, "temporal dither phase: the host writes the frame number mod 16 (section 11.1)"),
    F("TEMPORAL", 15, 1, K::Flag, "with DITHER: temporal dither, threshold B XOR bit-reversed DITHER_PHASE, levels scaled to 0..2^n - 1 (section 11.1)"),
    F("TEX_DECAL", 14, 1, K::Flag, "textured: 1 = texel replaces the colour, 0 = texel x colour (modulate)"),
    F("MASK_A", 13, 1, K::Flag, "1 = do not write alpha"),
    F("MASK_B", 12, 1, K::Flag, "1 = do not write blue"),
    F("MASK_G", 11, 1, K::Flag, "1 = do not write green"),
    F("MASK_R", 10, 1, K::Flag, "1 = do not write red"),
    F("DITHER", 9, 1, K::Flag, "ordered 4x4 Bayer dither when the framebuffer has < 8 bits per channel"),
    F("BLEND", 7, 2, K::Enum, "blend equation (exact integer formulas in the document)", kBlendValues),
    F("Z_WRITE", 6, 1, K::Flag, "write Z of pixels that pass the depth test"),
    F("Z_FUNC", 3, 3, K::Enum, "depth compare: pass when (new Z) FUNC (stored Z)", kDepthFuncValues),
    F("Z_TEST", 2, 1, K::Flag, "enable the depth test (0: every pixel passes, Z buffer not read)"),
    F("TEXTURED", 1, 1, K::Flag, "sample the bound texture"),
    F("GOURAUD", 0, 1, K::Flag, "interpolate vertex colours (0: flat, colour of the triangle's first vertex)"),
};
constexpr Field kAddr16[] = {
    F("ADDR", 4, 28, K::Unsigned, "byte address / 16 (16-byte aligned; bits [3:0] reserved)"),
};
constexpr Field kTexFmt[] = {
    F("FORMAT", 16, 2, K::Enum, "texel format", kFormatValues),
    F("BILINEAR", 12, 1, K::Flag, "bilinear filtering (0: nearest)"),
    F("WRAP_T", 10, 2, K::Enum, "vertical addressing", kWrapValues),
    F("WRAP_S", 8, 2, K::Enum, "horizontal addressing", kWrapValues),
    F("HEIGHT_LOG2", 4, 4, K::Unsigned, "log2 of the height in texels, 3..10"),
    F("WIDTH_LOG2", 0, 4, K::Unsigned, "log2 of the width in texels, 3..10"),
};
constexpr Field kScissor[] = {
    F("Y1", 48, 11, K::Unsigned, "bottom, exclusive (0..1024)"),
    F("X1", 32, 11, K::Unsigned, "right, exclusive (0..1024)"),
    F("Y0", 16, 11, K::Unsigned, "top, inclusive (0..1024)"),
    F("X0", 0, 11, K::Unsigned, "left, inclusive (0..1024)"),
};
constexpr Field kRgba[] = {
    F("R", 24, 8, K::Unsigned, "red"),
    F("G", 16, 8, K::Unsigned, "green"),
    F("B", 8, 8, K::Unsigned, "blue"),
    F("A", 0, 8, K::Unsigned, "alpha"),
};
constexpr Field kNone[] = {F("ZERO", 0, 0, K::Unsigned, "data must be 0")};
constexpr Field kClearDepth[] = {F("Z", 0, 24, K::Unsigned, "depth written by CLEAR_Z")};
constexpr Field kFbFormat[] = {
    F("FORMAT", 32, 2, K::Enum, "pixel format of draw and display buffers", kFormatValues),
    F("HEIGHT", 16, 11, K::Unsigned, "height in pixels, 1..CAPS.MAX_HEIGHT"),
    F("WIDTH", 0, 11, K::Unsigned, "width in pixels, 1..CAPS.MAX_WIDTH; pitch = WIDTH * bytes per pixel"),
};
constexpr Field kStatus[] = {
    F("ERRORS", 48, 16, K::Unsigned, "sticky error flags (ERR_*), cleared by ERR_CLEAR or RESET"),
    F("FRAME_COUNT", 32, 16, K::Unsigned, "scanned-out frames since reset, modulo 2^16"),
    F("LINK_PENDING", 20, 1, K::Flag, "strict link mode: writes held waiting for LINK_CHECK"),
    F("SWAP_PENDING", 19, 1, K::Flag, "FB_DISPLAY written, not yet latched by vsync"),
    F("MEM_READY", 18, 1, K::Flag, "MEM_DATA prefetch holds the word at MEM_ADDR"),
    F("VBLANK", 17, 1, K::Flag, "scanout is in vertical blanking"),
    F("BUSY", 16, 1, K::Flag, "the FIFO is non-empty or a command is executing"),
    F("FIFO_LEVEL", 0, 16, K::Unsigned, "entries in the command FIFO"),
};
constexpr Field kErrClear[] = {F("MASK", 0, 16, K::Unsigned, "1 bits clear the matching STATUS.ERRORS flags")};
constexpr Field kFrameCrc[] = {
    F("FRAME", 32, 16, K::Unsigned, "FRAME_COUNT of the frame the CRC belongs to"),
    F("CRC", 0, 32, K::Unsigned, "CRC-32 (IEEE 802.3) of the scanned-out buffer bytes"),
};
constexpr Field kLinkCtrl[] = {
    F("CLEAR_KEY", 32, 32, K::Unsigned,
      "write-only, reads 0: must be 0x6F666621 (\"off!\") for a write of STRICT = 0 to leave strict mode (1.3)"),
    F("STRICT", 0, 1, K::Flag, "hold queued writes until a matching LINK_CHECK"),
};
constexpr Field kLinkCheck[] = {F("CRC", 0, 32, K::Unsigned, "host's CRC-32 of all frames since the last check")};
constexpr Field kLinkStatus[] = {
    F("GROUPS_BAD", 48, 16, K::Unsigned, "LINK_CHECKs that failed, modulo 2^16"),
    F("GROUPS_OK", 32, 16, K::Unsigned, "LINK_CHECKs that matched, modulo 2^16"),
    F("DISCARDING", 24, 1, K::Flag, "strict mode: a check failed; queued writes are dropped until LINK_CTRL is written"),
    F("FRAMES", 0, 24, K::Unsigned, "complete frames received since the last LINK_CHECK or LINK_CTRL write"),
};
constexpr Field kHostTag[] = {F("TAG", 0, 64, K::Unsigned, "any value; 0 after reset (detects board resets)")};
constexpr Field kReset[] = {F("MAGIC", 0, 40, K::Unsigned, "must be 0x5245534554 (\"RESET\")")};
constexpr Field kFence[] = {F("ID", 0, 64, K::Unsigned, "reads return the ID of the last executed FENCE")};
constexpr Field kMemAddr[] = {F("ADDR", 3, 29, K::Unsigned, "byte address / 8 of the next MEM_DATA access")};
constexpr Field kMemData[] = {F("DATA", 0, 64, K::Unsigned, "8 bytes, big-endian: bits [63:56] at MEM_ADDR")};
constexpr Field kCaps[] = {
    F("FEATURES", 56, 8, K::Unsigned, "bit 0 bilinear, 1 blend, 2 dither, 3 strict link, 4 RGB565, 5 RGBA2222, 6 temporal dither, 7 texturing"),
    F("FIFO_DEPTH", 46, 10, K::Unsigned, "command FIFO entries"),
    F("MAX_HEIGHT", 35, 11, K::Unsigned, "largest framebuffer height"),
    F("MAX_WIDTH", 24, 11, K::Unsigned, "largest framebuffer width"),
    F("VRAM_KIB", 0, 24, K::Unsigned, "video memory size in KiB"),
};
constexpr Field kCaps2[] = {
    F("FEATURES2", 0, 8, K::Unsigned, "bit 0 depth buffer (TRI_MODE.Z_TEST/Z_WRITE, CLEAR_Z); bits 1-7 reserved, read 0"),
};
constexpr Field kId[] = {
    F("MAGIC", 32, 32, K::Unsigned, "0x53504755 (\"SPGU\")"),
    F("MAJOR", 24, 8, K::Unsigned, "protocol major version (1)"),
    F("MINOR", 16, 8, K::Unsigned, "protocol minor version (4)"),
    F("VARIANT", 0, 16, K::Unsigned, "implementation: 0 simulator, others per board profile"),
};

using A = Access;
using P = Path;

// Reset values are normative: a device after power-on or RESET holds exactly these.
constexpr RegisterDesc kTable[] = {
    {0x00, "COLOR", A::ReadWrite, P::Queued, 0xFFFFFFFF'FFFFFFFFull, kColor,
     "vertex colour RGBA8888 (R in the top byte) and Q = 1/W, latched for the next VERTEX"},
    {0x01, "TEXCOORD", A::ReadWrite, P::Queued, 0, kTexcoord, "vertex S = U/W and T = V/W, latched for the next VERTEX"},
    {0x02, "VERTEX", A::ReadWrite, P::Queued, 0, kVertex, "pushes a vertex; kicks a triangle per PRIM.TYPE"},
    {0x03, "PRIM", A::ReadWrite, P::Queued, 0, kPrim, "primitive type; any write restarts vertex counting"},
    {0x04, "TRI_MODE", A::ReadWrite, P::Queued, 0, kTriMode, "render state, sampled when a triangle is kicked"},
    {0x05, "TEX_BASE", A::ReadWrite, P::Queued, 0, kAddr16, "texture byte address"},
    {0x06, "TEX_FMT", A::ReadWrite, P::Queued, 0x33, kTexFmt, "texture size, format, addressing and filter"},
    {0x07, "SCISSOR", A::ReadWrite, P::Queued, 0x0400'0400'0000'0000ull, kScissor,
     "pixels outside [X0,X1) x [Y0,Y1) are not drawn or cleared"},
    {0x08, "FB_DRAW", A::ReadWrite, P::Queued, 0, kAddr16, "colour buffer byte address for drawing and CLEAR"},
    {0x09, "FB_DISPLAY", A::ReadWrite, P::Queued, 0, kAddr16, "scanout byte address; latched at the next vsync"},
    {0x0A, "CLEAR_COLOR", A::ReadWrite, P::Queued, 0x000000FF, kRgba, "colour written by CLEAR"},
    {0x0B, "CLEAR", A::WriteOnly, P::Queued, 0, kNone, "fills the scissor rectangle of FB_DRAW with CLEAR_COLOR"},
    {0x0C, "CLEAR_Z", A::WriteOnly, P::Queued, 0, kNone, "fills the scissor rectangle of FB_Z with CLEAR_DEPTH"},
    {0x0D, "CLEAR_DEPTH", A::ReadWrite, P::Queued, 0xFFFFFF, kClearDepth, "depth written by CLEAR_Z"},
    {0x0E, "FB_Z", A::ReadWrite, P::Queued, 0, kAddr16, "depth buffer byte address (4 bytes per pixel)"},
    {0x0F, "FB_FORMAT", A::ReadWrite, P::Queued, (480ull << 16) | 640, kFbFormat,
     "framebuffer size and pixel format (drawing and scanout)"},
    {0x10, "STATUS", A::ReadOnly, P::Immediate, 0, kStatus, "FIFO level, busy, vblank, frame counter, error flags"},
    {0x11, "ERR_CLEAR", A::WriteOnly, P::Immediate, 0, kErrClear, "clears sticky error flags"},
    {0x12, "FRAME_CRC", A::ReadOnly, P::Immediate, 0, kFrameCrc, "CRC-32 of the last scanned-out frame"},
    {0x13, "LINK_CTRL", A::ReadWrite, P::Immediate, 0, kLinkCtrl, "link integrity mode; an accepted write restarts the link CRC"},
    {0x14, "LINK_CHECK", A::WriteOnly, P::Immediate, 0, kLinkCheck, "compares the host's link CRC with the device's"},
    {0x15, "LINK_STATUS", A::ReadOnly, P::Immediate, 0, kLinkStatus, "link integrity counters"},
    {0x16, "HOST_TAG", A::ReadWrite, P::Immediate, 0, kHostTag, "host-owned value, reset to 0"},
    {0x17, "RESET", A::WriteOnly, P::Immediate, 0, kReset, "soft reset of registers, FIFO and flags (memory kept)"},
    {0x18, "FENCE", A::ReadWrite, P::Queued, 0, kFence, "completion marker"},
    {0x70, "MEM_ADDR", A::ReadWrite, P::Queued, 0, kMemAddr, "memory access pointer (8-byte aligned)"},
    {0x71, "MEM_DATA", A::ReadWrite, P::Queued, 0, kMemData,
     "writes 8 bytes at MEM_ADDR (queued); reads return the prefetched 8 bytes (immediate); both add 8"},
    {0x7D, "CAPS2", A::ReadOnly, P::Immediate, 0, kCaps2,
     "more device capabilities, protocol 1.4 (value depends on the board; bits 63:8 reserved, read 0)"},
    {0x7E, "CAPS", A::ReadOnly, P::Immediate, 0, kCaps, "device capabilities (value depends on the board)"},
    {0x7F, "ID", A::ReadOnly, P::Immediate,
     (std::uint64_t{kIdMagic} << 32) | (std::uint64_t{kVersionMajor} << 24) | (std::uint64_t{kVersionMinor} << 16),
     kId, "identification: magic, protocol version, variant"},
};

bool iequals(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::toupper(static_cast<unsigned char>(x)) == std::toupper(static_cast<unsigned char>(y));
         });
}

struct IndexMap {
  std::array<const RegisterDesc*, kRegisterCount> by_index{};
  IndexMap() {
    for (const auto& r : kTable) by_index[r.index] = &r;
  }
};
const IndexMap& index_map() {
  static const IndexMap m;
  return m;
}

}  // namespace

std::int64_t Field::get_signed(std::uint64_t data) const {
  std::uint64_t v = get(data);
  if (kind == FieldKind::Signed && width > 0 && width < 64 && (v >> (width - 1)) & 1) v |= ~0ull << width;
  return static_cast<std::int64_t>(v);
}

std::uint64_t RegisterDesc::reserved_mask() const {
  std::uint64_t used = 0;
  for (const auto& f : fields) used |= f.mask();
  return ~used;
}

const Field* RegisterDesc::field(std::string_view field_name) const {
  for (const auto& f : fields)
    if (f.width > 0 && iequals(f.name, field_name)) return &f;
  return nullptr;
}

std::span<const RegisterDesc> register_table() { return kTable; }

const RegisterDesc* find_register(std::uint8_t index) {
  return index < kRegisterCount ? index_map().by_index[index] : nullptr;
}

const RegisterDesc* find_register(std::string_view name) {
  for (const auto& r : kTable)
    if (iequals(r.name, name)) return &r;
  return nullptr;
}

const RegisterDesc& describe(Reg r) { return *find_register(index_of(r)); }

std::string_view to_string(PixelFormat f) {
  for (const auto& v : kFormatValues)
    if (v.value == static_cast<std::uint32_t>(f)) return v.name;
  return "?";
}

std::optional<PixelFormat> parse_pixel_format(std::string_view s) {
  for (const auto& v : kFormatValues)
    if (iequals(v.name, s)) return static_cast<PixelFormat>(v.value);
  return std::nullopt;
}

std::string describe_errors(std::uint16_t flags) {
  static constexpr std::string_view names[] = {"FRAMING", "OVERFLOW", "LINK_CRC", "RESERVED_BITS",
                                               "BAD_VALUE", "BAD_REGISTER", "MEM_RANGE"};
  std::string out;
  for (unsigned i = 0; i < std::size(names); ++i) {
    if (flags & (1u << i)) {
      if (!out.empty()) out += '|';
      out += names[i];
    }
  }
  if (flags & ~kAllErrors) {
    if (!out.empty()) out += '|';
    out += "UNDEFINED";
  }
  return out.empty() ? "none" : out;
}

WriteCheck check_write(std::uint8_t index, std::uint64_t data) {
  const RegisterDesc* r = find_register(index);
  if (!r) return {0, ERR_BAD_REGISTER, "no register at index " + std::to_string(index)};
  if (r->access == Access::ReadOnly)
    return {0, ERR_BAD_REGISTER, std::string(r->name) + " is read-only"};
  WriteCheck out{data, 0, {}};
  if (std::uint64_t bad = data & r->reserved_mask()) {
    out.data &= ~r->reserved_mask();
    out.errors |= ERR_RESERVED_BITS;
    char buf[64];
    std::snprintf(buf, sizeof buf, "reserved bits 0x%016llx set", static_cast<unsigned long long>(bad));
    out.problem = std::string(r->name) + ": " + buf;
  }
  for (const auto& f : r->fields) {
    if (f.kind != FieldKind::Enum) continue;
    const auto v = f.get(out.data);
    const bool known = std::any_of(f.values.begin(), f.values.end(), [&](const EnumValue& e) { return e.value == v; });
    if (!known) {
      out.data = f.put(out.data, 0);  // documented replacement: the enum's value 0
      out.errors |= ERR_BAD_VALUE;
      if (!out.problem.empty()) out.problem += "; ";
      out.problem += std::string(r->name) + "." + std::string(f.name) + " = " + std::to_string(v) + " is not defined";
    }
  }
  return out;
}

}  // namespace gpubridge::protocol
