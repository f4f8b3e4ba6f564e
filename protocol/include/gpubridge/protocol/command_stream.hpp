#pragma once
// The typed command stream: what a client asks a device to do, independent of where it came from.
// Binary traces, text traces and the daemon's recorder all produce/consume this; `render`, `play`
// and the simulator execute it. Each command corresponds to exactly one client→server socket
// message of a device-affecting type (WRITE_FRAMES, UPLOAD, FENCE, READ_REG, READBACK).
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::protocol {

// A batch of register writes exactly as they travel on the wire (9 bytes per frame, read bit
// clear). One batch = one WRITE_FRAMES message.
struct FramesCmd {
  std::vector<std::uint8_t> bytes;  // size is a non-zero multiple of kFrameBytes

  FrameView view() const { return FrameView{bytes}; }
  std::size_t size() const { return bytes.size() / kFrameBytes; }
  void push(const Frame& f) { append(bytes, f); }
  friend bool operator==(const FramesCmd&, const FramesCmd&) = default;
};
// Writes `data` to device memory starting at byte `address` (MEM_ADDR/MEM_DATA on hardware).
struct UploadCmd {
  std::uint32_t address = 0;
  std::vector<std::uint8_t> data;  // 1 .. kMaxUploadBytes bytes
  friend bool operator==(const UploadCmd&, const UploadCmd&) = default;
};
// Completion marker: everything before it has executed once it is reported done.
struct FenceCmd {
  std::uint64_t id = 0;
  friend bool operator==(const FenceCmd&, const FenceCmd&) = default;
};
// Reads one register (`play` prints the value).
struct ReadRegCmd {
  std::uint8_t index = 0;  // 0..127
  friend bool operator==(const ReadRegCmd&, const ReadRegCmd&) = default;
};
// Reads `length` bytes of device memory starting at `address`.
struct ReadbackCmd {
  std::uint32_t address = 0;
  std::uint32_t length = 0;  // 1 .. kMaxReadbackBytes
  friend bool operator==(const ReadbackCmd&, const ReadbackCmd&) = default;
};

using Command = std::variant<FramesCmd, UploadCmd, FenceCmd, ReadRegCmd, ReadbackCmd>;

struct TimedCommand {
  std::uint64_t timestamp_ns = 0;  // since the start of the trace; 0 for text traces
  Command command;
  friend bool operator==(const TimedCommand&, const TimedCommand&) = default;
};

// A whole trace in memory. `metadata_json` is the binary trace's JSON object ("{}" when absent).
struct CommandStream {
  std::string metadata_json = "{}";
  std::vector<TimedCommand> commands;
};

// Largest UPLOAD data that fits one message (payload = u32 address + data).
inline constexpr std::uint32_t kMaxUploadBytes = kMaxPayload - 4;
// Largest READBACK length (the server streams it in READBACK_DATA chunks).
inline constexpr std::uint32_t kMaxReadbackBytes = 64u << 20;
// Largest number of frames in one WRITE_FRAMES message.
inline constexpr std::size_t kMaxFramesPerBatch = kMaxPayload / kFrameBytes;

// Builds a CommandStream from register writes and uploads as a host program would send them: writes
// gather into WRITE_FRAMES commands of at most kMaxFramesPerBatch frames, and an upload first closes
// the open batch so that commands keep their order. Call flush() after the last write.
class CommandStreamWriter {
 public:
  explicit CommandStreamWriter(CommandStream& s) : s_(s) {}
  void write(Reg r, std::uint64_t value) { frames_.push_back(write_frame(r, value)); }
  // The open batch, for encoders that append frames themselves (geometry::encode_triangle).
  std::vector<Frame>& frames() { return frames_; }
  void upload(std::uint32_t address, std::vector<std::uint8_t> data);
  void flush();

 private:
  CommandStream& s_;
  std::vector<Frame> frames_;
};

// The socket message carrying a command (request id chosen by the caller). Never fails.
Message to_message(const Command& c, std::uint32_t request_id);
// The command a message carries, or nullopt for message types that do not affect the device
// (HELLO, PING, SUBSCRIBE, ...). Copies the payload bytes out of the parser's buffer.
std::optional<Command> command_from_message(const Message& m);
// The message type a command travels as.
MsgType message_type_of(const Command& c);
// Empty when c can be sent as one message; otherwise what is wrong ("UPLOAD of 0 bytes; ...").
// Checks the same limits the message parser enforces, so a valid command always round-trips.
std::string command_problem(const Command& c);

}  // namespace gpubridge::protocol
