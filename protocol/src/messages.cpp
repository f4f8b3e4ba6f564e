// Socket protocol v1: message encoder and payload decoder (the incremental parser is message_parser.cpp).
// Each payload's fields are described once, by its layout() below; the decoder (FieldReader) and
// the encoder (FieldWriter) both walk that description. Every decode problem becomes a
// DecodeError naming the message type, the field and its byte offset in the payload; the parser
// adds the stream offset of the message.
#include "gpubridge/protocol/messages.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <concepts>
#include <cstdio>
#include <type_traits>
#include <utility>

#include <nlohmann/json.hpp>

namespace gpubridge::protocol {
namespace {

// ---- little-endian helpers -------------------------------------------------------------

template <class T>
void put_le(std::vector<std::uint8_t>& out, T v) {
  for (std::size_t i = 0; i < sizeof(T); ++i) out.push_back(static_cast<std::uint8_t>(std::uint64_t{v} >> (8 * i)));
}
template <class T>
T get_le(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (std::size_t i = sizeof(T); i-- > 0;) v = (v << 8) | p[i];
  return static_cast<T>(v);
}

std::string as_string(std::span<const std::uint8_t> b) { return std::string(b.begin(), b.end()); }

bool valid_utf8(std::string_view s) {
  std::size_t i = 0;
  while (i < s.size()) {
    const auto c = static_cast<unsigned char>(s[i]);
    std::size_t extra;
    std::uint32_t cp;
    if (c < 0x80) { ++i; continue; }
    if ((c >> 5) == 0x6) { extra = 1; cp = c & 0x1F; }
    else if ((c >> 4) == 0xE) { extra = 2; cp = c & 0x0F; }
    else if ((c >> 3) == 0x1E) { extra = 3; cp = c & 0x07; }
    else return false;
    if (s.size() - i <= extra) return false;
    for (std::size_t k = 1; k <= extra; ++k) {
      const auto cc = static_cast<unsigned char>(s[i + k]);
      if ((cc & 0xC0) != 0x80) return false;
      cp = (cp << 6) | (cc & 0x3F);
    }
    // Reject overlong forms, surrogates and values past U+10FFFF.
    static constexpr std::uint32_t kMin[] = {0, 0x80, 0x800, 0x10000};
    if (cp < kMin[extra] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return false;
    i += extra + 1;
  }
  return true;
}

// ---- field vocabulary --------------------------------------------------------------------

// The values a field may hold; `what` completes "<field> <value> ..." in the decode error.
struct Range {
  std::uint64_t lo, hi;
  const char* what;
};
// A trailing byte field's size limit; `what` completes "<field> of <n> bytes ...". The encoder
// clips to the limit only where `clip` says so (it never writes what the decoder refuses there).
struct MaxBytes {
  std::size_t max;
  const char* what;
  bool clip = false;
};
enum class Text : std::uint8_t { Bytes, Utf8 };

// Decoder side: reads each field the layout names, in order, and checks it. After the first
// problem every later read yields a zero value and no new error, so the first problem is the one
// reported. Text checks (UTF-8, JSON) run after the whole layout has been read.
class FieldReader {
 public:
  FieldReader(std::string_view type_name, std::span<const std::uint8_t> p) : type_name_(type_name), p_(p) {}

  template <std::unsigned_integral T>
  void num(const char* field, T& v) {
    if (!start(sizeof(T), field)) return;
    v = get_le<T>(p_.data() + pos_);
    pos_ += sizeof(T);
  }
  template <std::unsigned_integral T>
  void num(const char* field, T& v, Range r) {
    num(field, v);
    if (!failed() && (v < r.lo || v > r.hi)) bad_field(field, at_, std::to_string(v) + " " + r.what);
  }
  // An enumeration carried as the unsigned integer Wire.
  template <std::unsigned_integral Wire, class E>
  void code(const char* field, E& v, std::optional<Range> r = std::nullopt) {
    Wire w = 0;
    if (r) num(field, w, *r);
    else num(field, w);
    v = static_cast<E>(w);
  }
  template <std::unsigned_integral Wire, class E>
  void optional_code(const char* field, std::optional<E>& v, Range r) {
    if (failed() || remaining() == 0) return;
    E e{};
    code<Wire>(field, e, r);
    v = e;
  }
  // A number that may end the payload (absent in a message's original, shorter form).
  template <std::unsigned_integral T>
  void optional_num(const char* field, std::optional<T>& v) {
    if (failed() || remaining() == 0) return;
    T n = 0;
    num(field, n);
    v = n;
  }
  void flag(const char* field, bool& v) {
    std::uint8_t w = 0;
    num(field, w, Range{0, 1, "is not 0 or 1"});
    v = w == 1;
  }
  // u8 length (the field `len_field`, at most `max`), then that many bytes.
  void counted(const char* len_field, const char* field, std::string& s, std::size_t max, Text text) {
    std::uint8_t n = 0;
    num(len_field, n);
    if (!failed() && n > max) bad_field(len_field, at_, std::to_string(n) + " exceeds " + std::to_string(max) + " bytes");
    if (!start(n, field)) return;
    s = as_string(p_.subspan(pos_, n));
    pos_ += n;
    if (text == Text::Utf8) defer_check(field, &s, false);
  }
  // The rest of the payload.
  [[gnu::always_inline]] void rest(const char* field, std::span<const std::uint8_t>& data,
                                   std::optional<MaxBytes> limit = std::nullopt) {
    start(0, field);
    data = p_.subspan(pos_);
    pos_ = p_.size();
    if (!failed() && limit && data.size() > limit->max)
      bad_field(field, at_, "of " + std::to_string(data.size()) + " bytes " + limit->what);
  }
  void rest(const char* field, std::vector<std::uint8_t>& data, MaxBytes limit) {
    std::span<const std::uint8_t> s;
    rest(field, s, limit);
    data.assign(s.begin(), s.end());
  }
  void rest_text(const char* field, std::string& s) {
    std::span<const std::uint8_t> b;
    rest(field, b);
    s = as_string(b);
    defer_check(field, &s, false);
  }
  void rest_json(const char* field, std::string& s) {
    std::span<const std::uint8_t> b;
    rest(field, b);
    s = as_string(b);
    defer_check(field, &s, true);
  }
  // WRITE_FRAMES: whole 9-byte write frames, at least one.
  void frames(FrameView& v) {
    std::span<const std::uint8_t> data;
    rest("frames", data);
    v = FrameView{data};
    if (data.empty()) {
      fail(ErrorCode::Malformed, "payload is empty; send at least one 9-byte frame");
    } else if (data.size() % kFrameBytes != 0) {
      fail(ErrorCode::Malformed, "payload of " + std::to_string(data.size()) + " bytes is not a multiple of 9");
    } else if (const std::size_t f = first_read_frame(v); f * kFrameBytes < data.size()) {
      fail(ErrorCode::BadFrame, "frame " + std::to_string(f) + " (payload byte " + std::to_string(f * kFrameBytes) +
                                    ") has the read bit set; use READ_REG");
    }
  }
  // A check across fields, reported against the last field read: `problem()` returns what is
  // wrong, or an empty string.
  template <class F>
  void check(F&& problem) {
    if (failed()) return;
    if (std::string what = problem(); !what.empty()) bad_field(field_, at_, what);
  }

  // After the layout: no trailing bytes, then the deferred text checks.
  [[gnu::always_inline]] std::optional<DecodeError> finish() {
    if (!failed() && pos_ != p_.size())
      fail(ErrorCode::Malformed, std::to_string(p_.size() - pos_) + " unexpected trailing bytes at payload byte " +
                                     std::to_string(pos_));
    if (text_.text && !failed()) {
      const std::string problem = text_.json ? json_object_problem(*text_.text)
                                  : valid_utf8(*text_.text) ? std::string()
                                                            : std::string("is not valid UTF-8");
      if (!problem.empty()) bad_field(text_.field, text_.at, problem);
    }
    return std::move(error_);
  }

 private:
  // A payload has at most one text field that needs a content check.
  struct TextCheck {
    const char* field = "";
    std::size_t at = 0;
    const std::string* text = nullptr;
    bool json = false;  // a JSON object, else UTF-8 text
  };
  void defer_check(const char* field, const std::string* text, bool json) {
    assert(!text_.text && "one checked text field per payload");
    text_ = TextCheck{field, at_, text, json};
  }
  bool failed() const { return error_.has_value(); }
  std::size_t remaining() const { return p_.size() - pos_; }
  // Begins field `field` of n bytes at the current position.
  // The reads are inlined into each message's decoder; building an error is the cold path.
  [[gnu::always_inline]] bool start(std::size_t n, const char* field) {
    field_ = field;
    at_ = pos_;
    if (failed()) return false;
    if (remaining() < n) [[unlikely]] {
      too_short(n, field);
      return false;
    }
    return true;
  }
  [[gnu::cold, gnu::noinline]] void too_short(std::size_t n, const char* field) {
    fail(ErrorCode::Malformed, "payload of " + std::to_string(p_.size()) + " bytes is too short: " + field + " needs " +
                                   std::to_string(n) + " bytes at payload byte " + std::to_string(pos_));
  }
  [[gnu::cold, gnu::noinline]] void fail(ErrorCode code, const std::string& what) {
    if (!error_) error_ = DecodeError{code, std::string(type_name_) + " " + what};
  }
  // Field value problem: "<TYPE> <field> <what> (payload byte N)".
  [[gnu::cold, gnu::noinline]] void bad_field(const char* field, std::size_t at, const std::string& what) {
    fail(ErrorCode::Malformed, std::string(field) + " " + what + " (payload byte " + std::to_string(at) + ")");
  }

  std::string_view type_name_;
  std::span<const std::uint8_t> p_;
  std::size_t pos_ = 0;
  const char* field_ = "";  // the field being read, and where it starts
  std::size_t at_ = 0;
  TextCheck text_;
  std::optional<DecodeError> error_;
};

// Encoder side: appends each field the layout names. Checks are the decoder's business.
class FieldWriter {
 public:
  explicit FieldWriter(std::vector<std::uint8_t>& out) : o_(out) {}

  template <std::unsigned_integral T>
  void num(const char*, T v, std::optional<Range> = std::nullopt) { put_le(o_, v); }
  template <std::unsigned_integral Wire, class E>
  void code(const char*, E v, std::optional<Range> = std::nullopt) { put_le(o_, static_cast<Wire>(v)); }
  template <std::unsigned_integral Wire, class E>
  void optional_code(const char*, const std::optional<E>& v, Range) {
    if (v) put_le(o_, static_cast<Wire>(*v));
  }
  template <std::unsigned_integral T>
  void optional_num(const char*, const std::optional<T>& v) {
    if (v) put_le(o_, *v);
  }
  void flag(const char*, bool v) { put_le(o_, static_cast<std::uint8_t>(v ? 1 : 0)); }
  void counted(const char*, const char*, std::string_view s, std::size_t max, Text) {
    s = s.substr(0, max);
    put_le(o_, static_cast<std::uint8_t>(s.size()));
    o_.insert(o_.end(), s.begin(), s.end());
  }
  void rest(const char*, std::span<const std::uint8_t> data, std::optional<MaxBytes> limit = std::nullopt) {
    if (limit && limit->clip) data = data.first(std::min(data.size(), limit->max));
    o_.insert(o_.end(), data.begin(), data.end());
  }
  void rest_text(const char*, std::string_view s) { o_.insert(o_.end(), s.begin(), s.end()); }
  void rest_json(const char*, std::string_view s) { o_.insert(o_.end(), s.begin(), s.end()); }
  void frames(const FrameView& v) { rest("frames", v.bytes); }
  template <class F>
  void check(F&&) {}

 private:
  std::vector<std::uint8_t>& o_;
};

// ---- payload layouts: one per message, in wire order (docs/protocol.md "Socket protocol") ----

// `M` is the message type, const when encoding.
template <class M, class... T>
concept OneOf = (std::same_as<std::remove_const_t<M>, T> || ...);

constexpr Range kRegisterIndex{0, kRegisterCount - 1, "exceeds the 7-bit register index range 0..127"};
constexpr Range kSource{0, 2, "is not 0 (board), 1 (sim) or 2 (diff)"};

std::string address_space_problem(std::uint32_t address, std::uint64_t length) {
  if (std::uint64_t{address} + length <= (std::uint64_t{1} << 32)) return {};
  return std::to_string(length) + " bytes at address " + std::to_string(address) + " run past the 4 GiB address space";
}

void layout(auto& io, OneOf<Hello> auto& m) {
  io.num("version", m.version);
  io.counted("name_len", "name", m.name, kMaxNameBytes, Text::Utf8);
  io.counted("token_len", "token", m.token, kMaxTokenBytes, Text::Bytes);
  io.optional_num("codecs", m.codecs);  // absent in the original form (no compression offered)
}
void layout(auto& io, OneOf<Welcome> auto& m) {
  io.num("version", m.version);
  io.num("max_payload", m.max_payload);
  io.num("session_id", m.session_id);
  io.rest_json("device description", m.json);
}
void layout(auto& io, OneOf<ErrorMsg> auto& m) {
  io.template code<std::uint16_t>("code", m.code);
  io.num("ref", m.ref);
  io.rest_text("text", m.text);
}
void layout(auto& io, OneOf<Ping, Pong> auto& m) { io.rest("data", m.data, MaxBytes{64, "exceeds 64 bytes", true}); }
void layout(auto&, OneOf<Bye, StatusReq, Unsubscribe, LeaseRelease, LeaseReleased> auto&) {}
void layout(auto& io, OneOf<WriteFrames> auto& m) { io.frames(m.frames); }
void layout(auto& io, OneOf<ReadReg> auto& m) { io.num("index", m.index, kRegisterIndex); }
void layout(auto& io, OneOf<RegValue> auto& m) {
  io.num("index", m.index, kRegisterIndex);
  io.num("value", m.value);
}
void layout(auto& io, OneOf<Upload> auto& m) {
  io.num("address", m.address);
  io.rest("data", m.data);
  io.check([&] { return m.data.empty() ? std::string("is empty; an UPLOAD carries at least 1 byte") : std::string(); });
  // Device addresses are 32-bit: a range that wraps past 4 GiB is malformed, whoever sends it
  // (socket, binary trace) — the text trace reader refuses the same range.
  io.check([&] { return address_space_problem(m.address, m.data.size()); });
}
void layout(auto& io, OneOf<UploadAck> auto& m) {
  io.num("address", m.address);
  io.num("length", m.length);
}
void layout(auto& io, OneOf<Readback> auto& m) {
  io.num("address", m.address);
  io.num("length", m.length, Range{1, 64u << 20, "is outside 1..67108864 (64 MiB)"});
  io.check([&] { return address_space_problem(m.address, m.length); });
}
void layout(auto& io, OneOf<ReadbackData> auto& m) {
  io.num("address", m.address);
  io.flag("last", m.last);
  io.rest("data", m.data, MaxBytes{kMaxReadbackChunk, "exceeds the 65536-byte chunk limit"});
}
// The bounds of the inflated size hold before anything is inflated: frames_bytes is a WRITE_FRAMES
// payload size here, and the receiver checks it against its own max_payload (compression.hpp).
void layout(auto& io, OneOf<WriteFramesZ> auto& m) {
  io.template code<std::uint8_t>("codec", m.codec, Range{1, 1, "is not a known codec (1 = zstd)"});
  io.num("frames_bytes", m.frames_bytes);
  io.check([&] {
    if (m.frames_bytes != 0 && m.frames_bytes <= kMaxPayload && m.frames_bytes % kFrameBytes == 0) return std::string();
    return std::to_string(m.frames_bytes) + " is not a WRITE_FRAMES payload size (a multiple of 9, 9..16777216)";
  });
  io.rest("data", m.data);
  io.check([&] { return m.data.empty() ? std::string("is empty") : std::string(); });
}
void layout(auto& io, OneOf<Dmc1Words> auto& m) {
  io.rest("words", m.bytes);
  io.check([&] {
    if (m.bytes.empty()) return std::string("are empty; send at least one 8-byte command word");
    if (m.bytes.size() % kDmc1WordBytes != 0)
      return "of " + std::to_string(m.bytes.size()) + " bytes are not whole 8-byte command words";
    return std::string();
  });
}
void layout(auto& io, OneOf<FenceMsg, FenceDone> auto& m) { io.num("id", m.id); }
void layout(auto& io, OneOf<StatusReply> auto& m) { io.rest_json("status", m.json); }
void layout(auto& io, OneOf<Subscribe> auto& m) {
  io.template code<std::uint8_t>("format", m.format, Range{0, 3, "is not 0..3"});
  io.num("max_fps", m.max_fps);
  io.template optional_code<std::uint8_t>("source", m.source, kSource);  // absent in the original 3-byte form
}
void layout(auto& io, OneOf<FrameData> auto& m) {
  io.num("number", m.number);
  io.num("width", m.width);
  io.num("height", m.height);
  io.template code<std::uint8_t>("format", m.format, Range{0, 2, "is not a pixel format (0..2)"});
  io.template code<std::uint8_t>("source", m.source, kSource);
  io.num("crc", m.crc);
  io.num("swap_ns", m.swap_ns);
  io.rest("pixels", m.pixels);
  io.check([&] {
    const std::uint64_t expect = std::uint64_t{m.width} * m.height * bytes_per_pixel(m.format);
    if (m.pixels.size() == expect) return std::string();
    return "of " + std::to_string(m.pixels.size()) + " bytes do not match " + std::to_string(m.width) + "x" +
           std::to_string(m.height) + " " + std::string(to_string(m.format)) + " (" + std::to_string(expect) + " bytes)";
  });
}
void layout(auto& io, OneOf<LeaseAcquire> auto& m) {
  io.template code<std::uint8_t>("mode", m.mode, Range{0, 1, "is not 0 (wait) or 1 (fail if busy)"});
}
void layout(auto& io, OneOf<LeaseGranted> auto& m) { io.num("session_id", m.session_id); }
void layout(auto& io, OneOf<DeviceEvent> auto& m) { io.rest_json("event", m.json); }

// ---- the message table, derived from the Payload variant ----------------------------------

template <class T>
std::optional<DecodeError> decode_as(std::span<const std::uint8_t> payload, Payload& out) {
  T m;
  FieldReader r(T::kName, payload);
  layout(r, m);
  auto error = r.finish();
  out = std::move(m);
  return error;
}

using Decoder = std::optional<DecodeError> (*)(std::span<const std::uint8_t>, Payload&);
struct TypeEntry {
  std::string_view name;
  Decoder decode = nullptr;  // nullptr: not a message type
  Sender sender = Sender::Server;
};

// Indexed by the type byte.
constexpr std::array<TypeEntry, 256> kTypes = []<std::size_t... I>(std::index_sequence<I...>) {
  std::array<TypeEntry, 256> t{};
  ((t[static_cast<std::uint8_t>(std::variant_alternative_t<I, Payload>::kType)] =
        TypeEntry{std::variant_alternative_t<I, Payload>::kName, &decode_as<std::variant_alternative_t<I, Payload>>,
                  std::variant_alternative_t<I, Payload>::kSender}),
   ...);
  return t;
}(std::make_index_sequence<std::variant_size_v<Payload>>{});

}  // namespace

std::string_view to_string(MsgType t) {
  const auto& e = kTypes[static_cast<std::uint8_t>(t)];
  return e.decode ? e.name : "UNKNOWN";
}

bool is_known_type(std::uint8_t t) { return kTypes[t].decode != nullptr; }

Sender sender(MsgType t) { return kTypes[static_cast<std::uint8_t>(t)].sender; }

std::string_view to_string(ErrorCode c) {
  switch (c) {
    case ErrorCode::BadMagic: return "BAD_MAGIC";
    case ErrorCode::BadVersion: return "BAD_VERSION";
    case ErrorCode::UnknownType: return "UNKNOWN_TYPE";
    case ErrorCode::TooLarge: return "TOO_LARGE";
    case ErrorCode::Malformed: return "MALFORMED";
    case ErrorCode::AuthFailed: return "AUTH_FAILED";
    case ErrorCode::NotHandshaken: return "NOT_HANDSHAKEN";
    case ErrorCode::Busy: return "BUSY";
    case ErrorCode::NoLease: return "NO_LEASE";
    case ErrorCode::DeviceError: return "DEVICE_ERROR";
    case ErrorCode::DeviceGone: return "DEVICE_GONE";
    case ErrorCode::Timeout: return "TIMEOUT";
    case ErrorCode::ServerFull: return "SERVER_FULL";
    case ErrorCode::Range: return "RANGE";
    case ErrorCode::ShuttingDown: return "SHUTTING_DOWN";
    case ErrorCode::Internal: return "INTERNAL";
    case ErrorCode::BadFrame: return "BAD_FRAME";
    case ErrorCode::Unavailable: return "UNAVAILABLE";
    case ErrorCode::WrongDevice: return "WRONG_DEVICE";
  }
  return "UNKNOWN_ERROR";
}

std::uint64_t Dmc1Words::word(std::size_t i) const { return get_le<std::uint64_t>(bytes.data() + i * kDmc1WordBytes); }

void append_dmc1_words(std::span<const std::uint64_t> words, std::vector<std::uint8_t>& out) {
  out.reserve(out.size() + words.size() * kDmc1WordBytes);
  for (const auto w : words) put_le(out, w);
}

std::vector<std::uint64_t> dmc1_words_of(std::span<const std::uint8_t> bytes) {
  std::vector<std::uint64_t> out(bytes.size() / kDmc1WordBytes);
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = get_le<std::uint64_t>(bytes.data() + i * kDmc1WordBytes);
  return out;
}

std::string_view to_string(Codec c) { return c == Codec::Zstd ? "zstd" : "?"; }

std::string_view to_string(FrameSource s) {
  switch (s) {
    case FrameSource::Board: return "board";
    case FrameSource::Sim: return "sim";
    case FrameSource::Diff: return "diff";
  }
  return "?";
}

std::optional<FrameSource> parse_frame_source(std::string_view s) {
  if (s == "board") return FrameSource::Board;
  if (s == "sim") return FrameSource::Sim;
  if (s == "diff") return FrameSource::Diff;
  return std::nullopt;
}

MsgType type_of(const Payload& p) {
  return std::visit([](const auto& m) { return std::remove_cvref_t<decltype(m)>::kType; }, p);
}

std::string json_object_problem(std::string_view text) {
  // Bound the nesting first: deep nesting costs stack in consumers that walk the tree.
  unsigned depth = 0;
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      if (c == '\\') ++i;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      if (++depth > kMaxJsonDepth) return "is nested deeper than " + std::to_string(kMaxJsonDepth) + " levels";
    } else if ((c == '}' || c == ']') && depth > 0) {
      --depth;
    }
  }
  const auto j = nlohmann::json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return "is not valid UTF-8 JSON";
  if (!j.is_object()) return "is JSON but not an object ({...})";
  return {};
}

void encode_header(MsgType type, std::uint32_t length, std::uint32_t request_id, std::uint8_t* out12) {
  out12[0] = kMagic0;
  out12[1] = kMagic1;
  out12[2] = kSocketVersion;
  out12[3] = static_cast<std::uint8_t>(type);
  for (int i = 0; i < 4; ++i) out12[4 + i] = static_cast<std::uint8_t>(length >> (8 * i));
  for (int i = 0; i < 4; ++i) out12[8 + i] = static_cast<std::uint8_t>(request_id >> (8 * i));
}

void encode(const Message& m, std::vector<std::uint8_t>& out) {
  const std::size_t start = out.size();
  out.resize(start + kHeaderBytes);
  FieldWriter w(out);
  std::visit([&w](const auto& payload) { layout(w, payload); }, m.payload);
  const auto length = static_cast<std::uint32_t>(out.size() - start - kHeaderBytes);
  encode_header(type_of(m.payload), length, m.request_id, out.data() + start);
}

std::vector<std::uint8_t> encode(const Message& m) {
  std::vector<std::uint8_t> out;
  encode(m, out);
  return out;
}

namespace {

void read_header(std::span<const std::uint8_t, kHeaderBytes> b, Header& out) {
  out.version = b[2];
  out.type = static_cast<MsgType>(b[3]);
  out.length = get_le<std::uint32_t>(b.data() + 4);
  out.request_id = get_le<std::uint32_t>(b.data() + 8);
}

// The first problem of a header, in the order decode_header checks them (off the hot path).
[[gnu::cold, gnu::noinline]] DecodeError header_problem(std::span<const std::uint8_t, kHeaderBytes> b,
                                                        std::uint32_t max_payload, Header& out) {
  if (b[0] != kMagic0 || b[1] != kMagic1) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "bad magic 0x%02X 0x%02X (expected 'G' 'B'); is this a gpubridge client?", b[0], b[1]);
    return DecodeError{ErrorCode::BadMagic, buf};
  }
  if (b[2] != kSocketVersion)
    return DecodeError{ErrorCode::BadVersion, "protocol version " + std::to_string(b[2]) +
                                                  " is not supported; this server speaks version 1"};
  if (!is_known_type(b[3])) {
    char buf[80];
    std::snprintf(buf, sizeof buf, "unknown message type 0x%02X", b[3]);
    return DecodeError{ErrorCode::UnknownType, buf};
  }
  read_header(b, out);
  return DecodeError{ErrorCode::TooLarge, std::string(to_string(out.type)) + " payload length " + std::to_string(out.length) +
                                              " exceeds the maximum of " + std::to_string(max_payload) +
                                              " bytes; split it into smaller messages"};
}

}  // namespace

std::optional<DecodeError> decode_header(std::span<const std::uint8_t, kHeaderBytes> b, std::uint32_t max_payload,
                                         Header& out) {
  if (b[0] == kMagic0 && b[1] == kMagic1 && b[2] == kSocketVersion && kTypes[b[3]].decode &&
      get_le<std::uint32_t>(b.data() + 4) <= max_payload) [[likely]] {
    read_header(b, out);
    return std::nullopt;
  }
  return header_problem(b, max_payload, out);
}

std::optional<DecodeError> decode_payload(const Header& h, std::span<const std::uint8_t> payload, Message& out) {
  out.request_id = h.request_id;
  const auto& entry = kTypes[static_cast<std::uint8_t>(h.type)];
  if (!entry.decode) return DecodeError{ErrorCode::UnknownType, std::string(to_string(h.type)) + " has no decoder"};
  return entry.decode(payload, out.payload);
}

}  // namespace gpubridge::protocol
