#include "gpubridge/daemon/session.hpp"

#include <algorithm>

#include "gpubridge/common/log.hpp"

namespace gpubridge::daemon {
namespace {

using protocol::ErrorCode;
using protocol::Message;
namespace asio = boost::asio;

// Reads go straight into the parser's buffer (MessageParser::prepare/commit): no copy per read.
constexpr std::size_t kPreAuthReadBytes = 4096;     // pre-handshake buffer: a page plus at most one 1 KiB message
constexpr std::size_t kReadBytes = 1024 * 1024;     // fewer syscalls and device hand-offs per MiB
constexpr std::uint32_t kPreAuthMaxPayload = 1024;  // HELLO is at most ~200 bytes
constexpr auto kCloseGrace = std::chrono::milliseconds(1000);
constexpr unsigned kMessagesPerTurn = 64;  // then other sessions get the network thread
constexpr std::size_t kWriteBuffers = 64;
constexpr std::size_t kWriteBytes = 4u << 20;
// While a request is live the client is not read, so a peer that went away is noticed by polling
// its socket at this period (and its work cancelled).
constexpr auto kLivePeerCheck = std::chrono::milliseconds(50);
const std::vector<std::uint8_t> kKeepaliveData{'k', 'e', 'e', 'p', 'a', 'l', 'i', 'v', 'e'};

long long ms(std::chrono::steady_clock::duration d) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(d).count();
}

}  // namespace

Session::Session(Hub& hub, std::unique_ptr<Stream> stream, asio::any_io_executor executor)
    : hub_(hub),
      stream_(std::move(stream)),
      tick_(executor),
      frame_timer_(executor),
      parser_(kPreAuthMaxPayload),
      handler_(*this, hub),
      out_(hub.options().limits.queue_bytes) {}

Session::~Session() = default;

void Session::start() {
  id_ = hub_.add_session(shared_from_this());
  read_bytes_ = kPreAuthReadBytes;
  logger("daemon")->debug("session {}: connected over {} from {}", id_, stream_->transport(), stream_->peer());
  arm_tick();
  do_read();
}

void Session::handshake_done(const std::string& name) {
  handshaken_ = true;
  name_ = name;
  parser_.set_max_payload(hub_.options().limits.max_message_bytes);
  read_bytes_ = kReadBytes;
  window_start_ = Clock::now();
  window_bytes_ = 0;
}

// ---------------------------------------------------------------------------------- input

void Session::do_read() {
  if (reading_ || closing_ || paused_ || terminated_ || continuing_) return;
  // Backpressure, per message: a client that does not read its replies stops being read.
  if (out_.full()) {
    blocked_ = true;
    return;
  }
  // Safe to hand out parser memory: no message span is live (paused_ is false) and next() is not
  // called until this read completes (process() returns while reading_).
  const auto space = parser_.prepare(read_bytes_);
  if (space.empty()) return;  // poisoned parser: the session is closing anyway
  reading_ = true;
  stream_->async_read_some(asio::buffer(space.data(), space.size()),
                           [self = shared_from_this()](const auto& ec, std::size_t n) { self->on_read(ec, n); });
}

void Session::on_read(const boost::system::error_code& ec, std::size_t n) {
  reading_ = false;
  parser_.commit(ec ? 0 : n);
  if (terminated_) return;
  if (ec) {
    terminate(ec == asio::error::eof ? "client closed the connection" : "read error");
    return;
  }
  if (closing_) return;  // input after a fatal error is ignored
  bytes_in_ += n;
  window_bytes_ += n;
  last_rx_ = Clock::now();
  keepalive_sent_ = false;
  process();
}

void Session::process() {
  if (reading_ || continuing_) return;  // the read's completion, or the posted turn, continues
  for (unsigned handled = 0; !paused_ && !closing_ && !terminated_; ++handled) {
    // The bound holds per message: nothing more is dispatched while the replies already queued
    // exceed it; the write that brings them under it continues here (on_write).
    if (out_.full()) {
      blocked_ = true;
      return;
    }
    if (handled == kMessagesPerTurn) {  // a burst of small requests must not starve other sessions
      continuing_ = true;
      asio::post(tick_.get_executor(), [self = shared_from_this()] {
        self->continuing_ = false;
        self->process();
      });
      return;
    }
    Message m;
    const auto st = parser_.next(m);
    if (st == protocol::MessageParser::Status::NeedMore) break;
    if (st == protocol::MessageParser::Status::Error) {
      const auto& e = parser_.error();  // the parser's message already names the stream offset
      fail(e.code, e.message);
      return;
    }
    handler_.dispatch(m);
  }
  do_read();
}

void Session::pause() {
  paused_ = true;
  // From now on the client is watched for going away at the shorter period (check_peer).
  if (next_tick_ - Clock::now() > 2 * kLivePeerCheck) arm_tick();
}

void Session::resume() {
  paused_ = false;
  probed_ = false;
  restart_input_clocks();
  if (!closing_ && !terminated_) process();
}

void Session::restart_input_clocks() {
  const auto now = Clock::now();
  last_rx_ = now;
  window_start_ = now;
  window_bytes_ = 0;
  partial_at_window_start_ = false;
}

void Session::on_lease_granted() {
  if (terminated_) return;
  handler_.on_lease_granted();
  resume();
}

// ---------------------------------------------------------------------------------- output

void Session::reply(std::uint32_t request_id, protocol::Payload payload) {
  auto bytes = std::make_shared<std::vector<std::uint8_t>>();
  protocol::encode(Message{request_id, std::move(payload)}, *bytes);
  send(std::move(bytes));
}

void Session::reply_error(std::uint32_t ref, ErrorCode code, const std::string& text) {
  logger("daemon")->debug("session {}: {} {}", id_, protocol::to_string(code), text);
  reply(ref, protocol::ErrorMsg{code, ref, text});
}

void Session::fail(ErrorCode code, const std::string& text, std::uint32_t ref, bool quiet) {
  if (closing_ || terminated_) return;
  if (!quiet)
    hub_.log_closing("session " + std::to_string(id_) + " (" + stream_->peer() + "): closing: " +
                     std::string(protocol::to_string(code)) + ": " + text);
  reply(ref, protocol::ErrorMsg{code, ref, text});
  closing_ = true;
  close_deadline_ = Clock::now() + kCloseGrace;
  hub_.device().cancel(cancel_);  // its device work, if any, no longer matters
  do_write();
}

void Session::close_after_flush() {
  closing_ = true;
  close_deadline_ = Clock::now() + kCloseGrace;
  do_write();
}

void Session::send(Buffer bytes) {
  if (terminated_) return;
  out_.push(std::move(bytes));
  do_write();
}

void Session::when_room(std::uint64_t bytes, std::function<void()> then) {
  if (terminated_) return;
  if (out_.has_room(bytes)) {
    then();
    return;
  }
  room_wanted_ = bytes;
  on_room_ = std::move(then);
}

void Session::offer_frame(std::shared_ptr<FrameFanout> swap) {
  if (closing_ || terminated_ || !handshaken_) return;
  subscription_.offer(std::move(swap));
  do_write();
}

void Session::do_write() {
  if (writing_ || terminated_) return;
  in_flight_.clear();
  in_flight_queued_ = out_.take(in_flight_, kWriteBuffers, kWriteBytes);
  if (in_flight_.empty() && !closing_ && subscription_.active()) {
    // Replies first; a frame only when none wait. Encoded now, in the subscriber's format.
    std::optional<Clock::time_point> due;
    if (auto frame = subscription_.take(Clock::now(), due))
      in_flight_.push_back(std::move(frame));
    else if (due)
      arm_frame_timer(*due);
  }
  if (in_flight_.empty()) {
    if (closing_) terminate("closed after the last reply");
    return;
  }
  std::vector<asio::const_buffer> bufs;
  bufs.reserve(in_flight_.size());
  for (const auto& b : in_flight_) bufs.push_back(asio::buffer(*b));
  writing_ = true;
  write_started_ = Clock::now();
  stream_->async_write(bufs, [self = shared_from_this()](const auto& ec, std::size_t) { self->on_write(ec); });
}

void Session::arm_frame_timer(Clock::time_point due) {
  if (frame_timer_armed_) return;
  frame_timer_armed_ = true;
  frame_timer_.expires_at(due);
  frame_timer_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
    self->frame_timer_armed_ = false;
    if (!ec) self->do_write();
  });
}

void Session::on_write(const boost::system::error_code& ec) {
  writing_ = false;
  if (terminated_) return;
  if (ec) {
    terminate("write error");
    return;
  }
  out_.written(in_flight_queued_);
  in_flight_queued_ = 0;
  in_flight_.clear();
  if (on_room_ && out_.has_room(room_wanted_)) std::exchange(on_room_, nullptr)();
  do_write();
  if (blocked_ && !out_.full()) {
    blocked_ = false;
    restart_input_clocks();
    process();
  }
}

void Session::terminate(const char* why) {
  if (terminated_) return;
  terminated_ = true;
  closing_ = true;
  logger("daemon")->debug("session {}: {}", id_, why);
  hub_.device().cancel(cancel_);  // a batch still running for this client stops between frames
  tick_.cancel();
  frame_timer_.cancel();
  stream_->close();
  out_.clear();
  subscription_.unsubscribe();
  on_room_ = nullptr;
  handler_.on_closed();
  hub_.remove_session(id_);  // frees the lease (the device is reset before the next holder)
}

// ---------------------------------------------------------------------------------- timeouts

void Session::arm_tick() {
  const auto& l = hub_.options().limits;
  unsigned period = std::min(l.handshake_timeout_ms, l.trickle_window_ms);
  if (l.idle_timeout_ms) period = std::min(period, l.idle_timeout_ms / 2);
  auto every = std::chrono::milliseconds(std::clamp(period / 4, 5u, 1000u));
  if (paused_) every = std::min<std::chrono::milliseconds>(every, kLivePeerCheck);
  next_tick_ = Clock::now() + every;
  tick_.expires_at(next_tick_);
  tick_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
    if (!ec) self->on_tick();
  });
}

void Session::check_peer(Clock::time_point) {
  switch (stream_->peer_state()) {
    case Stream::PeerState::Open: return;
    case Stream::PeerState::Gone:
      hub_.log_closing("session " + std::to_string(id_) + " (" + stream_->peer() +
                       "): the client went away while its request ran; its work is dropped");
      terminate("client gone during a live request");
      return;
    case Stream::PeerState::HalfClosed:
      // A TCP peer that closed and one that only shut down its sending side look the same until
      // something is sent: a closed one answers with a reset, seen at the next check.
      if (!probed_) {
        probed_ = true;
        reply(0, protocol::Ping{kKeepaliveData});
      }
      return;
  }
}

void Session::on_tick() {
  if (terminated_) return;
  const auto now = Clock::now();
  const auto& l = hub_.options().limits;
  if (closing_) {
    if (now >= close_deadline_) terminate("client did not take its last reply in time");
    else arm_tick();
    return;
  }
  if (!handshaken_ && now - accepted_at_ >= std::chrono::milliseconds(l.handshake_timeout_ms)) {
    fail(ErrorCode::Timeout, "no HELLO within " + std::to_string(l.handshake_timeout_ms) + " ms");
    arm_tick();
    return;
  }
  // A client that takes nothing of what is written to it for idle_timeout_ms (its socket buffer
  // is full) is closed: it would otherwise hold its slot, and its queue, forever.
  if (writing_ && l.idle_timeout_ms && now - write_started_ >= std::chrono::milliseconds(l.idle_timeout_ms)) {
    hub_.log_closing("session " + std::to_string(id_) + " (" + stream_->peer() + "): closing: it has not taken what " +
                     "was written to it for " + std::to_string(ms(now - write_started_)) + " ms (limits.idle_timeout_ms)");
    terminate("not reading");
    return;
  }
  if (paused_) {  // device work or lease wait: the client is not read, but may have gone
    check_peer(now);
    if (terminated_) return;
  }
  // The silence and trickle checks measure the client only while it is read: not while a request
  // is live (paused_) nor while its replies are over queue_bytes (blocked_; one that takes nothing
  // is closed by the write check above). Both clocks restart when reading resumes.
  const bool reading = !paused_ && !blocked_;
  if (reading && now - window_start_ >= std::chrono::milliseconds(l.trickle_window_ms)) {
    const bool partial = parser_.buffered() > 0;
    const auto window_ms = ms(now - window_start_);
    if (partial && partial_at_window_start_ &&
        window_bytes_ * 1000 < std::uint64_t{l.min_bytes_per_sec} * static_cast<std::uint64_t>(window_ms)) {
      fail(ErrorCode::Timeout, "message arriving too slowly: " + std::to_string(window_bytes_) + " bytes in " +
                                   std::to_string(window_ms) + " ms (minimum " + std::to_string(l.min_bytes_per_sec) +
                                   " bytes/s)");
      arm_tick();
      return;
    }
    window_start_ = now;
    window_bytes_ = 0;
    partial_at_window_start_ = partial;
  }
  if (handshaken_ && l.idle_timeout_ms && reading) {
    const auto silent = now - last_rx_;
    const auto idle = std::chrono::milliseconds(l.idle_timeout_ms);
    if (silent >= idle) {
      fail(ErrorCode::Timeout, subscribed() ? "subscriber silent for " + std::to_string(ms(silent)) +
                                                  " ms: no answer to the keepalive PING (the gpubridge client library "
                                                  "answers it while it waits for frames)"
                                            : "idle for " + std::to_string(l.idle_timeout_ms) + " ms");
    } else if (subscribed() && silent >= idle / 2 && !keepalive_sent_) {
      // Subscribers may be silent for long (a viewer only reads); the keepalive asks for a PONG
      // so that one whose client is gone, or never reads, does not hold its slot forever.
      keepalive_sent_ = true;
      reply(0, protocol::Ping{kKeepaliveData});
    }
  }
  arm_tick();
}

}  // namespace gpubridge::daemon
