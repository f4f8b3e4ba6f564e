#include "gpubridge/daemon/session.hpp"

#include <algorithm>
#include <filesystem>

#include "gpubridge/common/log.hpp"
#include "gpubridge/protocol/command_stream.hpp"
#include "gpubridge/protocol/trace.hpp"
#include "gpubridge/common/json_text.hpp"

namespace gpubridge::daemon {
namespace {

using protocol::ErrorCode;
using protocol::Message;
using protocol::MsgType;
namespace asio = boost::asio;

// Reads go straight into the parser's buffer (MessageParser::prepare/commit): no copy per read.
constexpr std::size_t kPreAuthReadBytes = 4096;   // pre-handshake buffer: a page plus at most one 1 KiB message
constexpr std::size_t kReadBytes = 1024 * 1024;  // fewer syscalls and device hand-offs per MiB
constexpr std::uint32_t kPreAuthMaxPayload = 1024;  // HELLO is at most ~200 bytes
constexpr auto kCloseGrace = std::chrono::milliseconds(1000);

// Constant-time comparison: the time depends on the lengths only, never on the contents.
bool tokens_equal(const std::string& a, const std::string& b) {
  unsigned char diff = a.size() == b.size() ? 0 : 1;
  const std::size_t n = std::max(a.size(), b.size());
  for (std::size_t i = 0; i < n; ++i) {
    const unsigned char x = i < a.size() ? static_cast<unsigned char>(a[i]) : 0;
    const unsigned char y = i < b.size() ? static_cast<unsigned char>(b[i]) : 0;
    diff |= static_cast<unsigned char>(x ^ y);
  }
  return diff == 0;
}

std::string device_problem(const Error& e) { return "device error: " + e.message; }

ErrorCode code_for(const Error& e) {
  switch (e.code) {
    case backends::kDeviceGone: return ErrorCode::DeviceGone;
    case backends::kBadRequest: return ErrorCode::Range;
    default: return ErrorCode::DeviceError;
  }
}

bool client_may_send(MsgType t) {
  switch (t) {
    case MsgType::Hello: case MsgType::Ping: case MsgType::Bye: case MsgType::WriteFrames: case MsgType::ReadReg:
    case MsgType::Upload: case MsgType::Readback: case MsgType::Fence: case MsgType::StatusReq:
    case MsgType::Subscribe: case MsgType::Unsubscribe: case MsgType::LeaseAcquire: case MsgType::LeaseRelease:
      return true;
    default:
      return false;
  }
}

}  // namespace

Session::Session(Hub& hub, std::unique_ptr<Stream> stream, asio::any_io_executor executor)
    : hub_(hub), stream_(std::move(stream)), tick_(executor), frame_timer_(executor), parser_(kPreAuthMaxPayload) {}

Session::~Session() = default;

void Session::start() {
  id_ = hub_.add_session(shared_from_this());
  read_bytes_ = kPreAuthReadBytes;
  logger("daemon")->debug("session {}: connected over {} from {}", id_, stream_->transport(), stream_->peer());
  arm_tick();
  do_read();
}

// ---------------------------------------------------------------------------------- input

void Session::do_read() {
  if (reading_ || closing_ || paused_ || terminated_) return;
  // Backpressure: a client that does not read its replies stops being read.
  if (queued_bytes_ > hub_.options().limits.queue_bytes) return;
  // Safe to hand out parser memory: no message span is live here (device work and lease waits
  // set paused_), and next() is not called until this read completes.
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
  process();
}

void Session::process() {
  while (!paused_ && !closing_ && !terminated_) {
    Message m;
    const auto st = parser_.next(m);
    if (st == protocol::MessageParser::Status::NeedMore) break;
    if (st == protocol::MessageParser::Status::Error) {
      const auto& e = parser_.error();  // the parser's message already names the stream offset
      fail(e.code, e.message);
      return;
    }
    dispatch(m);
  }
  do_read();
}

void Session::resume() {
  paused_ = false;
  if (!closing_ && !terminated_) process();
}

void Session::dispatch(Message& m) {
  const MsgType type = protocol::type_of(m.payload);
  if (!client_may_send(type)) {
    fail(ErrorCode::UnknownType, std::string(protocol::to_string(type)) + " is a server-to-client message", m.request_id);
    return;
  }
  if (!handshaken_) {
    if (type != MsgType::Hello) {
      fail(ErrorCode::NotHandshaken, "the first message must be HELLO, got " + std::string(protocol::to_string(type)),
           m.request_id);
      return;
    }
    handle_hello(m);
    return;
  }
  if (recording_) record(m);
  switch (type) {
    case MsgType::Hello:
      fail(ErrorCode::Malformed, "HELLO sent twice", m.request_id);
      return;
    case MsgType::Ping:
      reply(m.request_id, protocol::Pong{std::get<protocol::Ping>(m.payload).data});
      return;
    case MsgType::Bye:
      reply(m.request_id, protocol::Bye{});
      closing_ = true;
      close_deadline_ = Clock::now() + kCloseGrace;
      do_write();
      return;
    case MsgType::WriteFrames: handle_write_frames(m); return;
    case MsgType::ReadReg: handle_read_reg(m); return;
    case MsgType::Upload: handle_upload(m); return;
    case MsgType::Readback: handle_readback(m); return;
    case MsgType::Fence: handle_fence(m); return;
    case MsgType::StatusReq:
      reply(m.request_id, protocol::StatusReply{json_text(hub_.status_json())});
      return;
    case MsgType::Subscribe: {
      const auto& s = std::get<protocol::Subscribe>(m.payload);
      const auto source = s.source.value_or(protocol::FrameSource::Board);
      if (source != protocol::FrameSource::Board && !hub_.options().mirror) {
        // Not fatal: the session (and any earlier subscription) stays as it was.
        reply_error(m.request_id, ErrorCode::Unavailable,
                    "SUBSCRIBE source \"" + std::string(protocol::to_string(source)) +
                        "\" needs mirror mode, which this gpubridged does not run: start it with --mirror and a board "
                        "backend (e.g. --backend emulated:icebreaker --mirror), or subscribe to source \"board\"");
        return;
      }
      const bool switched = subscribed_ && source != frame_source_;
      subscribed_ = true;
      frame_format_ = s.format;
      frame_source_ = source;
      max_fps_ = s.max_fps;
      if (switched) hub_.offer_newest_frame(*this);
      return;
    }
    case MsgType::Unsubscribe:
      subscribed_ = false;
      held_frame_.reset();
      pending_frame_.reset();
      return;
    case MsgType::LeaseAcquire: handle_lease_acquire(m); return;
    case MsgType::LeaseRelease:
      hub_.release_lease(id_);
      reply(m.request_id, protocol::LeaseReleased{});
      return;
    default:
      fail(ErrorCode::UnknownType, "unexpected " + std::string(protocol::to_string(type)), m.request_id);
  }
}

void Session::handle_hello(const Message& m) {
  const auto& h = std::get<protocol::Hello>(m.payload);
  if (h.version != protocol::kSocketVersion) {
    fail(ErrorCode::BadVersion, "protocol version " + std::to_string(h.version) + " is not supported (this daemon speaks 1)",
         m.request_id);
    return;
  }
  const auto& token = hub_.options().token;
  if (!token.empty() && stream_->transport() == "tcp" && !tokens_equal(h.token, token)) {
    logger("daemon")->warn("session {}: bad token from {}", id_, stream_->peer());
    fail(ErrorCode::AuthFailed, "token rejected", m.request_id);
    return;
  }
  handshaken_ = true;
  name_ = h.name;
  parser_.set_max_payload(hub_.options().limits.max_message_bytes);
  read_bytes_ = kReadBytes;
  window_start_ = Clock::now();
  window_bytes_ = 0;
  if (!hub_.options().record_dir.empty()) {
    std::string safe = name_;
    for (char& c : safe)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
    const auto path = std::filesystem::path(hub_.options().record_dir) /
                      ("session-" + std::to_string(id_) + (safe.empty() ? "" : "-" + safe) + ".gbtrace");
    auto out = std::make_unique<std::ofstream>(path, std::ios::binary | std::ios::trunc);
    std::vector<std::uint8_t> header;
    const std::string meta = json_text(nlohmann::json{{"source", "gpubridged"}, {"client", name_}, {"session", id_}});
    if (*out && protocol::append_trace_header(meta, header)) {
      out->write(reinterpret_cast<const char*>(header.data()), static_cast<std::streamsize>(header.size()));
      recording_ = std::move(out);
      record_start_ = Clock::now();
    } else {
      logger("daemon")->error("session {}: cannot record to {}", id_, path.string());
    }
  }
  logger("daemon")->info("session {}: \"{}\" connected over {}", id_, name_, stream_->transport());
  reply(m.request_id, protocol::Welcome{protocol::kSocketVersion, hub_.options().limits.max_message_bytes, id_,
                                        hub_.device_json()});
}

void Session::record(const Message& m) {
  auto cmd = protocol::command_from_message(m);
  if (!cmd) return;  // not a device-affecting message
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - record_start_).count();
  std::vector<std::uint8_t> bytes;
  if (!protocol::append_trace_record(protocol::TimedCommand{static_cast<std::uint64_t>(ns), std::move(*cmd)}, ++records_,
                                     bytes))
    return;
  recording_->write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

bool Session::require_lease(const Message& m) {
  if (hub_.holds_lease(id_)) return true;
  reply_error(m.request_id, ErrorCode::NoLease,
              std::string(protocol::to_string(protocol::type_of(m.payload))) + " needs the device lease (send LEASE_ACQUIRE first)");
  return false;
}

void Session::handle_write_frames(const Message& m) {
  if (!require_lease(m)) return;
  // No read-bit scan here: the parser already refused any read frame (fatal BAD_FRAME), and a
  // second pass over a 1 MiB batch was a measurable share of the daemon's per-message cost.
  const auto frames = std::get<protocol::WriteFrames>(m.payload).frames;
  paused_ = true;  // `frames` points into the parser buffer until we call next() again
  const auto rid = m.request_id;
  hub_.device_call<void>([frames](backends::Backend& b) { return b.write_frames(frames); },
                         [self = shared_from_this(), rid](Result<void> r) {
                           if (!r) self->reply_error(rid, code_for(r.error()), device_problem(r.error()));
                           self->resume();
                         });
}

void Session::handle_read_reg(const Message& m) {
  const auto index = std::get<protocol::ReadReg>(m.payload).index;
  if (index >= protocol::kRegisterCount) {
    reply_error(m.request_id, ErrorCode::Range, "register index " + std::to_string(index) + " is beyond 127");
    return;
  }
  // Reading MEM_DATA advances MEM_ADDR: that changes device state, so it needs the lease.
  if (index == protocol::index_of(protocol::Reg::MEM_DATA) && !require_lease(m)) return;
  paused_ = true;
  const auto rid = m.request_id;
  hub_.device_call<std::uint64_t>([index](backends::Backend& b) { return b.read_register(index); },
                                  [self = shared_from_this(), rid, index](Result<std::uint64_t> r) {
                                    if (!r)
                                      self->reply_error(rid, code_for(r.error()), device_problem(r.error()));
                                    else
                                      self->reply(rid, protocol::RegValue{index, *r});
                                    self->resume();
                                  });
}

void Session::handle_upload(const Message& m) {
  if (!require_lease(m)) return;
  const auto& u = std::get<protocol::Upload>(m.payload);
  paused_ = true;
  const auto rid = m.request_id;
  const auto address = u.address;
  const auto data = u.data;
  hub_.device_call<void>([address, data](backends::Backend& b) { return b.upload(address, data); },
                         [self = shared_from_this(), rid, address, n = data.size()](Result<void> r) {
                           if (!r)
                             self->reply_error(rid, code_for(r.error()), device_problem(r.error()));
                           else
                             self->reply(rid, protocol::UploadAck{address, static_cast<std::uint32_t>(n)});
                           self->resume();
                         });
}

void Session::handle_readback(const Message& m) {
  if (!require_lease(m)) return;
  const auto rb = std::get<protocol::Readback>(m.payload);
  if (rb.length == 0 || rb.length > protocol::kMaxReadbackBytes) {
    reply_error(m.request_id, ErrorCode::Range, "READBACK length must be 1.." + std::to_string(protocol::kMaxReadbackBytes));
    return;
  }
  paused_ = true;
  const auto rid = m.request_id;
  hub_.device_call<std::vector<std::uint8_t>>(
      [rb](backends::Backend& b) { return b.readback(rb.address, rb.length); },
      [self = shared_from_this(), rid, rb](Result<std::vector<std::uint8_t>> r) {
        if (!r) {
          self->reply_error(rid, code_for(r.error()), device_problem(r.error()));
        } else if (r->size() != rb.length) {
          self->reply_error(rid, ErrorCode::DeviceError, "backend returned " + std::to_string(r->size()) + " of " +
                                                             std::to_string(rb.length) + " bytes");
        } else {
          const auto& data = *r;
          for (std::size_t off = 0; off < data.size(); off += protocol::kMaxReadbackChunk) {
            const std::size_t n = std::min<std::size_t>(protocol::kMaxReadbackChunk, data.size() - off);
            const bool last = off + n == data.size();
            self->reply(rid, protocol::ReadbackData{static_cast<std::uint32_t>(rb.address + off), last,
                                                    std::span<const std::uint8_t>(data.data() + off, n)});
          }
        }
        self->resume();
      });
}

void Session::handle_fence(const Message& m) {
  paused_ = true;
  const auto rid = m.request_id;
  const auto fence_id = std::get<protocol::FenceMsg>(m.payload).id;
  hub_.device_call<void>([](backends::Backend& b) { return b.flush(); },
                         [self = shared_from_this(), rid, fence_id](Result<void> r) {
                           if (!r)
                             self->reply_error(rid, code_for(r.error()), device_problem(r.error()));
                           else
                             self->reply(rid, protocol::FenceDone{fence_id});
                           self->resume();
                         });
}

void Session::handle_lease_acquire(const Message& m) {
  const auto mode = std::get<protocol::LeaseAcquire>(m.payload).mode;
  switch (hub_.acquire_lease(id_, mode)) {
    case Hub::LeaseResult::Granted:
      reply(m.request_id, protocol::LeaseGranted{id_});
      return;
    case Hub::LeaseResult::Busy:
      reply_error(m.request_id, ErrorCode::Busy, "another client holds the device lease");
      return;
    case Hub::LeaseResult::Queued:
      // Keep the client's order: nothing after LEASE_ACQUIRE runs before the grant.
      paused_ = true;
      waiting_lease_ = true;
      lease_request_id_ = m.request_id;
      return;
  }
}

void Session::on_lease_granted() {
  if (terminated_) return;
  waiting_lease_ = false;
  reply(lease_request_id_, protocol::LeaseGranted{id_});
  window_start_ = Clock::now();
  window_bytes_ = 0;
  last_rx_ = Clock::now();
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

void Session::fail(ErrorCode code, const std::string& text, std::uint32_t ref) {
  if (closing_ || terminated_) return;
  logger("daemon")->info("session {} ({}): closing: {}: {}", id_, stream_->peer(), protocol::to_string(code), text);
  reply(ref, protocol::ErrorMsg{code, ref, text});
  closing_ = true;
  close_deadline_ = Clock::now() + kCloseGrace;
  do_write();
}

void Session::send(Buffer bytes) {
  if (terminated_) return;
  queued_bytes_ += bytes->size();
  queue_.push_back(std::move(bytes));
  do_write();
}

void Session::offer_frame(FrameFanout& frame) {
  if (!subscribed_ || closing_ || terminated_ || !handshaken_) return;
  auto message = frame.message(frame_source_, frame_format_);
  if (!message) return;  // this swap has no picture of the subscribed source (CRC-only board)
  const auto now = Clock::now();
  if (max_fps_ != 0 && last_frame_sent_ != Clock::time_point{}) {
    const auto due = last_frame_sent_ + std::chrono::microseconds(1000000 / max_fps_);
    if (now < due) {
      // Too early for the subscriber's rate: keep only the newest such frame and send it when the
      // interval ends, so the last frame of an animation is never lost.
      held_frame_ = std::move(message);
      if (!frame_timer_armed_) {
        frame_timer_armed_ = true;
        frame_timer_.expires_at(due);
        frame_timer_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
          self->frame_timer_armed_ = false;
          if (ec || self->terminated_ || self->closing_ || !self->subscribed_ || !self->held_frame_) return;
          self->last_frame_sent_ = Clock::now();
          self->pending_frame_ = std::move(self->held_frame_);  // newest wins
          self->held_frame_.reset();
          self->do_write();
        });
      }
      return;
    }
  }
  last_frame_sent_ = now;
  held_frame_.reset();
  pending_frame_ = std::move(message);  // replaces an unsent older frame: newest wins
  do_write();
}

void Session::do_write() {
  if (writing_ || terminated_) return;
  in_flight_.clear();
  std::vector<asio::const_buffer> bufs;
  std::size_t total = 0;
  while (!queue_.empty() && bufs.size() < 64 && total < (4u << 20)) {
    total += queue_.front()->size();
    bufs.push_back(asio::buffer(*queue_.front()));
    in_flight_.push_back(std::move(queue_.front()));
    queue_.pop_front();
  }
  in_flight_queue_bytes_ = total;
  if (bufs.empty() && pending_frame_ && !closing_) {
    bufs.push_back(asio::buffer(*pending_frame_));
    in_flight_.push_back(std::move(pending_frame_));
    pending_frame_.reset();
  }
  if (bufs.empty()) {
    if (closing_) terminate("closed after the last reply");
    return;
  }
  writing_ = true;
  stream_->async_write(bufs, [self = shared_from_this()](const auto& ec, std::size_t) { self->on_write(ec); });
}

void Session::on_write(const boost::system::error_code& ec) {
  writing_ = false;
  if (terminated_) return;
  if (ec) {
    terminate("write error");
    return;
  }
  const bool was_over = queued_bytes_ > hub_.options().limits.queue_bytes;
  queued_bytes_ -= std::min(queued_bytes_, in_flight_queue_bytes_);
  in_flight_queue_bytes_ = 0;
  in_flight_.clear();
  do_write();
  if (was_over && queued_bytes_ <= hub_.options().limits.queue_bytes) do_read();
}

void Session::terminate(const char* why) {
  if (terminated_) return;
  terminated_ = true;
  closing_ = true;
  logger("daemon")->debug("session {}: {}", id_, why);
  tick_.cancel();
  frame_timer_.cancel();
  stream_->close();
  queue_.clear();
  pending_frame_.reset();
  held_frame_.reset();
  if (recording_) recording_->flush();
  hub_.remove_session(id_);
}

// ---------------------------------------------------------------------------------- timeouts

void Session::arm_tick() {
  const auto& l = hub_.options().limits;
  unsigned period = std::min(l.handshake_timeout_ms, l.trickle_window_ms);
  if (l.idle_timeout_ms) period = std::min(period, l.idle_timeout_ms);
  period = std::clamp(period / 4, 5u, 1000u);
  tick_.expires_after(std::chrono::milliseconds(period));
  tick_.async_wait([self = shared_from_this()](const boost::system::error_code& ec) {
    if (!ec) self->on_tick();
  });
}

void Session::on_tick() {
  if (terminated_) return;
  const auto now = Clock::now();
  const auto& l = hub_.options().limits;
  const auto ms = [](auto d) { return std::chrono::duration_cast<std::chrono::milliseconds>(d).count(); };
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
  const bool waiting_on_us = paused_;  // device work or lease wait: the client is not at fault
  if (!waiting_on_us && now - window_start_ >= std::chrono::milliseconds(l.trickle_window_ms)) {
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
  if (waiting_on_us) last_rx_ = now;
  if (handshaken_ && l.idle_timeout_ms && !subscribed_ && !waiting_on_us &&
      now - last_rx_ >= std::chrono::milliseconds(l.idle_timeout_ms)) {
    fail(ErrorCode::Timeout, "idle for " + std::to_string(l.idle_timeout_ms) + " ms");
  }
  arm_tick();
}

}  // namespace gpubridge::daemon
