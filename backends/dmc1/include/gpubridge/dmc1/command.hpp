#pragma once
// The DMC-1 command word (docs/dmc1.md, "Command word"): one 64-bit word `tex0 << 32 | tex1`.
// tex1 (bits 31:0) carries the 2-bit tag, light, rows and texture id; tex0 (bits 63:32) the
// per-kind data. One field table describes every kind; the builders, describe() and the docs table
// are all derived from it.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace gpubridge::dmc1 {

enum class CommandKind : std::uint8_t {
  Wall,         // tag 00: vertical textured span, constant depth
  Plane,        // tag 01: perspective span through the 1/n table
  Terrain,      // tag 10: Comanche-style height-field column
  RayCs,        // tag 11, sub-type 00: terrain ray cosine and sine
  UvOffset,     // tag 11, sub-type 01: plane/terrain texture offsets and lightmap mode
  PlaneA,       // tag 11, sub-type 10: plane gradients (n, u, v along the column) and dot_u/dot_v
  ViewZ,        // tag 11, sub-type 11: terrain view height
  EndOfColumn,  // tag 11 with bit 0 set: output the column and swap column buffers
};
inline constexpr unsigned kCommandKinds = 8;
std::string_view to_string(CommandKind k);
std::optional<CommandKind> parse_command_kind(std::string_view name);

inline constexpr std::uint64_t kEndOfColumnWord = 0xC0000001u;  // tex0 is ignored
inline constexpr unsigned kColumns = 320;                        // one frame = 320 end-of-column commands
inline constexpr unsigned kRows = 240;                           // rows 0..239, row 0 at the bottom

CommandKind kind_of(std::uint64_t word);
constexpr bool is_span(CommandKind k) { return k == CommandKind::Wall || k == CommandKind::Plane || k == CommandKind::Terrain; }

// One field of one command kind: bits [lsb, lsb + width) of the 64-bit word.
struct Field {
  CommandKind kind;
  std::string_view name;
  std::uint8_t lsb;
  std::uint8_t width;
  bool is_signed;
  std::string_view meaning;
};
// Every field of every kind, in word order within a kind (tags and the EOC bit are implied by
// the kind and not listed).
std::span<const Field> fields();
std::span<const Field> fields_of(CommandKind k);
const Field* find_field(CommandKind k, std::string_view name);

std::int64_t get_field(std::uint64_t word, const Field& f);
// Sets a field; values are truncated to the field's width (two's complement for signed fields).
void set_field(std::uint64_t& word, const Field& f, std::int64_t value);
// The word of kind k with every field zero (tag bits set).
std::uint64_t blank_word(CommandKind k);

// "wall texture=5 start=10 end=20 light=3 depth=4660 v_init=7 u_init=9": for disassembly and errors.
std::string describe(std::uint64_t word);
// The field table as docs/dmc1.md carries it (`gpubridge regs --device dmc1 --markdown`).
std::string field_table_markdown();

// Builders (values are truncated to their fields; see fields()).
struct SpanRows {
  unsigned start = 0, end = 0;  // rows; a span with start > end is dropped by the GPU
  unsigned light = 0;           // 0..15
  unsigned texture = 0;         // 0..1023; 0 = background (texel 99 at full light)
};
// d: depth (0xFFFF = behind everything); its low 14 bits are also the v increment (11 fractional bits).
std::uint64_t wall(const SpanRows& r, std::uint16_t d, std::uint8_t v_init, std::uint8_t u_init);
std::uint64_t plane(const SpanRows& r, std::int16_t ded, std::int16_t dr);
// For terrain, r.start is the first row drawn and r.end the highest row; distances are 0..2047
// (a start distance of 1024 or more ends the span at once).
std::uint64_t terrain(const SpanRows& r, unsigned start_distance, unsigned end_distance, bool pick_height);
std::uint64_t ray_cs(int cos, int sin);  // the GPU keeps 13 bits: -4096..4095
std::uint64_t uv_offset(std::int32_t u_offset, std::int32_t v_offset, bool lightmap);
std::uint64_t plane_a(int ny, int uy, int vy, int du, int dv);
std::uint64_t view_z(std::int16_t z);
inline constexpr std::uint64_t end_of_column() { return kEndOfColumnWord; }

}  // namespace gpubridge::dmc1
