#pragma once
// The gpubridge socket protocol v1 (docs/protocol.md, "Socket protocol"): typed messages, their
// encoder, and an incremental parser that never does I/O. Every message is
//   header (12 bytes, little-endian): magic 'G' 'B' | version u8 (=1) | type u8 | length u32 | request id u32
//   payload (length bytes, at most the negotiated maximum, never more than kMaxPayload).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::protocol {

inline constexpr std::uint8_t kMagic0 = 'G';
inline constexpr std::uint8_t kMagic1 = 'B';
inline constexpr std::uint8_t kSocketVersion = 1;
inline constexpr std::size_t kHeaderBytes = 12;
inline constexpr std::uint32_t kMaxPayload = 16u << 20;        // hard ceiling (16 MiB)
inline constexpr std::uint32_t kMinMaxPayload = 4096;          // the smallest max_payload a server may announce
inline constexpr std::uint32_t kMaxReadbackChunk = 64u << 10;  // READBACK_DATA payload data ≤ 64 KiB
inline constexpr std::size_t kMaxNameBytes = 64;
inline constexpr std::size_t kMaxTokenBytes = 128;

// Message types. Each payload's fields are described once, in wire order, by its layout() in
// messages.cpp (the encoder and the decoder are derived from it), and who sends it by its struct
// below; docs/protocol.md "Socket protocol" is the normative description.
enum class MsgType : std::uint8_t {
  Hello = 0x01,
  Welcome = 0x02,
  Error = 0x03,
  Ping = 0x04,
  Pong = 0x05,
  Bye = 0x06,           // the server answers Bye and closes
  WriteFrames = 0x10,   // lease required
  ReadReg = 0x11,
  RegValue = 0x12,
  Upload = 0x13,        // lease required
  UploadAck = 0x14,
  Readback = 0x15,      // lease required
  ReadbackData = 0x16,
  WriteFramesZ = 0x17,  // lease required; only after WELCOME named a codec (docs/protocol.md 17.6)
  Dmc1Words = 0x18,     // lease required; only to a daemon serving a DMC-1 (docs/protocol.md 17.7)
  Fence = 0x20,
  FenceDone = 0x21,     // every earlier command of this client has executed
  StatusReq = 0x22,
  StatusReply = 0x23,
  Subscribe = 0x30,
  Unsubscribe = 0x31,
  FrameMsg = 0x32,
  LeaseAcquire = 0x40,
  LeaseGranted = 0x41,
  LeaseRelease = 0x42,
  LeaseReleased = 0x43,
  DeviceEvent = 0x50,
};
// Who may send a message (the "Dir" column of docs/protocol.md 17.3).
enum class Sender : std::uint8_t { Client, Server, Either };
std::string_view to_string(MsgType t);
bool is_known_type(std::uint8_t t);
// Who may send messages of type t (Server for an unknown type: no client may send it).
Sender sender(MsgType t);

// Stable error codes carried by Error messages (never renumbered).
enum class ErrorCode : std::uint16_t {
  BadMagic = 1,
  BadVersion = 2,
  UnknownType = 3,
  TooLarge = 4,
  Malformed = 5,
  AuthFailed = 6,
  NotHandshaken = 7,
  Busy = 8,
  NoLease = 9,
  DeviceError = 10,
  DeviceGone = 11,
  Timeout = 12,
  ServerFull = 13,
  Range = 14,
  ShuttingDown = 15,
  Internal = 16,
  BadFrame = 17,
  Unavailable = 18,  // the request needs a daemon feature that is off (SUBSCRIBE source sim/diff without --mirror)
  WrongDevice = 19,  // the message is another device kind's (WRITE_FRAMES to a DMC-1, DMC1_WORDS to a spigpu)
};
std::string_view to_string(ErrorCode c);

enum class FrameFormat : std::uint8_t { Native = 0, RGBA8888 = 1, RGB565 = 2, RGBA2222 = 3 };
enum class LeaseMode : std::uint8_t { Wait = 0, FailIfBusy = 1 };
// Which picture a subscriber wants (docs/protocol.md 17.3, SUBSCRIBE): the device's own frames,
// the mirror simulator's frames, or their difference image. Sim and Diff need mirror mode.
enum class FrameSource : std::uint8_t { Board = 0, Sim = 1, Diff = 2 };
std::string_view to_string(FrameSource s);  // "board" | "sim" | "diff"
std::optional<FrameSource> parse_frame_source(std::string_view s);

struct Header {
  std::uint8_t version = kSocketVersion;
  MsgType type = MsgType::Ping;
  std::uint32_t length = 0;
  std::uint32_t request_id = 0;
};

// Typed payloads, one struct per message type: kType is its type byte, kName its name in
// docs/protocol.md and in error messages, kSender who sends it. Byte spans point into the parser's
// buffer and are valid until the next call to MessageParser::next(), feed() or prepare(); copy
// what you keep.
#define GPUBRIDGE_MESSAGE(T, NAME, SENDER)         \
  static constexpr MsgType kType = MsgType::T;     \
  static constexpr std::string_view kName = NAME;  \
  static constexpr Sender kSender = Sender::SENDER
// Compression of WRITE_FRAMES (docs/protocol.md 17.6). HELLO may end with a byte of codec bits the
// client accepts; the server names its choice in WELCOME's JSON ("compression") and from then on
// the client may send WRITE_FRAMES_Z in that codec. Bits the server does not know are ignored.
enum class Codec : std::uint8_t { Zstd = 1 };
inline constexpr std::uint8_t codec_bit(Codec c) { return static_cast<std::uint8_t>(1u << (static_cast<unsigned>(c) - 1)); }
std::string_view to_string(Codec c);  // "zstd"

struct Hello {
  GPUBRIDGE_MESSAGE(Hello, "HELLO", Client);
  std::uint16_t version = kSocketVersion;
  std::string name;
  std::string token;
  std::optional<std::uint8_t> codecs = std::nullopt;  // codec_bit()s offered; absent = the original form (no compression)
};
struct Welcome {
  GPUBRIDGE_MESSAGE(Welcome, "WELCOME", Server);
  std::uint16_t version = kSocketVersion;
  std::uint32_t max_payload = kMaxPayload;
  std::uint32_t session_id = 0;
  std::string json;  // device description
};
struct ErrorMsg { GPUBRIDGE_MESSAGE(Error, "ERROR", Server); ErrorCode code = ErrorCode::Internal; std::uint32_t ref = 0; std::string text; };
struct Ping { GPUBRIDGE_MESSAGE(Ping, "PING", Either); std::vector<std::uint8_t> data; };
struct Pong { GPUBRIDGE_MESSAGE(Pong, "PONG", Either); std::vector<std::uint8_t> data; };
struct Bye { GPUBRIDGE_MESSAGE(Bye, "BYE", Either); };
struct WriteFrames { GPUBRIDGE_MESSAGE(WriteFrames, "WRITE_FRAMES", Client); FrameView frames; };
struct ReadReg { GPUBRIDGE_MESSAGE(ReadReg, "READ_REG", Client); std::uint8_t index = 0; };
struct RegValue { GPUBRIDGE_MESSAGE(RegValue, "REG_VALUE", Server); std::uint8_t index = 0; std::uint64_t value = 0; };
struct Upload { GPUBRIDGE_MESSAGE(Upload, "UPLOAD", Client); std::uint32_t address = 0; std::span<const std::uint8_t> data; };
struct UploadAck { GPUBRIDGE_MESSAGE(UploadAck, "UPLOAD_ACK", Server); std::uint32_t address = 0; std::uint32_t length = 0; };
struct Readback { GPUBRIDGE_MESSAGE(Readback, "READBACK", Client); std::uint32_t address = 0; std::uint32_t length = 0; };
struct ReadbackData {
  GPUBRIDGE_MESSAGE(ReadbackData, "READBACK_DATA", Server);
  std::uint32_t address = 0;
  bool last = false;
  std::span<const std::uint8_t> data;
};
// A WRITE_FRAMES payload of frames_bytes bytes, compressed with codec (only after WELCOME chose it).
struct WriteFramesZ {
  GPUBRIDGE_MESSAGE(WriteFramesZ, "WRITE_FRAMES_Z", Client);
  Codec codec = Codec::Zstd;
  std::uint32_t frames_bytes = 0;
  std::span<const std::uint8_t> data;
};
// DMC-1 command words (docs/protocol.md 17.7, docs/dmc1.md): 8 bytes each, little-endian, at least
// one; the whole payload is words, so the bound per message is max_payload / 8 words.
inline constexpr std::size_t kDmc1WordBytes = 8;
struct Dmc1Words {
  GPUBRIDGE_MESSAGE(Dmc1Words, "DMC1_WORDS", Client);
  std::span<const std::uint8_t> bytes;  // a non-zero multiple of kDmc1WordBytes
  std::size_t size() const { return bytes.size() / kDmc1WordBytes; }
  std::uint64_t word(std::size_t i) const;
};
// Little-endian bytes of command words (a DMC1_WORDS payload), appended to out.
void append_dmc1_words(std::span<const std::uint64_t> words, std::vector<std::uint8_t>& out);
// The words of a DMC1_WORDS payload (whole words; a trailing partial word is ignored).
std::vector<std::uint64_t> dmc1_words_of(std::span<const std::uint8_t> bytes);
struct FenceMsg { GPUBRIDGE_MESSAGE(Fence, "FENCE", Client); std::uint64_t id = 0; };
struct FenceDone { GPUBRIDGE_MESSAGE(FenceDone, "FENCE_DONE", Server); std::uint64_t id = 0; };
struct StatusReq { GPUBRIDGE_MESSAGE(StatusReq, "STATUS_REQ", Client); };
struct StatusReply { GPUBRIDGE_MESSAGE(StatusReply, "STATUS_REPLY", Server); std::string json; };
// Without a source, SUBSCRIBE is encoded in the original 3-byte form (board; old daemons accept it).
// An explicit source is a 4th byte, kept as decoded so that re-encoding gives the same bytes.
struct Subscribe {
  GPUBRIDGE_MESSAGE(Subscribe, "SUBSCRIBE", Client);
  FrameFormat format = FrameFormat::Native;
  std::uint16_t max_fps = 0;  // 0 = every frame
  std::optional<FrameSource> source = std::nullopt;  // absent = FrameSource::Board
};
struct Unsubscribe { GPUBRIDGE_MESSAGE(Unsubscribe, "UNSUBSCRIBE", Client); };
struct FrameData {
  GPUBRIDGE_MESSAGE(FrameMsg, "FRAME", Server);
  std::uint32_t number = 0;
  std::uint16_t width = 0, height = 0;
  PixelFormat format = PixelFormat::RGBA8888;
  std::uint32_t crc = 0;
  std::uint64_t swap_ns = 0;
  std::span<const std::uint8_t> pixels;  // width * height * bpp(format)
  FrameSource source = FrameSource::Board;  // payload byte 9 (was reserved 0: board frames are unchanged)
};
struct LeaseAcquire { GPUBRIDGE_MESSAGE(LeaseAcquire, "LEASE_ACQUIRE", Client); LeaseMode mode = LeaseMode::Wait; };
struct LeaseGranted { GPUBRIDGE_MESSAGE(LeaseGranted, "LEASE_GRANTED", Server); std::uint32_t session_id = 0; };
struct LeaseRelease { GPUBRIDGE_MESSAGE(LeaseRelease, "LEASE_RELEASE", Client); };
struct LeaseReleased { GPUBRIDGE_MESSAGE(LeaseReleased, "LEASE_RELEASED", Server); };
struct DeviceEvent { GPUBRIDGE_MESSAGE(DeviceEvent, "DEVICE_EVENT", Server); std::string json; };  // {"event": "...", ...}
#undef GPUBRIDGE_MESSAGE

// Every message type: the decoder, to_string(MsgType), is_known_type() and sender() are derived
// from this list.
using Payload = std::variant<Hello, Welcome, ErrorMsg, Ping, Pong, Bye, WriteFrames, ReadReg, RegValue, Upload,
                             UploadAck, Readback, ReadbackData, WriteFramesZ, Dmc1Words, FenceMsg, FenceDone, StatusReq, StatusReply,
                             Subscribe, Unsubscribe, FrameData, LeaseAcquire, LeaseGranted, LeaseRelease,
                             LeaseReleased, DeviceEvent>;

struct Message {
  std::uint32_t request_id = 0;
  Payload payload;
};

MsgType type_of(const Payload& p);

// Appends the complete wire form (header + payload) of m to out.
void encode(const Message& m, std::vector<std::uint8_t>& out);
std::vector<std::uint8_t> encode(const Message& m);
// Writes only the 12-byte header for a payload of `length` bytes (zero-copy senders).
void encode_header(MsgType type, std::uint32_t length, std::uint32_t request_id, std::uint8_t* out12);

// Decodes one payload whose header has already been validated.
struct DecodeError {
  ErrorCode code;
  std::string message;  // what is wrong and where ("WRITE_FRAMES payload of 10 bytes is not a multiple of 9")
};

// Empty when `text` is a valid UTF-8 JSON object nested at most kMaxJsonDepth deep; otherwise
// what is wrong. Used for every JSON payload and for trace metadata.
inline constexpr unsigned kMaxJsonDepth = 64;
std::string json_object_problem(std::string_view text);

// The two halves of parsing, usable on their own (the binary trace reader uses them).
// decode_header checks magic, version, type and length (against max_payload) in that order.
std::optional<DecodeError> decode_header(std::span<const std::uint8_t, kHeaderBytes> bytes, std::uint32_t max_payload,
                                         Header& out);
// Decodes a payload whose header passed decode_header. Spans in `out` point into `payload`.
// Messages name the field and its payload byte offset; the caller adds the stream position.
std::optional<DecodeError> decode_payload(const Header& h, std::span<const std::uint8_t> payload, Message& out);

// Incremental parser. Bytes go in either way:
//  - feed(bytes) copies them in (tests, fuzzers, small readers);
//  - prepare(n) returns writable space inside the parser's own buffer, the caller reads into it
//    (a socket read) and commit(k) appends the first k of those bytes to the stream: no copy
//    (like Asio's dynamic buffers, but the span may be shorter than n, see prepare()).
// Then call next() until it returns NeedMore. After an Error the parser is poisoned (the stream
// cannot be resynchronised) and keeps returning the same error. A header's length field is
// checked against max_payload before it decides any allocation; the buffer never exceeds
// kHeaderBytes + max_payload plus one feed() or prepare() size (when next() runs between them).
class MessageParser {
 public:
  enum class Status { Ok, NeedMore, Error };

  explicit MessageParser(std::uint32_t max_payload = kMaxPayload);
  void set_max_payload(std::uint32_t max_payload);
  void feed(std::span<const std::uint8_t> bytes);
  // Writable space for at most `max_bytes` incoming bytes (1..max_bytes of them; empty only when
  // max_bytes is 0 or the parser is poisoned). While the message in progress is a large one
  // (valid header, kLargeMessageBytes or more in all), the span ends where that message ends: it
  // then completes at the end of the buffer, which empties, so a stream of large messages is read
  // without moving bytes to make room. Small messages share reads; their partial tails are moved.
  // Invalidates earlier spans (from prepare() and from parsed messages).
  std::span<std::uint8_t> prepare(std::size_t max_bytes);
  // Appends the first n bytes written into the last prepare() span (n beyond it is clamped).
  void commit(std::size_t n);
  Status next(Message& out);
  const DecodeError& error() const { return error_; }
  // Bytes buffered but not yet returned as messages (for trickle/idle accounting).
  std::size_t buffered() const { return end_ - pos_; }
  // Bytes the parser holds in memory (its buffer's capacity).
  std::size_t held_bytes() const { return capacity_; }
  // Total stream offset of the first byte of the message being parsed (for error messages).
  std::uint64_t stream_offset() const { return consumed_ + pos_; }

  // prepare() stops at the end of a message in progress of at least this size (header included).
  static constexpr std::size_t kLargeMessageBytes = 16 * 1024;

 private:
  // Makes room for n more bytes after the unconsumed ones: moves them to the front when that is
  // enough, otherwise grows (doubling, capped at `ceiling` unless n itself needs more).
  void make_room(std::size_t n, std::size_t ceiling);
  // kHeaderBytes + length of the message in progress once its header is buffered and valid.
  std::optional<std::size_t> current_message_bytes() const;

  std::unique_ptr<std::uint8_t[]> buf_;
  std::size_t capacity_ = 0;
  std::size_t pos_ = 0;       // first unconsumed byte
  std::size_t end_ = 0;       // one past the last stream byte
  std::size_t prepared_ = 0;  // size of the span the last prepare() returned
  std::uint64_t consumed_ = 0;
  std::uint32_t max_payload_;
  bool failed_ = false;
  DecodeError error_{ErrorCode::Internal, {}};
};

}  // namespace gpubridge::protocol
