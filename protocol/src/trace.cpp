// Binary trace reader and writer (docs/protocol.md, "Traces"). The reader holds one record at
// a time; its memory is bounded by the largest message (kMaxPayload) whatever the file size.
#include "gpubridge/protocol/trace.hpp"

#include <algorithm>
#include <cstring>

#include <nlohmann/json.hpp>

namespace gpubridge::protocol {
namespace {

bool is_trace_record_type(MsgType t) {
  return t == MsgType::WriteFrames || t == MsgType::Upload || t == MsgType::Fence || t == MsgType::ReadReg ||
         t == MsgType::Readback;
}
bool is_dmc1_record_type(MsgType t) { return t == MsgType::Dmc1Words || t == MsgType::Fence; }

template <class T>
T get_le(const std::uint8_t* p) {
  std::uint64_t v = 0;
  for (std::size_t i = sizeof(T); i-- > 0;) v = (v << 8) | p[i];
  return static_cast<T>(v);
}
template <class T>
void put_le(std::vector<std::uint8_t>& out, T v) {
  for (std::size_t i = 0; i < sizeof(T); ++i) out.push_back(static_cast<std::uint8_t>(std::uint64_t{v} >> (8 * i)));
}

// Payload bytes are read in slices of this size so that a header claiming a large payload in a
// short (truncated or hostile) file costs only what the file really holds.
constexpr std::size_t kReadSlice = 64u << 10;

}  // namespace

Result<std::size_t> MemorySource::read(std::span<std::uint8_t> out) {
  const std::size_t n = std::min(out.size(), bytes_.size() - pos_);
  if (n > 0) std::memcpy(out.data(), bytes_.data() + pos_, n);
  pos_ += n;
  return n;
}

BinaryTraceReader::BinaryTraceReader(ByteSource& source, std::string name_for_errors)
    : source_(source), name_(std::move(name_for_errors)) {}

Error BinaryTraceReader::fail(std::uint64_t at, const std::string& what) const {
  std::string where = records_ > 0 || opened_ ? "record " + std::to_string(records_) + " at byte " + std::to_string(at)
                                              : "byte " + std::to_string(at);
  return make_error(name_ + ": " + where + ": " + what);
}

Result<bool> BinaryTraceReader::read_exact(std::span<std::uint8_t> out, bool eof_ok) {
  std::size_t got = 0;
  while (got < out.size()) {
    auto n = source_.read(out.subspan(got));
    if (!n) return make_error(name_ + ": " + n.error().message);
    if (*n == 0) break;
    got += *n;
  }
  offset_ += got;
  if (got == out.size()) return true;
  if (got == 0 && eof_ok) return false;
  return fail(offset_, "the trace ends " + std::to_string(out.size() - got) + " bytes early (truncated file?)");
}

Result<void> BinaryTraceReader::open() {
  if (opened_) return make_error(name_ + ": open() called twice");
  std::uint8_t h[kTraceHeaderBytes];
  if (auto r = read_exact(h, false); !r) return r.error();
  if (std::memcmp(h, kTraceMagic, sizeof kTraceMagic) != 0)
    return fail(0, "not a gpubridge binary trace (magic is not \"GBTRACE\\0\"); text traces use .trace/.txt");
  const auto version = get_le<std::uint16_t>(h + 8);
  const auto flags = get_le<std::uint16_t>(h + 10);
  const auto json_len = get_le<std::uint32_t>(h + 12);
  if (version != kTraceVersion)
    return fail(8, "trace version " + std::to_string(version) + " is not supported (this reader knows version 1)");
  if (flags != 0) return fail(10, "flags " + std::to_string(flags) + " must be 0 in version 1");
  if (json_len > kMaxTraceJson)
    return fail(12, "metadata length " + std::to_string(json_len) + " exceeds the 65536-byte limit");
  std::string json(json_len, '\0');
  if (auto r = read_exact(std::span(reinterpret_cast<std::uint8_t*>(json.data()), json.size()), false); !r)
    return r.error();
  if (auto problem = json_object_problem(json); !problem.empty()) return fail(16, "metadata " + problem);
  const auto kind = trace_metadata_device_kind(json);
  if (!kind) return fail(16, "metadata " + kind.error().message);
  kind_ = *kind;
  metadata_ = std::move(json);
  opened_ = true;
  return {};
}

Result<bool> BinaryTraceReader::next(TimedCommand& out) {
  if (opened_ && kind_ != DeviceKind::Spigpu)
    return make_error(name_ + ": a " + std::string(device_kind_info(kind_).label) + " trace (metadata \"device_kind\": \"" +
                      std::string(device_kind_info(kind_).name) + "\"), not a spigpu one: play it to a daemon serving a " +
                      std::string(device_kind_info(kind_).label) + " (gpubridge play) or render it with gpubridge render --device " +
                      std::string(device_kind_info(kind_).name));
  Message m;
  std::uint64_t timestamp = 0;
  const std::uint64_t record_start = offset_;
  auto more = next_message(m, timestamp, &is_trace_record_type, "only WRITE_FRAMES, UPLOAD, FENCE, READ_REG, READBACK");
  if (!more || !*more) return more;
  auto cmd = command_from_message(m);
  if (!cmd) return fail(record_start, "internal: record type has no command");  // excluded by next_message
  out.timestamp_ns = timestamp;
  out.command = std::move(*cmd);
  return true;
}

Result<bool> BinaryTraceReader::next_dmc1(std::uint64_t& timestamp_ns, std::vector<std::uint64_t>& words) {
  if (opened_ && kind_ != DeviceKind::Dmc1)
    return make_error(name_ + ": a " + std::string(device_kind_info(kind_).label) + " trace, not a DMC-1 one");
  Message m;
  auto more = next_message(m, timestamp_ns, &is_dmc1_record_type, "a DMC-1 trace holds only DMC1_WORDS and FENCE");
  if (!more || !*more) return more;
  if (const auto* w = std::get_if<Dmc1Words>(&m.payload)) words = dmc1_words_of(w->bytes);
  else words.clear();
  return true;
}

Result<bool> BinaryTraceReader::next_message(Message& m, std::uint64_t& out_timestamp, bool (*allowed)(MsgType),
                                             const char* allowed_text) {
  if (!opened_) return make_error(name_ + ": next() before open()");
  const std::uint64_t record_start = offset_;
  std::uint8_t head[kTraceTimestampBytes + kHeaderBytes];
  auto got_ts = read_exact(std::span(head, kTraceTimestampBytes), true);
  if (!got_ts) return got_ts.error();
  if (!*got_ts) return false;  // clean end between records
  if (auto r = read_exact(std::span(head + kTraceTimestampBytes, kHeaderBytes), false); !r) return r.error();

  const auto timestamp = get_le<std::uint64_t>(head);
  if (timestamp < last_timestamp_)
    return fail(record_start, "timestamp " + std::to_string(timestamp) + " ns is earlier than the previous record's " +
                                  std::to_string(last_timestamp_) + " ns; timestamps must not decrease");
  Header h;
  if (auto e = decode_header(std::span<const std::uint8_t, kHeaderBytes>(head + kTraceTimestampBytes, kHeaderBytes),
                             kMaxPayload, h))
    return fail(record_start + kTraceTimestampBytes, e->message);
  if (!allowed(h.type))
    return fail(record_start + kTraceTimestampBytes,
                std::string(to_string(h.type)) + " cannot appear in a trace (" + allowed_text + ")");

  record_.clear();
  while (record_.size() < h.length) {
    const std::size_t old = record_.size();
    record_.resize(old + std::min<std::size_t>(kReadSlice, h.length - old));
    if (auto r = read_exact(std::span(record_).subspan(old), false); !r) return r.error();
  }
  if (auto e = decode_payload(h, record_, m)) return fail(record_start + kTraceTimestampBytes + kHeaderBytes, e->message);
  out_timestamp = timestamp;
  last_timestamp_ = timestamp;
  ++records_;
  return true;
}

Result<CommandStream> read_binary_trace(std::span<const std::uint8_t> bytes, const std::string& name_for_errors) {
  MemorySource src(bytes);
  BinaryTraceReader reader(src, name_for_errors);
  if (auto r = reader.open(); !r) return r.error();
  CommandStream s;
  s.metadata_json = reader.metadata_json();
  for (;;) {
    TimedCommand c;
    auto more = reader.next(c);
    if (!more) return more.error();
    if (!*more) break;
    s.commands.push_back(std::move(c));
  }
  return s;
}

Result<DeviceKind> trace_metadata_device_kind(std::string_view metadata_json) {
  const auto meta = nlohmann::json::parse(metadata_json, nullptr, /*allow_exceptions=*/false);
  if (!meta.is_object() || !meta.contains("device_kind")) return DeviceKind::Spigpu;
  const auto& k = meta["device_kind"];
  const auto kind = k.is_string() ? parse_device_kind(k.get<std::string>()) : std::nullopt;
  if (!kind) return make_error("device_kind " + k.dump() + " is not a device kind (" + device_kind_names() + ")");
  return *kind;
}

Result<DeviceKind> binary_trace_device_kind(std::span<const std::uint8_t> bytes, const std::string& name_for_errors) {
  MemorySource src(bytes);
  BinaryTraceReader reader(src, name_for_errors);
  if (auto r = reader.open(); !r) return r.error();
  return reader.device_kind();
}

Result<std::vector<std::uint64_t>> read_dmc1_trace(std::span<const std::uint8_t> bytes, const std::string& name_for_errors) {
  MemorySource src(bytes);
  BinaryTraceReader reader(src, name_for_errors);
  if (auto r = reader.open(); !r) return r.error();
  std::vector<std::uint64_t> all, words;
  std::uint64_t timestamp = 0;
  for (;;) {
    auto more = reader.next_dmc1(timestamp, words);
    if (!more) return more.error();
    if (!*more) return all;
    all.insert(all.end(), words.begin(), words.end());
  }
}

void append_trace_message(std::uint64_t timestamp_ns, const Message& m, std::vector<std::uint8_t>& out) {
  put_le(out, timestamp_ns);
  encode(m, out);
}

Result<void> append_trace_header(std::string_view metadata_json, std::vector<std::uint8_t>& out) {
  const std::string_view text = metadata_json.empty() ? std::string_view("{}") : metadata_json;
  if (auto problem = json_object_problem(text); !problem.empty())
    return make_error("trace metadata " + problem + "; pass a JSON object such as {\"created_by\": \"me\"}");
  // Kept verbatim when it fits on one line (so binary -> text -> binary is byte-identical);
  // multi-line metadata is stored compactly, which is also how the text form writes it.
  const std::string stored = trace_metadata_line(text);
  if (stored.size() > kMaxTraceJson)
    return make_error("trace metadata of " + std::to_string(stored.size()) + " bytes exceeds the 65536-byte limit");
  out.insert(out.end(), std::begin(kTraceMagic), std::end(kTraceMagic));
  put_le(out, kTraceVersion);
  put_le(out, std::uint16_t{0});
  put_le(out, static_cast<std::uint32_t>(stored.size()));
  out.insert(out.end(), stored.begin(), stored.end());
  return {};
}

Result<void> append_trace_record(const TimedCommand& c, std::uint64_t record_number, std::vector<std::uint8_t>& out) {
  if (auto problem = command_problem(c.command); !problem.empty())
    return make_error("trace record " + std::to_string(record_number) + ": " + problem);
  put_le(out, c.timestamp_ns);
  encode(to_message(c.command, static_cast<std::uint32_t>(record_number)), out);
  return {};
}

Result<std::vector<std::uint8_t>> write_binary_trace(const CommandStream& s) {
  std::vector<std::uint8_t> out;
  if (auto r = append_trace_header(s.metadata_json, out); !r) return r.error();  // also: a JSON object
  // A CommandStream holds spigpu commands: metadata naming another kind would make a trace that
  // every reader refuses (DMC-1 traces are written record by record: append_trace_message).
  const auto kind = trace_metadata_device_kind(s.metadata_json);
  if (!kind) return make_error("trace metadata " + kind.error().message);
  if (*kind != DeviceKind::Spigpu)
    return make_error("trace metadata says device_kind \"" + std::string(device_kind_info(*kind).name) +
                      "\", but the commands are spigpu register writes; remove \"device_kind\" or set it to \"spigpu\"");
  std::uint64_t last = 0;
  for (std::size_t i = 0; i < s.commands.size(); ++i) {
    const auto& c = s.commands[i];
    if (c.timestamp_ns < last)
      return make_error("trace record " + std::to_string(i) + ": timestamp " + std::to_string(c.timestamp_ns) +
                        " ns is earlier than the previous record's; timestamps must not decrease");
    last = c.timestamp_ns;
    if (auto r = append_trace_record(c, i + 1, out); !r) return r.error();
  }
  return out;
}

std::string trace_metadata_line(std::string_view metadata_json) {
  if (metadata_json.find_first_of("\r\n") == std::string_view::npos) return std::string(metadata_json);
  auto j = nlohmann::json::parse(metadata_json, nullptr, /*allow_exceptions=*/false);
  return j.is_discarded() ? std::string("{}") : j.dump();
}

bool looks_like_binary_trace(std::span<const std::uint8_t> bytes) {
  return bytes.size() >= sizeof kTraceMagic && std::memcmp(bytes.data(), kTraceMagic, sizeof kTraceMagic) == 0;
}

}  // namespace gpubridge::protocol
