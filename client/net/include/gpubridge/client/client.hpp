#pragma once
// Client: a synchronous connection to gpubridged (socket protocol v1, docs/protocol.md).
// Every blocking call takes a timeout. One Client per thread (the viewer subscribes on its own
// Client in its own thread); the class does no locking.
//
// Errors: protocol ERROR replies become Error{code = 1000 + ErrorCode, message = "<CODE>: text"}.
// WRITE_FRAMES is fire-and-forget: a failure the daemon reports for it is kept and returned by
// the next fence() (or any later call that waits for a reply).
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "gpubridge/client/address.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::client {

using Timeout = std::chrono::milliseconds;
inline constexpr Timeout kDefaultTimeout{10000};
inline constexpr int kProtocolErrorBase = 1000;  // Error::code = kProtocolErrorBase + ErrorCode
inline constexpr int kTimeoutError = 2;          // Error::code of a client-side timeout
inline constexpr int kConnectionError = 3;       // socket closed / I/O error
inline constexpr int kInterrupted = 4;           // the interrupt flag was set (set_interrupt_flag)

struct SessionInfo {
  std::uint32_t session_id = 0;
  std::uint32_t max_payload = 0;
  std::string device_json;  // WELCOME's device description
};

struct ReceivedFrame {
  std::uint32_t number = 0;
  unsigned width = 0, height = 0;
  protocol::PixelFormat format = protocol::PixelFormat::RGBA8888;
  std::uint32_t crc = 0;
  std::uint64_t swap_ns = 0;  // daemon steady clock at the swap
  std::vector<std::uint8_t> pixels;
  protocol::FrameSource source = protocol::FrameSource::Board;  // board, mirror simulator or diff image
};

// Progress: bytes done, bytes total.
using Progress = std::function<void(std::uint64_t, std::uint64_t)>;

class Client {
 public:
  Client(Client&&) noexcept;
  Client& operator=(Client&&) noexcept;
  ~Client();

  // Connects (no handshake yet). address: "unix:PATH" | "tcp:HOST:PORT" | "" (the default socket).
  // On a Unix socket the daemon must run as this user or root (daemon_owner.hpp).
  static Result<Client> connect(std::string_view address, Timeout timeout = kDefaultTimeout);

  Result<SessionInfo> handshake(std::string_view name, std::string_view token = {}, Timeout timeout = kDefaultTimeout);
  const SessionInfo& session() const { return session_; }
  const Address& address() const { return address_; }

  Result<void> acquire_lease(protocol::LeaseMode mode = protocol::LeaseMode::Wait, Timeout timeout = kDefaultTimeout);
  Result<void> release_lease(Timeout timeout = kDefaultTimeout);

  // Sends register writes (9-byte wire frames, write bit clear), split into WRITE_FRAMES
  // messages of at most the negotiated payload. Returns once the bytes are handed to the kernel.
  Result<void> write_frames(protocol::FrameView frames, Timeout timeout = kDefaultTimeout);
  Result<std::uint64_t> read_register(std::uint8_t index, Timeout timeout = kDefaultTimeout);
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes, const Progress& progress = {},
                      Timeout timeout = kDefaultTimeout);
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length, const Progress& progress = {},
                                             Timeout timeout = kDefaultTimeout);
  // Blocks until the daemon has executed every earlier command of this client.
  Result<void> fence(Timeout timeout = kDefaultTimeout);
  Result<std::string> status(Timeout timeout = kDefaultTimeout);  // JSON text
  Result<void> ping(Timeout timeout = kDefaultTimeout);

  Result<void> subscribe(protocol::FrameFormat format = protocol::FrameFormat::Native, std::uint16_t max_fps = 0,
                         Timeout timeout = kDefaultTimeout);
  // Subscribes to one picture of a mirror-mode daemon (board, simulator or diff). A daemon without
  // mirror mode refuses sim/diff with ERROR UNAVAILABLE (returned here).
  Result<void> subscribe(const protocol::Subscribe& request, Timeout timeout = kDefaultTimeout);
  Result<void> unsubscribe(Timeout timeout = kDefaultTimeout);
  // The next frame not yet returned (the newest one if several arrived), waiting up to timeout.
  Result<ReceivedFrame> next_frame(Timeout timeout = kDefaultTimeout);
  // DEVICE_EVENT JSON texts received so far (drained by the call).
  std::vector<std::string> take_device_events();

  // Says BYE and closes. The destructor closes without BYE.
  void close();
  int native_handle() const { return fd_; }
  // A flag the program sets from its SIGINT handler: every call that waits returns an error with
  // code kInterrupted soon after it is set, instead of waiting out its timeout.
  void set_interrupt_flag(const std::atomic<bool>* flag) { interrupt_ = flag; }

  // The daemon's keepalive PINGs (sent to subscribers that have been silent for a while) are
  // answered with PONG while the client reads, between messages it sends.

 private:
  Client() = default;
  Result<void> send_message(const protocol::Message& m, Timeout timeout);
  // One message (split in two spans), after any PONGs owed to the daemon.
  Result<void> send_raw(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b, Timeout timeout);
  Result<void> write_all(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b, Timeout timeout);
  Result<void> send_pongs(Timeout timeout);
  bool interrupted() const { return interrupt_ && interrupt_->load(); }
  // Reads until a message for which `want` returns true arrives (ERROR replies with a matching
  // ref end the wait with an error). Frames and events are stored on the way.
  Result<protocol::Message> wait_for(std::uint32_t request_id, protocol::MsgType type, Timeout timeout);
  // Reads what is available (waiting up to `wait` for the first byte) and stores frames/events/errors.
  Result<void> pump(std::chrono::steady_clock::time_point deadline, bool block);
  // After a failed send: the ERROR the daemon sent before it closed (SERVER_FULL, SHUTTING_DOWN),
  // if it is still readable, so the caller learns why instead of "Broken pipe".
  std::optional<Error> daemon_last_words();
  Result<void> take_async_error();
  std::uint32_t next_request_id() { return ++request_counter_; }

  int fd_ = -1;
  Address address_;
  SessionInfo session_;
  std::uint32_t request_counter_ = 0;
  std::unique_ptr<protocol::MessageParser> parser_;
  std::deque<protocol::Message> inbox_;  // replies read while sending or waiting for something else
  struct ReadbackChunk {
    std::uint32_t request_id;
    bool last;
    std::vector<std::uint8_t> data;
  };
  std::deque<ReadbackChunk> readback_chunks_;
  std::optional<ReceivedFrame> latest_frame_;
  std::vector<std::string> events_;
  std::optional<Error> async_error_;  // first unanswered ERROR (e.g. for a WRITE_FRAMES)
  std::vector<std::vector<std::uint8_t>> pongs_;  // owed for the daemon's PINGs, sent between messages
  const std::atomic<bool>* interrupt_ = nullptr;
};

// Accumulates register writes and flushes them as large WRITE_FRAMES messages.
class RegisterWriter {
 public:
  explicit RegisterWriter(Client& client, std::size_t batch_frames = 64 * 1024);
  Result<void> write(protocol::Reg reg, std::uint64_t data) { return write(protocol::index_of(reg), data); }
  Result<void> write(std::uint8_t index, std::uint64_t data);
  Result<void> write_raw(protocol::FrameView frames);  // already-encoded frames
  Result<void> flush();
  std::size_t pending() const { return bytes_.size() / protocol::kFrameBytes; }

 private:
  Client& client_;
  std::size_t batch_frames_;
  std::vector<std::uint8_t> bytes_;
};

// Error::code helpers.
inline bool is_protocol_error(const Error& e, protocol::ErrorCode c) {
  return e.code == kProtocolErrorBase + static_cast<int>(c);
}

}  // namespace gpubridge::client
