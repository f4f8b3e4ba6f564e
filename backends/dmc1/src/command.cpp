#include "gpubridge/dmc1/command.hpp"

#include <array>
#include <utility>

namespace gpubridge::dmc1 {
namespace {

using K = CommandKind;

// A field before its kind is attached.
struct FieldSpec {
  std::string_view name;
  std::uint8_t lsb, width;
  bool is_signed;
  std::string_view meaning;
};
// Fields every span kind (wall, plane, terrain) has, all in tex1.
constexpr FieldSpec kSpanFields[] = {
    {"texture", 0, 10, false, "texture id; 0 = background (texel 99, light 15)"},
    {"start", 10, 8, false, "first row (0 = bottom)"},
    {"end", 18, 8, false, "last row; the span is dropped when start > end, end is clamped to 239"},
    {"light", 26, 4, false, "light level 0..15"},
};
// Each kind's own fields. Bit positions are in the 64-bit word (tex0 = bits 63:32).
constexpr std::pair<CommandKind, FieldSpec> kOwnFields[] = {
    {K::Wall, {"depth", 32, 16, false, "depth, sign-extended (0xFFFF = behind everything); low 14 bits = v increment"}},
    {K::Wall, {"v_init", 48, 8, false, "first v texel row"}},
    {K::Wall, {"u_init", 56, 8, false, "texel column (constant for the span)"}},
    {K::Plane, {"ded", 32, 16, true, "plane distance along its normal"}},
    {K::Plane, {"dr", 48, 16, true, "ray . normal at the span start (dot_ray = dr << 8)"}},
    {K::Terrain, {"end_distance", 32, 11, false, "last distance step drawn"}},
    {K::Terrain, {"start_distance", 48, 11, false, "first distance; 1024 or more ends the span at once"}},
    {K::Terrain, {"pick", 63, 1, false, "latch the first height sample (picked height)"}},
    {K::RayCs, {"cos", 32, 14, true, "ray cosine (the GPU keeps 13 bits)"}},
    {K::RayCs, {"sin", 46, 14, true, "ray sine (the GPU keeps 13 bits)"}},
    {K::UvOffset, {"u_offset", 1, 24, true, "u offset added to plane and terrain coordinates"}},
    {K::UvOffset, {"lightmap", 25, 1, false, "lightmap mode: texels become the light byte"}},
    {K::UvOffset, {"v_offset", 32, 24, true, "v offset added to plane and terrain coordinates"}},
    {K::PlaneA, {"du", 1, 14, true, "dot_u = du << 8"}},
    {K::PlaneA, {"dv", 15, 14, true, "dot_v = dv << 8"}},
    {K::PlaneA, {"ny", 32, 10, true, "dot_ray increment per row event"}},
    {K::PlaneA, {"uy", 42, 10, true, "dot_u increment per row event"}},
    {K::PlaneA, {"vy", 52, 10, true, "dot_v increment per row event"}},
    {K::ViewZ, {"z", 32, 16, true, "terrain view height"}},
};

// The one table: per kind, the span fields (for span kinds) then the kind's own fields.
constexpr auto kFields = [] {
  std::array<Field, 3 * std::size(kSpanFields) + std::size(kOwnFields)> t{};
  std::size_t n = 0;
  auto add = [&](CommandKind k, const FieldSpec& s) { t[n++] = Field{k, s.name, s.lsb, s.width, s.is_signed, s.meaning}; };
  for (std::size_t i = 0; i < std::size(kOwnFields); ++i) {
    const CommandKind k = kOwnFields[i].first;
    if (is_span(k) && (i == 0 || kOwnFields[i - 1].first != k))
      for (const FieldSpec& s : kSpanFields) add(k, s);
    add(k, kOwnFields[i].second);
  }
  return t;
}();

constexpr std::array<std::string_view, kCommandKinds> kNames = {"wall",    "plane",   "terrain", "ray_cs",
                                                                 "uv_offset", "plane_a", "view_z",  "eoc"};

std::uint64_t mask(unsigned width) { return width >= 64 ? ~0ull : ((1ull << width) - 1); }

}  // namespace

std::string_view to_string(CommandKind k) { return kNames[static_cast<unsigned>(k)]; }

std::optional<CommandKind> parse_command_kind(std::string_view name) {
  for (unsigned i = 0; i < kCommandKinds; ++i)
    if (kNames[i] == name) return static_cast<CommandKind>(i);
  return std::nullopt;
}

CommandKind kind_of(std::uint64_t word) {
  const unsigned tag = (word >> 30) & 3;
  if (tag != 3) return static_cast<CommandKind>(tag);  // Wall, Plane, Terrain
  if (word & 1) return CommandKind::EndOfColumn;
  return static_cast<CommandKind>(3 + ((word >> 62) & 3));  // RayCs, UvOffset, PlaneA, ViewZ
}

std::span<const Field> fields() { return kFields; }

std::span<const Field> fields_of(CommandKind k) {
  const Field* b = kFields.data();
  const Field* end = b + kFields.size();
  while (b != end && b->kind != k) ++b;
  const Field* e = b;
  while (e != end && e->kind == k) ++e;
  return {b, e};
}

const Field* find_field(CommandKind k, std::string_view name) {
  for (const Field& f : fields_of(k))
    if (f.name == name) return &f;
  return nullptr;
}

std::int64_t get_field(std::uint64_t word, const Field& f) {
  const std::uint64_t v = (word >> f.lsb) & mask(f.width);
  if (!f.is_signed) return static_cast<std::int64_t>(v);
  const std::uint64_t sign = 1ull << (f.width - 1);
  return static_cast<std::int64_t>(v ^ sign) - static_cast<std::int64_t>(sign);
}

void set_field(std::uint64_t& word, const Field& f, std::int64_t value) {
  const std::uint64_t m = mask(f.width) << f.lsb;
  word = (word & ~m) | ((static_cast<std::uint64_t>(value) << f.lsb) & m);
}

std::uint64_t blank_word(CommandKind k) {
  switch (k) {
    case CommandKind::Wall:
    case CommandKind::Plane:
    case CommandKind::Terrain: return std::uint64_t{static_cast<unsigned>(k)} << 30;
    case CommandKind::EndOfColumn: return kEndOfColumnWord;
    default: return (3ull << 30) | (std::uint64_t{static_cast<unsigned>(k) - 3} << 62);
  }
}

std::string describe(std::uint64_t word) {
  const CommandKind k = kind_of(word);
  std::string s(to_string(k));
  for (const Field& f : fields_of(k)) {
    s += ' ';
    s += f.name;
    s += '=';
    s += std::to_string(get_field(word, f));
  }
  return s;
}

std::string field_table_markdown() {
  std::string md = "| command | tag | field | bits | signed | meaning |\n|---|---|---|---|---|---|\n";
  auto bits = [](unsigned hi, unsigned lo) { return hi == lo ? std::to_string(lo) : std::to_string(hi) + ":" + std::to_string(lo); };
  for (unsigned k = 0; k < kCommandKinds; ++k) {
    const auto kind = static_cast<CommandKind>(k);
    std::string tag = "tex1[31:30] = " + std::to_string(k < 3 ? k : 3);
    if (kind == CommandKind::EndOfColumn) tag += ", bit 0 = 1";
    else if (!is_span(kind)) tag += ", bit 0 = 0, tex0[31:30] = " + std::to_string(k - 3);
    const auto fs = fields_of(kind);
    if (fs.empty()) md += "| " + std::string(to_string(kind)) + " | " + tag + " | | | | the rest is ignored |\n";
    for (const Field& f : fs)
      md += "| " + std::string(to_string(kind)) + " | " + tag + " | " + std::string(f.name) + " | " +
            bits(f.lsb + f.width - 1u, f.lsb) + " | " + (f.is_signed ? "yes" : "no") + " | " + std::string(f.meaning) + " |\n";
  }
  return md;
}

namespace {
std::uint64_t build(CommandKind k, std::initializer_list<std::pair<std::string_view, std::int64_t>> values) {
  std::uint64_t w = blank_word(k);
  for (const auto& [name, v] : values) set_field(w, *find_field(k, name), v);
  return w;
}
std::uint64_t span(CommandKind k, const SpanRows& r) {
  return build(k, {{"texture", r.texture}, {"start", r.start}, {"end", r.end}, {"light", r.light}});
}
}  // namespace

std::uint64_t wall(const SpanRows& r, std::uint16_t d, std::uint8_t v_init, std::uint8_t u_init) {
  std::uint64_t w = span(CommandKind::Wall, r);
  set_field(w, *find_field(CommandKind::Wall, "depth"), d);
  set_field(w, *find_field(CommandKind::Wall, "v_init"), v_init);
  set_field(w, *find_field(CommandKind::Wall, "u_init"), u_init);
  return w;
}

std::uint64_t plane(const SpanRows& r, std::int16_t ded, std::int16_t dr) {
  std::uint64_t w = span(CommandKind::Plane, r);
  set_field(w, *find_field(CommandKind::Plane, "ded"), ded);
  set_field(w, *find_field(CommandKind::Plane, "dr"), dr);
  return w;
}

std::uint64_t terrain(const SpanRows& r, unsigned start_distance, unsigned end_distance, bool pick_height) {
  std::uint64_t w = span(CommandKind::Terrain, r);
  set_field(w, *find_field(CommandKind::Terrain, "start_distance"), start_distance);
  set_field(w, *find_field(CommandKind::Terrain, "end_distance"), end_distance);
  set_field(w, *find_field(CommandKind::Terrain, "pick"), pick_height ? 1 : 0);
  return w;
}

std::uint64_t ray_cs(int cos, int sin) { return build(CommandKind::RayCs, {{"cos", cos}, {"sin", sin}}); }

std::uint64_t uv_offset(std::int32_t u_offset, std::int32_t v_offset, bool lightmap) {
  return build(CommandKind::UvOffset, {{"u_offset", u_offset}, {"v_offset", v_offset}, {"lightmap", lightmap ? 1 : 0}});
}

std::uint64_t plane_a(int ny, int uy, int vy, int du, int dv) {
  return build(CommandKind::PlaneA, {{"ny", ny}, {"uy", uy}, {"vy", vy}, {"du", du}, {"dv", dv}});
}

std::uint64_t view_z(std::int16_t z) { return build(CommandKind::ViewZ, {{"z", z}}); }

}  // namespace gpubridge::dmc1
