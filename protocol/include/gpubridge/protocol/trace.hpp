#pragma once
// Binary traces (docs/protocol.md, "Traces"): a recorded client stream.
//   file header: "GBTRACE\0" | u16 version (1) | u16 flags (0) | u32 json_len (≤ 64 KiB) | JSON object
//   records:     u64 timestamp_ns (non-decreasing) | one complete socket message (header + payload)
// All integers little-endian. Records carry only device-affecting client messages: WRITE_FRAMES,
// UPLOAD, FENCE, READ_REG, READBACK. The reader is streaming: it holds one record at a time and
// pulls bytes from a ByteSource, so the same code reads files and fuzzer inputs.
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/command_stream.hpp"
#include "gpubridge/protocol/device_kind.hpp"

namespace gpubridge::protocol {

inline constexpr char kTraceMagic[8] = {'G', 'B', 'T', 'R', 'A', 'C', 'E', '\0'};
inline constexpr std::uint16_t kTraceVersion = 1;
inline constexpr std::size_t kTraceHeaderBytes = 16;  // magic + version + flags + json_len
inline constexpr std::uint32_t kMaxTraceJson = 64u << 10;
inline constexpr std::size_t kTraceTimestampBytes = 8;

// Where trace bytes come from. read() fills up to out.size() bytes and returns how many it
// read; it returns 0 only at the end of the input.
class ByteSource {
 public:
  virtual ~ByteSource() = default;
  virtual Result<std::size_t> read(std::span<std::uint8_t> out) = 0;
};

// A ByteSource over bytes in memory (fuzzers, tests, the daemon's in-memory recordings).
class MemorySource final : public ByteSource {
 public:
  explicit MemorySource(std::span<const std::uint8_t> bytes) : bytes_(bytes) {}
  Result<std::size_t> read(std::span<std::uint8_t> out) override;

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t pos_ = 0;
};

class BinaryTraceReader {
 public:
  // name_for_errors prefixes every message ("scene.gbt: record 3 at byte 120: ...").
  BinaryTraceReader(ByteSource& source, std::string name_for_errors);
  // Reads and validates the file header; call once before next().
  Result<void> open();
  const std::string& metadata_json() const { return metadata_; }
  // The metadata's "device_kind" (docs/protocol.md 18.1); spigpu when it has none.
  DeviceKind device_kind() const { return kind_; }
  // spigpu traces: true: `out` holds the next record; false: clean end of the trace. A trace of
  // another device kind is an error saying what reads it.
  Result<bool> next(TimedCommand& out);
  // DMC-1 traces (records DMC1_WORDS or FENCE): true: `words` holds the next record's command words
  // (empty for a FENCE) and `timestamp_ns` its time; false: clean end of the trace.
  Result<bool> next_dmc1(std::uint64_t& timestamp_ns, std::vector<std::uint64_t>& words);
  std::uint64_t records_read() const { return records_; }

 private:
  Result<bool> read_exact(std::span<std::uint8_t> out, bool eof_ok);
  // The next record's message, of a type `allowed` accepts (`allowed_text` lists them for errors).
  Result<bool> next_message(Message& m, std::uint64_t& timestamp, bool (*allowed)(MsgType), const char* allowed_text);
  Error fail(std::uint64_t at, const std::string& what) const;

  ByteSource& source_;
  std::string name_;
  std::string metadata_;
  std::vector<std::uint8_t> record_;  // one record's message bytes, reused
  std::uint64_t offset_ = 0;          // bytes consumed from the source
  std::uint64_t records_ = 0;
  std::uint64_t last_timestamp_ = 0;
  bool opened_ = false;
  DeviceKind kind_ = DeviceKind::Spigpu;
};

// The device kind trace metadata names in its optional "device_kind" (docs/protocol.md 18.1):
// spigpu when it has none; an error ("device_kind 5 is not a device kind (spigpu, dmc1)") when the
// value is not a kind's name. metadata_json must already be a JSON object (json_object_problem).
Result<DeviceKind> trace_metadata_device_kind(std::string_view metadata_json);

// The device kind a binary trace held in memory records (its header and metadata only).
Result<DeviceKind> binary_trace_device_kind(std::span<const std::uint8_t> bytes, const std::string& name_for_errors);
// Reads a whole DMC-1 binary trace held in memory: every command word, in order.
Result<std::vector<std::uint64_t>> read_dmc1_trace(std::span<const std::uint8_t> bytes, const std::string& name_for_errors);
// Appends one record holding message m (a DMC-1 trace's DMC1_WORDS or FENCE; spigpu traces use
// append_trace_record).
void append_trace_message(std::uint64_t timestamp_ns, const Message& m, std::vector<std::uint8_t>& out);

// Reads a whole binary trace held in memory.
Result<CommandStream> read_binary_trace(std::span<const std::uint8_t> bytes, const std::string& name_for_errors);

// Writing. The metadata must be a JSON object (stored verbatim, or compacted when it spans
// several lines); records get request id = record number (1-based). Commands are validated with
// command_problem().
Result<void> append_trace_header(std::string_view metadata_json, std::vector<std::uint8_t>& out);
Result<void> append_trace_record(const TimedCommand& c, std::uint64_t record_number, std::vector<std::uint8_t>& out);
Result<std::vector<std::uint8_t>> write_binary_trace(const CommandStream& s);

// The one-line form metadata is stored in (binary header and text `.meta`): verbatim when it has
// no line break, else re-serialised compactly.
std::string trace_metadata_line(std::string_view metadata_json);

// True when bytes start with the binary trace magic (format sniffing).
bool looks_like_binary_trace(std::span<const std::uint8_t> bytes);

}  // namespace gpubridge::protocol
