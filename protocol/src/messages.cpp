// Socket protocol v1: message encoder and payload decoder (the incremental parser is message_parser.cpp).
// Every decode problem becomes a DecodeError naming the message type, the field and its byte
// offset in the payload; the parser adds the stream offset of the message.
#include "gpubridge/protocol/messages.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
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

void put_bytes(std::vector<std::uint8_t>& out, std::span<const std::uint8_t> b) { out.insert(out.end(), b.begin(), b.end()); }
void put_string(std::vector<std::uint8_t>& out, std::string_view s) { out.insert(out.end(), s.begin(), s.end()); }

// ---- payload reader with field names for error messages ---------------------------------

class PayloadReader {
 public:
  PayloadReader(MsgType type, std::span<const std::uint8_t> p) : type_(type), p_(p) {}

  std::size_t pos() const { return pos_; }
  std::size_t remaining() const { return p_.size() - pos_; }
  bool failed() const { return error_.has_value(); }
  std::optional<DecodeError> take_error() { return std::move(error_); }

  template <class T>
  T get(const char* field) {
    if (!need(sizeof(T), field)) return T{};
    T v = get_le<T>(p_.data() + pos_);
    pos_ += sizeof(T);
    return v;
  }
  std::span<const std::uint8_t> bytes(std::size_t n, const char* field) {
    if (!need(n, field)) return {};
    auto s = p_.subspan(pos_, n);
    pos_ += n;
    return s;
  }
  std::span<const std::uint8_t> rest() {
    auto s = p_.subspan(pos_);
    pos_ = p_.size();
    return s;
  }
  void expect_end() {
    if (!failed() && pos_ != p_.size())
      fail(ErrorCode::Malformed, std::to_string(p_.size() - pos_) + " unexpected trailing bytes at payload byte " +
                                     std::to_string(pos_));
  }
  void fail(ErrorCode code, const std::string& what) {
    if (!error_) error_ = DecodeError{code, std::string(to_string(type_)) + " " + what};
  }
  // Field value problem: "<TYPE> <field> <what> (payload byte N)".
  void bad_field(const char* field, std::size_t at, const std::string& what) {
    fail(ErrorCode::Malformed, std::string(field) + " " + what + " (payload byte " + std::to_string(at) + ")");
  }

 private:
  bool need(std::size_t n, const char* field) {
    if (failed()) return false;
    if (remaining() < n) {
      fail(ErrorCode::Malformed, "payload of " + std::to_string(p_.size()) + " bytes is too short: " + field +
                                     " needs " + std::to_string(n) + " bytes at payload byte " + std::to_string(pos_));
      return false;
    }
    return true;
  }

  MsgType type_;
  std::span<const std::uint8_t> p_;
  std::size_t pos_ = 0;
  std::optional<DecodeError> error_;
};

std::string as_string(std::span<const std::uint8_t> b) { return std::string(b.begin(), b.end()); }

void read_json(PayloadReader& r, const char* field, std::string& out) {
  const std::size_t at = r.pos();
  out = as_string(r.rest());
  if (r.failed()) return;
  if (auto problem = json_object_problem(out); !problem.empty()) r.bad_field(field, at, problem);
}

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

void read_text(PayloadReader& r, const char* field, std::string& out) {
  const std::size_t at = r.pos();
  out = as_string(r.rest());
  if (!r.failed() && !valid_utf8(out)) r.bad_field(field, at, "is not valid UTF-8");
}

void decode_into(const Header& h, PayloadReader& r, Payload& out) {
  switch (h.type) {
    case MsgType::Hello: {
      Hello m;
      m.version = r.get<std::uint16_t>("version");
      const std::size_t name_at = r.pos();
      const auto name_len = r.get<std::uint8_t>("name_len");
      if (!r.failed() && name_len > kMaxNameBytes)
        r.bad_field("name_len", name_at, std::to_string(name_len) + " exceeds " + std::to_string(kMaxNameBytes) + " bytes");
      m.name = as_string(r.bytes(name_len, "name"));
      const std::size_t token_at = r.pos();
      const auto token_len = r.get<std::uint8_t>("token_len");
      if (!r.failed() && token_len > kMaxTokenBytes)
        r.bad_field("token_len", token_at,
                    std::to_string(token_len) + " exceeds " + std::to_string(kMaxTokenBytes) + " bytes");
      m.token = as_string(r.bytes(token_len, "token"));
      r.expect_end();
      if (!r.failed() && !valid_utf8(m.name)) r.bad_field("name", name_at + 1, "is not valid UTF-8");
      out = std::move(m);
      return;
    }
    case MsgType::Welcome: {
      Welcome m;
      m.version = r.get<std::uint16_t>("version");
      m.max_payload = r.get<std::uint32_t>("max_payload");
      m.session_id = r.get<std::uint32_t>("session_id");
      read_json(r, "device description", m.json);
      out = std::move(m);
      return;
    }
    case MsgType::Error: {
      ErrorMsg m;
      m.code = static_cast<ErrorCode>(r.get<std::uint16_t>("code"));
      m.ref = r.get<std::uint32_t>("ref");
      read_text(r, "text", m.text);
      out = std::move(m);
      return;
    }
    case MsgType::Ping:
    case MsgType::Pong: {
      auto data = r.rest();
      if (data.size() > 64) r.bad_field("data", 0, "of " + std::to_string(data.size()) + " bytes exceeds 64 bytes");
      std::vector<std::uint8_t> copy(data.begin(), data.end());
      if (h.type == MsgType::Ping)
        out = Ping{std::move(copy)};
      else
        out = Pong{std::move(copy)};
      return;
    }
    case MsgType::Bye: r.expect_end(); out = Bye{}; return;
    case MsgType::WriteFrames: {
      auto data = r.rest();
      if (data.empty()) {
        r.fail(ErrorCode::Malformed, "payload is empty; send at least one 9-byte frame");
      } else if (data.size() % kFrameBytes != 0) {
        r.fail(ErrorCode::Malformed, "payload of " + std::to_string(data.size()) + " bytes is not a multiple of 9");
      } else {
        if (const std::size_t f = first_read_frame(FrameView{data}); f * kFrameBytes < data.size())
          r.fail(ErrorCode::BadFrame, "frame " + std::to_string(f) + " (payload byte " +
                                          std::to_string(f * kFrameBytes) + ") has the read bit set; use READ_REG");
      }
      out = WriteFrames{FrameView{data}};
      return;
    }
    case MsgType::ReadReg: {
      ReadReg m;
      m.index = r.get<std::uint8_t>("index");
      if (!r.failed() && m.index >= kRegisterCount)
        r.bad_field("index", 0, std::to_string(m.index) + " exceeds the 7-bit register index range 0..127");
      r.expect_end();
      out = m;
      return;
    }
    case MsgType::RegValue: {
      RegValue m;
      m.index = r.get<std::uint8_t>("index");
      if (!r.failed() && m.index >= kRegisterCount)
        r.bad_field("index", 0, std::to_string(m.index) + " exceeds the 7-bit register index range 0..127");
      m.value = r.get<std::uint64_t>("value");
      r.expect_end();
      out = m;
      return;
    }
    case MsgType::Upload: {
      Upload m;
      m.address = r.get<std::uint32_t>("address");
      m.data = r.rest();
      if (!r.failed() && m.data.empty()) r.bad_field("data", 4, "is empty; an UPLOAD carries at least 1 byte");
      // Device addresses are 32-bit: a range that wraps past 4 GiB is malformed, whoever sends it
      // (socket, binary trace) — the text trace reader refuses the same range.
      if (!r.failed() && std::uint64_t{m.address} + m.data.size() > (std::uint64_t{1} << 32))
        r.bad_field("data", 4, std::to_string(m.data.size()) + " bytes at address " + std::to_string(m.address) +
                                   " run past the 4 GiB address space");
      out = m;
      return;
    }
    case MsgType::UploadAck: {
      UploadAck m;
      m.address = r.get<std::uint32_t>("address");
      m.length = r.get<std::uint32_t>("length");
      r.expect_end();
      out = m;
      return;
    }
    case MsgType::Readback: {
      Readback m;
      m.address = r.get<std::uint32_t>("address");
      m.length = r.get<std::uint32_t>("length");
      if (!r.failed() && (m.length == 0 || m.length > (64u << 20)))
        r.bad_field("length", 4, std::to_string(m.length) + " is outside 1..67108864 (64 MiB)");
      if (!r.failed() && std::uint64_t{m.address} + m.length > (std::uint64_t{1} << 32))
        r.bad_field("length", 4, std::to_string(m.length) + " bytes at address " + std::to_string(m.address) +
                                     " run past the 4 GiB address space");
      r.expect_end();
      out = m;
      return;
    }
    case MsgType::ReadbackData: {
      ReadbackData m;
      m.address = r.get<std::uint32_t>("address");
      const auto last = r.get<std::uint8_t>("last");
      if (!r.failed() && last > 1) r.bad_field("last", 4, std::to_string(last) + " is not 0 or 1");
      m.last = last == 1;
      m.data = r.rest();
      if (!r.failed() && m.data.size() > kMaxReadbackChunk)
        r.bad_field("data", 5, "of " + std::to_string(m.data.size()) + " bytes exceeds the 65536-byte chunk limit");
      out = m;
      return;
    }
    case MsgType::Fence: {
      FenceMsg m;
      m.id = r.get<std::uint64_t>("id");
      r.expect_end();
      out = m;
      return;
    }
    case MsgType::FenceDone: {
      FenceDone m;
      m.id = r.get<std::uint64_t>("id");
      r.expect_end();
      out = m;
      return;
    }
    case MsgType::StatusReq: r.expect_end(); out = StatusReq{}; return;
    case MsgType::StatusReply: {
      StatusReply m;
      read_json(r, "status", m.json);
      out = std::move(m);
      return;
    }
    case MsgType::Subscribe: {
      Subscribe m;
      const auto format = r.get<std::uint8_t>("format");
      if (!r.failed() && format > 3) r.bad_field("format", 0, std::to_string(format) + " is not 0..3");
      m.format = static_cast<FrameFormat>(format);
      m.max_fps = r.get<std::uint16_t>("max_fps");
      // Optional trailing source byte (absent in the original 3-byte form = board).
      if (!r.failed() && r.remaining() > 0) {
        const auto source = r.get<std::uint8_t>("source");
        if (source > 2) r.bad_field("source", 3, std::to_string(source) + " is not 0 (board), 1 (sim) or 2 (diff)");
        m.source = static_cast<FrameSource>(source);
      }
      r.expect_end();
      out = m;
      return;
    }
    case MsgType::Unsubscribe: r.expect_end(); out = Unsubscribe{}; return;
    case MsgType::FrameMsg: {
      FrameData m;
      m.number = r.get<std::uint32_t>("number");
      m.width = r.get<std::uint16_t>("width");
      m.height = r.get<std::uint16_t>("height");
      const auto format = r.get<std::uint8_t>("format");
      if (!r.failed() && format > 2) r.bad_field("format", 8, std::to_string(format) + " is not a pixel format (0..2)");
      m.format = static_cast<PixelFormat>(format);
      const auto source = r.get<std::uint8_t>("source");
      if (!r.failed() && source > 2) r.bad_field("source", 9, std::to_string(source) + " is not 0 (board), 1 (sim) or 2 (diff)");
      m.source = static_cast<FrameSource>(source);
      m.crc = r.get<std::uint32_t>("crc");
      m.swap_ns = r.get<std::uint64_t>("swap_ns");
      m.pixels = r.rest();
      if (!r.failed()) {
        const std::uint64_t expect = std::uint64_t{m.width} * m.height * bytes_per_pixel(m.format);
        if (m.pixels.size() != expect)
          r.bad_field("pixels", 22, "of " + std::to_string(m.pixels.size()) + " bytes do not match " +
                                        std::to_string(m.width) + "x" + std::to_string(m.height) + " " +
                                        std::string(to_string(m.format)) + " (" + std::to_string(expect) + " bytes)");
      }
      out = m;
      return;
    }
    case MsgType::LeaseAcquire: {
      LeaseAcquire m;
      const auto mode = r.get<std::uint8_t>("mode");
      if (!r.failed() && mode > 1) r.bad_field("mode", 0, std::to_string(mode) + " is not 0 (wait) or 1 (fail if busy)");
      m.mode = static_cast<LeaseMode>(mode);
      r.expect_end();
      out = m;
      return;
    }
    case MsgType::LeaseGranted: {
      LeaseGranted m;
      m.session_id = r.get<std::uint32_t>("session_id");
      r.expect_end();
      out = m;
      return;
    }
    case MsgType::LeaseRelease: r.expect_end(); out = LeaseRelease{}; return;
    case MsgType::LeaseReleased: r.expect_end(); out = LeaseReleased{}; return;
    case MsgType::DeviceEvent: {
      DeviceEvent m;
      read_json(r, "event", m.json);
      out = std::move(m);
      return;
    }
  }
  r.fail(ErrorCode::UnknownType, "has no decoder");
}

// ---- encoder ----------------------------------------------------------------------------

struct PayloadEncoder {
  std::vector<std::uint8_t>& o;

  void operator()(const Hello& m) {
    const auto name = std::string_view(m.name).substr(0, kMaxNameBytes);
    const auto token = std::string_view(m.token).substr(0, kMaxTokenBytes);
    put_le(o, m.version);
    put_le(o, static_cast<std::uint8_t>(name.size()));
    put_string(o, name);
    put_le(o, static_cast<std::uint8_t>(token.size()));
    put_string(o, token);
  }
  void operator()(const Welcome& m) {
    put_le(o, m.version);
    put_le(o, m.max_payload);
    put_le(o, m.session_id);
    put_string(o, m.json);
  }
  void operator()(const ErrorMsg& m) {
    put_le(o, static_cast<std::uint16_t>(m.code));
    put_le(o, m.ref);
    put_string(o, m.text);
  }
  void operator()(const Ping& m) { put_bytes(o, std::span(m.data).first(std::min<std::size_t>(m.data.size(), 64))); }
  void operator()(const Pong& m) { put_bytes(o, std::span(m.data).first(std::min<std::size_t>(m.data.size(), 64))); }
  void operator()(const Bye&) {}
  void operator()(const WriteFrames& m) { put_bytes(o, m.frames.bytes); }
  void operator()(const ReadReg& m) { put_le(o, m.index); }
  void operator()(const RegValue& m) {
    put_le(o, m.index);
    put_le(o, m.value);
  }
  void operator()(const Upload& m) {
    put_le(o, m.address);
    put_bytes(o, m.data);
  }
  void operator()(const UploadAck& m) {
    put_le(o, m.address);
    put_le(o, m.length);
  }
  void operator()(const Readback& m) {
    put_le(o, m.address);
    put_le(o, m.length);
  }
  void operator()(const ReadbackData& m) {
    put_le(o, m.address);
    put_le(o, static_cast<std::uint8_t>(m.last ? 1 : 0));
    put_bytes(o, m.data);
  }
  void operator()(const FenceMsg& m) { put_le(o, m.id); }
  void operator()(const FenceDone& m) { put_le(o, m.id); }
  void operator()(const StatusReq&) {}
  void operator()(const StatusReply& m) { put_string(o, m.json); }
  void operator()(const Subscribe& m) {
    put_le(o, static_cast<std::uint8_t>(m.format));
    put_le(o, m.max_fps);
    if (m.source) put_le(o, static_cast<std::uint8_t>(*m.source));
  }
  void operator()(const Unsubscribe&) {}
  void operator()(const FrameData& m) {
    put_le(o, m.number);
    put_le(o, m.width);
    put_le(o, m.height);
    put_le(o, static_cast<std::uint8_t>(m.format));
    put_le(o, static_cast<std::uint8_t>(m.source));
    put_le(o, m.crc);
    put_le(o, m.swap_ns);
    put_bytes(o, m.pixels);
  }
  void operator()(const LeaseAcquire& m) { put_le(o, static_cast<std::uint8_t>(m.mode)); }
  void operator()(const LeaseGranted& m) { put_le(o, m.session_id); }
  void operator()(const LeaseRelease&) {}
  void operator()(const LeaseReleased&) {}
  void operator()(const DeviceEvent& m) { put_string(o, m.json); }
};

constexpr MsgType kTypeOfIndex[] = {
    MsgType::Hello,       MsgType::Welcome,      MsgType::Error,        MsgType::Ping,        MsgType::Pong,
    MsgType::Bye,         MsgType::WriteFrames,  MsgType::ReadReg,      MsgType::RegValue,    MsgType::Upload,
    MsgType::UploadAck,   MsgType::Readback,     MsgType::ReadbackData, MsgType::Fence,       MsgType::FenceDone,
    MsgType::StatusReq,   MsgType::StatusReply,  MsgType::Subscribe,    MsgType::Unsubscribe, MsgType::FrameMsg,
    MsgType::LeaseAcquire, MsgType::LeaseGranted, MsgType::LeaseRelease, MsgType::LeaseReleased, MsgType::DeviceEvent,
};
static_assert(std::size(kTypeOfIndex) == std::variant_size_v<Payload>, "one MsgType per payload alternative");

}  // namespace

std::string_view to_string(MsgType t) {
  switch (t) {
    case MsgType::Hello: return "HELLO";
    case MsgType::Welcome: return "WELCOME";
    case MsgType::Error: return "ERROR";
    case MsgType::Ping: return "PING";
    case MsgType::Pong: return "PONG";
    case MsgType::Bye: return "BYE";
    case MsgType::WriteFrames: return "WRITE_FRAMES";
    case MsgType::ReadReg: return "READ_REG";
    case MsgType::RegValue: return "REG_VALUE";
    case MsgType::Upload: return "UPLOAD";
    case MsgType::UploadAck: return "UPLOAD_ACK";
    case MsgType::Readback: return "READBACK";
    case MsgType::ReadbackData: return "READBACK_DATA";
    case MsgType::Fence: return "FENCE";
    case MsgType::FenceDone: return "FENCE_DONE";
    case MsgType::StatusReq: return "STATUS_REQ";
    case MsgType::StatusReply: return "STATUS_REPLY";
    case MsgType::Subscribe: return "SUBSCRIBE";
    case MsgType::Unsubscribe: return "UNSUBSCRIBE";
    case MsgType::FrameMsg: return "FRAME";
    case MsgType::LeaseAcquire: return "LEASE_ACQUIRE";
    case MsgType::LeaseGranted: return "LEASE_GRANTED";
    case MsgType::LeaseRelease: return "LEASE_RELEASE";
    case MsgType::LeaseReleased: return "LEASE_RELEASED";
    case MsgType::DeviceEvent: return "DEVICE_EVENT";
  }
  return "UNKNOWN";
}

bool is_known_type(std::uint8_t t) {
  return std::any_of(std::begin(kTypeOfIndex), std::end(kTypeOfIndex),
                     [t](MsgType k) { return static_cast<std::uint8_t>(k) == t; });
}

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
  }
  return "UNKNOWN_ERROR";
}

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

MsgType type_of(const Payload& p) { return kTypeOfIndex[p.index()]; }

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
  std::visit(PayloadEncoder{out}, m.payload);
  const auto length = static_cast<std::uint32_t>(out.size() - start - kHeaderBytes);
  encode_header(type_of(m.payload), length, m.request_id, out.data() + start);
}

std::vector<std::uint8_t> encode(const Message& m) {
  std::vector<std::uint8_t> out;
  encode(m, out);
  return out;
}

std::optional<DecodeError> decode_header(std::span<const std::uint8_t, kHeaderBytes> b, std::uint32_t max_payload,
                                         Header& out) {
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
  out.version = b[2];
  out.type = static_cast<MsgType>(b[3]);
  out.length = get_le<std::uint32_t>(b.data() + 4);
  out.request_id = get_le<std::uint32_t>(b.data() + 8);
  if (out.length > max_payload)
    return DecodeError{ErrorCode::TooLarge, std::string(to_string(out.type)) + " payload length " +
                                                std::to_string(out.length) + " exceeds the maximum of " +
                                                std::to_string(max_payload) + " bytes; split it into smaller messages"};
  return std::nullopt;
}

std::optional<DecodeError> decode_payload(const Header& h, std::span<const std::uint8_t> payload, Message& out) {
  PayloadReader r(h.type, payload);
  out.request_id = h.request_id;
  decode_into(h, r, out.payload);
  return r.take_error();
}

}  // namespace gpubridge::protocol
