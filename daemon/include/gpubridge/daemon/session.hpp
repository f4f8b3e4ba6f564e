#pragma once
// Session: one client connection, shaped like the Asio/Beast examples' connection: it reads bytes
// straight into the MessageParser's buffer, hands each message to its RequestHandler, writes
// replies (OutgoingQueue) and frames (FrameSubscription), and enforces the per-connection limits
// (docs/daemon.md "Limits"): handshake deadline, idle and trickle timeouts, keepalive of idle
// subscribers, a client that stops reading, the outgoing byte bound, a peer that went away while
// its request runs. One thread (the network executor) runs everything of a session.
//
// Input stops while the handler has a message "live" (device work or a lease wait: pause/resume),
// so a WRITE_FRAMES batch is handed to the device as a view into the parser's buffer and a client
// can never queue unbounded work; it also stops while the outgoing queue is over its bound, per
// message, and a burst of small messages yields the thread to other sessions every few dozen.
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <utility>  // before Asio: Boost 1.74's awaitable.hpp uses std::exchange without it
#include <boost/asio.hpp>

#include "gpubridge/daemon/device_worker.hpp"
#include "gpubridge/daemon/frame_subscription.hpp"
#include "gpubridge/daemon/hub.hpp"
#include "gpubridge/daemon/outgoing_queue.hpp"
#include "gpubridge/daemon/request_handler.hpp"
#include "gpubridge/daemon/stream.hpp"
#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::daemon {

class Session : public std::enable_shared_from_this<Session> {
 public:
  using Clock = std::chrono::steady_clock;
  using Buffer = OutgoingQueue::Buffer;

  Session(Hub& hub, std::unique_ptr<Stream> stream, boost::asio::any_io_executor executor);
  ~Session();
  void start();

  // --- to the client ---
  void reply(std::uint32_t request_id, protocol::Payload payload);
  void reply_error(std::uint32_t ref, protocol::ErrorCode code, const std::string& text);
  // Sends ERROR(code, text) and closes once it is flushed (or after a short grace period). `quiet`:
  // no log line of its own (the caller logs through a rate limiter).
  void fail(protocol::ErrorCode code, const std::string& text, std::uint32_t ref = 0, bool quiet = false);
  void close_after_flush();  // BYE: no more input; closes once everything queued is written
  void send_event(const std::string& json) { reply(0, protocol::DeviceEvent{json}); }
  void offer_frame(std::shared_ptr<FrameFanout> swap);

  // --- for the handler ---
  // The current message stays live (device work, lease wait): nothing else is read or parsed.
  void pause();
  void resume();
  // Runs `then` once `bytes` more fit in the outgoing queue (a streamed reply's next step).
  void when_room(std::uint64_t bytes, std::function<void()> then);
  // HELLO accepted: post-handshake limits (message size, read size) apply from now on.
  void handshake_done(const std::string& name);
  const std::shared_ptr<DeviceWorker::CancelFlag>& cancel_flag() const { return cancel_; }
  FrameSubscription& subscription() { return subscription_; }
  RequestHandler& handler() { return handler_; }
  const OutgoingQueue& outgoing() const { return out_; }
  void on_lease_granted();

  // --- for the hub and status ---
  std::uint32_t id() const { return id_; }
  const std::string& name() const { return name_; }
  std::string transport() const { return stream_->transport(); }
  std::string peer() const { return stream_->peer(); }
  Stream::Security security() const { return stream_->security(); }
  bool tls_required() const { return stream_->tls_required(); }
  bool handshaken() const { return handshaken_; }
  bool closed() const { return closing_ || terminated_; }
  bool subscribed() const { return subscription_.active(); }
  protocol::FrameSource frame_source() const { return subscription_.source(); }
  std::uint64_t bytes_in() const { return bytes_in_; }

 private:
  void do_read();
  void on_read(const boost::system::error_code& ec, std::size_t n);
  void process();  // dispatches parsed messages until it needs bytes or must wait
  void send(Buffer bytes);
  void do_write();
  void on_write(const boost::system::error_code& ec);
  void arm_frame_timer(Clock::time_point due);
  void terminate(const char* why);  // closes the stream now, cancels device work, leaves the hub

  void arm_tick();
  void on_tick();
  void check_peer(Clock::time_point now);  // while a request is live: has the client gone?
  void restart_input_clocks();             // reading resumes: silence and trickle windows start now

  Hub& hub_;
  std::unique_ptr<Stream> stream_;
  boost::asio::steady_timer tick_;
  boost::asio::steady_timer frame_timer_;  // sends a rate-limited frame when its interval ends
  protocol::MessageParser parser_;         // socket reads land directly in its buffer
  RequestHandler handler_;
  std::shared_ptr<DeviceWorker::CancelFlag> cancel_ = std::make_shared<DeviceWorker::CancelFlag>(false);
  std::size_t read_bytes_ = 0;  // largest read: a page before the handshake, 1 MiB after

  std::uint32_t id_ = 0;
  std::string name_;
  bool handshaken_ = false;
  bool reading_ = false;     // an async read is outstanding
  bool paused_ = false;      // the handler has a live message (device work, lease wait)
  bool blocked_ = false;     // input stopped because the outgoing queue is over its bound
  bool continuing_ = false;  // a turn of process() was posted to let other sessions run
  bool closing_ = false;     // no more input is processed; closing after the output flushes
  bool terminated_ = false;

  // Outgoing: replies and events (bounded), frames (one pending swap), the write in flight.
  OutgoingQueue out_;
  FrameSubscription subscription_;
  std::vector<Buffer> in_flight_;
  std::size_t in_flight_queued_ = 0;  // the part of in_flight_ counted in out_
  bool writing_ = false;
  Clock::time_point write_started_{};
  bool frame_timer_armed_ = false;
  std::uint64_t room_wanted_ = 0;
  std::function<void()> on_room_;

  // Timeouts.
  Clock::time_point next_tick_{};
  Clock::time_point accepted_at_ = Clock::now();
  Clock::time_point last_rx_ = Clock::now();
  Clock::time_point close_deadline_{};
  Clock::time_point window_start_ = Clock::now();
  std::uint64_t window_bytes_ = 0;
  bool partial_at_window_start_ = false;
  bool keepalive_sent_ = false;  // a PING went out since the client last sent anything
  bool probed_ = false;          // a half-closed TCP peer was sent a probe during the live request
  std::uint64_t bytes_in_ = 0;
};

}  // namespace gpubridge::daemon
