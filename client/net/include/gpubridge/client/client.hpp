#pragma once
// Client: a synchronous connection to gpubridged (socket protocol v1, docs/protocol.md).
// Every blocking call takes a timeout. One Client per thread (the viewer subscribes on its own
// Client in its own thread); the class does no locking.
//
// Errors: protocol ERROR replies become Error{code = 1000 + ErrorCode, message = "<CODE>: text"}.
// WRITE_FRAMES is fire-and-forget: a failure the daemon reports for it is kept and returned by
// the next fence() (or any later call that waits for a reply).
//
// Remote use (docs/daemon.md "Remote use"): a program that gives no address or token gets them
// from the environment: GPUBRIDGE_ADDRESS (address.hpp), GPUBRIDGE_TOKEN or GPUBRIDGE_TOKEN_FILE
// (the token on the file's first line). `tls:HOST:PORT` encrypts and pins the daemon's certificate
// (GPUBRIDGE_TLS_FINGERPRINT, else trust on first use in the known-hosts file, tls.hpp). Over a
// link with latency, fence_async() + wait_fences() keep a window of frames in flight instead of a
// round trip per frame; WRITE_FRAMES is compressed (zstd) when the daemon agrees at HELLO.
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
#include "gpubridge/protocol/compression.hpp"
#include "gpubridge/protocol/device_kind.hpp"
#include "gpubridge/protocol/frame.hpp"
#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::client {

using Timeout = std::chrono::milliseconds;
inline constexpr Timeout kDefaultTimeout{10000};
inline constexpr int kProtocolErrorBase = 1000;  // Error::code = kProtocolErrorBase + ErrorCode
inline constexpr int kTimeoutError = 2;          // Error::code of a client-side timeout
inline constexpr int kConnectionError = 3;       // socket closed / I/O error
inline constexpr int kInterrupted = 4;           // the interrupt flag was set (set_interrupt_flag)
inline constexpr int kSecurityError = 5;         // TLS failure, fingerprint mismatch, token refused in clear

inline constexpr const char* kTokenEnv = "GPUBRIDGE_TOKEN";
inline constexpr const char* kTokenFileEnv = "GPUBRIDGE_TOKEN_FILE";
inline constexpr const char* kCompressEnv = "GPUBRIDGE_COMPRESS";  // zstd | none | auto (default)

// The token a program uses when it was given none: $GPUBRIDGE_TOKEN, else the first line of
// $GPUBRIDGE_TOKEN_FILE (a regular file of at most 4 KiB), else empty. Errors name the file.
Result<std::string> token_from_environment();

// WRITE_FRAMES compression. Auto: offered on connections that leave the machine (TCP/TLS to a
// host that is not loopback), not on Unix sockets or loopback, where it only costs CPU.
enum class Compression { Auto, Zstd, None };

// Bytes this client has put on the wire (headers included) and the WRITE_FRAMES payload bytes
// they stood for before compression.
struct WireStats {
  std::uint64_t bytes_sent = 0;
  std::uint64_t frame_bytes = 0;       // register-write bytes handed to write_frames()
  std::uint64_t frame_wire_bytes = 0;  // what those took on the wire (WRITE_FRAMES or WRITE_FRAMES_Z)
};

struct SessionInfo {
  std::uint32_t session_id = 0;
  std::uint32_t max_payload = 0;
  std::string device_json;  // WELCOME's device description
  bool compressed = false;  // WRITE_FRAMES go out as WRITE_FRAMES_Z (zstd)
  // WELCOME's "device_kind" (docs/protocol.md 17.7); a daemon that predates device kinds serves spigpu.
  protocol::DeviceKind device_kind = protocol::DeviceKind::Spigpu;
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

  // Connects (no handshake yet). address: "unix:PATH" | "tcp:HOST:PORT" | "tls:HOST:PORT" | ""
  // ($GPUBRIDGE_ADDRESS, else the default socket). On a Unix socket the daemon must run as this
  // user or root (daemon_owner.hpp); over tls: its certificate must match the pinned fingerprint.
  static Result<Client> connect(std::string_view address, Timeout timeout = kDefaultTimeout);

  // token empty: token_from_environment(). A token is never sent in clear to a host that is not
  // loopback (kSecurityError: use tls: or an SSH tunnel). compression: see Compression; the
  // environment's GPUBRIDGE_COMPRESS decides when the program passes Auto.
  Result<SessionInfo> handshake(std::string_view name, std::string_view token = {}, Timeout timeout = kDefaultTimeout,
                                Compression compression = Compression::Auto);
  const SessionInfo& session() const { return session_; }
  const Address& address() const { return address_; }

  Result<void> acquire_lease(protocol::LeaseMode mode = protocol::LeaseMode::Wait, Timeout timeout = kDefaultTimeout);
  Result<void> release_lease(Timeout timeout = kDefaultTimeout);

  // Sends register writes (9-byte wire frames, write bit clear), split into WRITE_FRAMES
  // messages of at most the negotiated payload. Returns once the bytes are handed to the kernel.
  Result<void> write_frames(protocol::FrameView frames, Timeout timeout = kDefaultTimeout);
  // DMC-1 command words (a daemon serving a DMC-1), split into DMC1_WORDS messages of at most
  // max_payload bytes; like write_frames, errors come back with a later wait.
  Result<void> write_dmc1_words(std::span<const std::uint64_t> words, Timeout timeout = kDefaultTimeout);
  Result<std::uint64_t> read_register(std::uint8_t index, Timeout timeout = kDefaultTimeout);
  Result<void> upload(std::uint32_t address, std::span<const std::uint8_t> bytes, const Progress& progress = {},
                      Timeout timeout = kDefaultTimeout);
  // Like upload(), but returns once the bytes are handed to the kernel: the UPLOAD_ACKs are taken
  // as they arrive and an error is returned by a later wait (like write_frames). For streaming
  // textures over a link with latency (the drawing API's uploads use it).
  Result<void> upload_async(std::uint32_t address, std::span<const std::uint8_t> bytes, Timeout timeout = kDefaultTimeout);
  Result<std::vector<std::uint8_t>> readback(std::uint32_t address, std::uint32_t length, const Progress& progress = {},
                                             Timeout timeout = kDefaultTimeout);
  // Blocks until the daemon has executed every earlier command of this client (one round trip).
  Result<void> fence(Timeout timeout = kDefaultTimeout);

  // Pipelined completion. fence_async() sends a FENCE and returns its handle at once; the handle
  // is done once the daemon has executed every command sent before it (handles complete in
  // order). wait_fences(n) blocks until at most n fences are outstanding: "no more than n frames
  // in flight" (n = 0: all done). The client keeps only the handles (8 bytes each); the frames in
  // flight are in the kernel's socket buffers and the network. Errors the daemon reported for
  // earlier writes are returned by the wait that passes them, like fence().
  using FenceHandle = std::uint64_t;
  Result<FenceHandle> fence_async(Timeout timeout = kDefaultTimeout);
  bool fence_done(FenceHandle handle) const { return handle <= fences_done_; }
  Result<void> wait_fence(FenceHandle handle, Timeout timeout = kDefaultTimeout);
  Result<void> wait_fences(std::size_t max_in_flight, Timeout timeout = kDefaultTimeout);
  std::size_t fences_in_flight() const { return fences_.size(); }
  // Called (from inside whichever call reads the FENCE_DONE) as each fence completes.
  void on_fence_done(std::function<void(FenceHandle)> callback) { fence_callback_ = std::move(callback); }
  const WireStats& wire_stats() const { return wire_; }
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

  // Waits, reading, until done() holds; ERRORs with ref 0 end the wait, others are kept for later.
  Result<void> wait_until(const std::function<bool()>& done, const char* what, Timeout timeout);
  // The transport: the socket, through TLS when tls_ is set (tls.hpp).
  long read_some(std::span<std::uint8_t> room);  // > 0 bytes, 0 end of stream, < 0 errno (EAGAIN: nothing yet)
  long write_some(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b);
  bool read_buffered() const;  // TLS holds decrypted bytes not yet read (poll would not see them)

  int fd_ = -1;
  std::unique_ptr<class TlsConnection> tls_;
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
  std::deque<FenceHandle> fences_;  // outstanding, in the order sent
  std::deque<std::uint32_t> async_uploads_;  // UPLOAD request ids whose ACK nobody waits for
  FenceHandle fences_done_ = 0;     // the newest completed handle (they complete in order)
  std::function<void(FenceHandle)> fence_callback_;
  std::unique_ptr<protocol::FrameDeflater> deflater_;  // when WELCOME agreed to compression
  std::vector<std::uint8_t> deflated_;
  WireStats wire_;
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
