#pragma once
// Session: one client connection. Reads bytes, feeds the MessageParser, dispatches messages,
// and enforces the per-session limits (handshake deadline, idle and trickle timeouts, message
// size, outgoing queue). Socket reads land directly in the parser's buffer. Device work pauses
// reading until it completes, so a WRITE_FRAMES batch is handed to the backend as a FrameView
// into that buffer (no per-write copy) and a client can never queue unbounded work.
// Subscribers hold at most one pending frame (newest wins).
#include <chrono>
#include <cstdint>
#include <deque>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange without it
#include <boost/asio.hpp>

#include "gpubridge/daemon/hub.hpp"
#include "gpubridge/daemon/stream.hpp"
#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::daemon {

class Session : public std::enable_shared_from_this<Session> {
 public:
  using Clock = std::chrono::steady_clock;
  using Buffer = std::shared_ptr<const std::vector<std::uint8_t>>;

  Session(Hub& hub, std::unique_ptr<Stream> stream, boost::asio::any_io_executor executor);
  ~Session();
  void start();

  // Sends ERROR(code, text) and closes once it is flushed (or after a short grace period).
  void fail(protocol::ErrorCode code, const std::string& text, std::uint32_t ref = 0);
  void offer_frame(FrameFanout& frame);
  void on_lease_granted();
  void send_event(const std::string& json) { reply(0, protocol::DeviceEvent{json}); }

  std::uint32_t id() const { return id_; }
  const std::string& name() const { return name_; }
  std::string transport() const { return stream_->transport(); }
  std::string peer() const { return stream_->peer(); }
  bool handshaken() const { return handshaken_; }
  bool subscribed() const { return subscribed_; }
  protocol::FrameSource frame_source() const { return frame_source_; }
  std::uint64_t bytes_in() const { return bytes_in_; }

 private:
  void do_read();
  void on_read(const boost::system::error_code& ec, std::size_t n);
  void process();  // dispatches parsed messages until it needs bytes or must wait
  void dispatch(protocol::Message& m);
  void handle_hello(const protocol::Message& m);
  void handle_write_frames(const protocol::Message& m);
  void handle_read_reg(const protocol::Message& m);
  void handle_upload(const protocol::Message& m);
  void handle_readback(const protocol::Message& m);
  void handle_fence(const protocol::Message& m);
  void handle_lease_acquire(const protocol::Message& m);
  bool require_lease(const protocol::Message& m);
  void record(const protocol::Message& m);
  void resume();  // device work or lease wait finished: continue with the next message

  void reply(std::uint32_t request_id, protocol::Payload payload);
  void reply_error(std::uint32_t ref, protocol::ErrorCode code, const std::string& text);
  void send(Buffer bytes);
  void do_write();
  void on_write(const boost::system::error_code& ec);
  void terminate(const char* why);  // closes the stream now and leaves the hub

  void arm_tick();
  void on_tick();

  Hub& hub_;
  std::unique_ptr<Stream> stream_;
  boost::asio::steady_timer tick_;
  boost::asio::steady_timer frame_timer_;  // releases a rate-limited frame when its interval ends
  protocol::MessageParser parser_;  // socket reads land directly in its buffer
  std::size_t read_bytes_ = 0;      // largest read: a page before the handshake, 1 MiB after

  std::uint32_t id_ = 0;
  std::string name_;
  bool handshaken_ = false;
  bool reading_ = false;       // an async read is outstanding
  bool paused_ = false;        // waiting for the device or the lease; the current message is live
  bool waiting_lease_ = false;
  std::uint32_t lease_request_id_ = 0;
  bool closing_ = false;       // no more input is processed; closing after the output flushes
  bool terminated_ = false;

  // Outgoing: queued replies (byte-capped; reading pauses above the cap) and one frame slot.
  std::deque<Buffer> queue_;
  std::uint64_t queued_bytes_ = 0;
  Buffer pending_frame_;
  std::vector<Buffer> in_flight_;
  std::uint64_t in_flight_queue_bytes_ = 0;  // the part of in_flight_ counted in queued_bytes_
  bool writing_ = false;

  bool subscribed_ = false;
  protocol::FrameFormat frame_format_ = protocol::FrameFormat::Native;
  protocol::FrameSource frame_source_ = protocol::FrameSource::Board;
  std::uint16_t max_fps_ = 0;
  Clock::time_point last_frame_sent_{};
  Buffer held_frame_;  // newest frame that arrived too early for max_fps; sent when the interval ends
  bool frame_timer_armed_ = false;

  // Timeouts.
  Clock::time_point accepted_at_ = Clock::now();
  Clock::time_point last_rx_ = Clock::now();
  Clock::time_point close_deadline_{};
  Clock::time_point window_start_ = Clock::now();
  std::uint64_t window_bytes_ = 0;
  bool partial_at_window_start_ = false;
  std::uint64_t bytes_in_ = 0;

  std::unique_ptr<std::ofstream> recording_;
  std::uint64_t records_ = 0;
  Clock::time_point record_start_{};
};

}  // namespace gpubridge::daemon
