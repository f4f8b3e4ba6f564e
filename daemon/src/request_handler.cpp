#include "gpubridge/daemon/request_handler.hpp"

#include <algorithm>
#include <optional>

#include "gpubridge/common/json_text.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/daemon/session.hpp"
#include "gpubridge/protocol/command_stream.hpp"

namespace gpubridge::daemon {
namespace {

using protocol::ErrorCode;
using protocol::Message;
using protocol::MsgType;
using protocol::Reg;

constexpr std::uint32_t kUploadSlice = 1u << 20;         // between slices a cancelled upload stops
constexpr std::uint32_t kReadbackStep = 1u << 20;        // device read per step of a streamed READBACK
constexpr std::uint32_t kReadbackMessageOverhead = 64;   // header and fields of one READBACK_DATA, rounded up

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

ErrorCode code_for(const Error& e) {
  switch (e.code) {
    case backends::kDeviceGone: return ErrorCode::DeviceGone;
    case backends::kBadRequest: return ErrorCode::Range;
    default: return ErrorCode::DeviceError;
  }
}

std::string hex_index(unsigned index) {
  const char* digits = "0123456789ABCDEF";
  return std::string("0x") + digits[(index >> 4) & 0xF] + digits[index & 0xF];
}

}  // namespace

template <class T, class Work, class OnOk>
void RequestHandler::device_request(std::uint32_t request_id, Work work, OnOk on_ok) {
  session_.pause();
  hub_.device().request<T>(
      session_.cancel_flag(), std::move(work),
      [self = session_.shared_from_this(), request_id, on_ok = std::move(on_ok)](Result<T> r) mutable {
        if (self->closed()) return;  // cancelled, or the session ended meanwhile: nobody to answer
        auto& h = self->handler();
        if (!r) {
          h.reply_device_error(request_id, r.error());
        } else if constexpr (std::is_void_v<T>) {
          on_ok(h);
        } else {
          on_ok(h, std::move(*r));
        }
        if (!std::exchange(h.continues_, false)) self->resume();
      });
}

void RequestHandler::reply_device_error(std::uint32_t request_id, const Error& e) {
  session_.reply_error(request_id, code_for(e), "device error: " + e.message);
}

void RequestHandler::dispatch(Message& m) {
  const MsgType type = protocol::type_of(m.payload);
  if (protocol::sender(type) == protocol::Sender::Server) {
    session_.fail(ErrorCode::UnknownType, std::string(protocol::to_string(type)) + " is a server-to-client message",
                  m.request_id);
    return;
  }
  if (!session_.handshaken()) {
    if (type != MsgType::Hello) {
      session_.fail(ErrorCode::NotHandshaken,
                    "the first message must be HELLO, got " + std::string(protocol::to_string(type)), m.request_id);
      return;
    }
    handle_hello(m);
    return;
  }
  if (!device_kind_fits(m)) return;
  if (type == MsgType::WriteFramesZ && !inflate(m)) return;
  if (recorder_) recorder_->record(m);  // a compressed batch is recorded as the WRITE_FRAMES it stands for
  switch (protocol::type_of(m.payload)) {
    case MsgType::Hello: session_.fail(ErrorCode::Malformed, "HELLO sent twice", m.request_id); return;
    case MsgType::Ping: session_.reply(m.request_id, protocol::Pong{std::get<protocol::Ping>(m.payload).data}); return;
    case MsgType::Pong: return;  // the answer to a keepalive; receiving it is all that counts
    case MsgType::Bye:
      session_.reply(m.request_id, protocol::Bye{});
      session_.close_after_flush();
      return;
    case MsgType::WriteFrames: handle_write_frames(m); return;
    case MsgType::Dmc1Words: handle_dmc1_words(m); return;
    case MsgType::ReadReg: handle_read_reg(m); return;
    case MsgType::Upload: handle_upload(m); return;
    case MsgType::Readback: handle_readback(m); return;
    case MsgType::Fence: handle_fence(m); return;
    case MsgType::StatusReq: session_.reply(m.request_id, protocol::StatusReply{json_text(hub_.status_json())}); return;
    case MsgType::Subscribe: handle_subscribe(m); return;
    case MsgType::Unsubscribe: session_.subscription().unsubscribe(); return;
    case MsgType::LeaseAcquire: handle_lease_acquire(m); return;
    case MsgType::LeaseRelease: handle_lease_release(m); return;
    default:
      session_.fail(ErrorCode::UnknownType, "unexpected " + std::string(protocol::to_string(type)), m.request_id);
  }
}

void RequestHandler::handle_hello(const Message& m) {
  const auto& h = std::get<protocol::Hello>(m.payload);
  if (h.version != protocol::kSocketVersion) {
    session_.fail(ErrorCode::BadVersion,
                  "protocol version " + std::to_string(h.version) + " is not supported (this daemon speaks 1)", m.request_id);
    return;
  }
  if (session_.tls_required() && session_.security() != Stream::Security::Tls) {
    hub_.log_refusal("refused a plain TCP client from " + session_.peer() + " on a TLS-only listener");
    session_.fail(ErrorCode::AuthFailed,
                  "this listener takes TLS only (it is reachable from other machines): connect with tls:HOST:PORT "
                  "instead of tcp:HOST:PORT (docs/daemon.md \"Remote use\")",
                  m.request_id, /*quiet=*/true);
    return;
  }
  const auto& token = hub_.options().token;
  if (!token.empty() && session_.transport() == "tcp" && !tokens_equal(h.token, token)) {
    hub_.log_refusal("bad token from " + session_.peer());
    session_.fail(ErrorCode::AuthFailed, "token rejected", m.request_id, /*quiet=*/true);
    return;
  }
  // Only sessions that completed their handshake count against max_clients: peers that never say
  // HELLO cannot take the slots of those that do.
  if (std::string why; !hub_.may_handshake(session_.transport(), why)) {
    hub_.log_refusal("refused a " + session_.transport() + " client: " + why);
    session_.fail(ErrorCode::ServerFull, why, m.request_id, /*quiet=*/true);
    return;
  }
  session_.handshake_done(h.name);
  const bool zstd = h.codecs && (*h.codecs & protocol::codec_bit(protocol::Codec::Zstd));
  if (zstd) inflater_ = std::make_unique<protocol::FrameInflater>();
  if (!hub_.options().record_dir.empty()) {
    auto r = TraceRecorder::open(hub_.options().record_dir, session_.id(), h.name, hub_.device_info().kind);
    if (r) recorder_ = std::move(*r);
    else logger("daemon")->error("session {}: {}", session_.id(), r.error().message);
  }
  logger("daemon")->info("session {}: \"{}\" connected over {}{}", session_.id(), h.name, session_.transport(),
                         zstd ? " (zstd)" : "");
  session_.reply(m.request_id, protocol::Welcome{protocol::kSocketVersion, hub_.options().limits.max_message_bytes,
                                                 session_.id(), hub_.device_json(zstd ? "zstd" : "none", session_.transport())});
}

bool RequestHandler::inflate(Message& m) {
  const auto z = std::get<protocol::WriteFramesZ>(m.payload);
  if (!inflater_) {
    session_.fail(ErrorCode::Malformed, "WRITE_FRAMES_Z without compression: HELLO offered no codec", m.request_id);
    return false;
  }
  if (!require_lease(m)) return false;  // no work spent inflating for a client that may not draw
  // The bound holds before a byte is inflated: frames_bytes is what the daemon will allocate.
  const auto limit = hub_.options().limits.max_message_bytes;
  if (z.frames_bytes > limit) {
    session_.fail(ErrorCode::TooLarge, "WRITE_FRAMES_Z frames_bytes " + std::to_string(z.frames_bytes) +
                                           " exceeds the maximum payload of " + std::to_string(limit) + " bytes",
                  m.request_id);
    return false;
  }
  if (auto e = inflater_->inflate(z, inflated_)) {
    session_.fail(e->code, e->message + " (request " + std::to_string(m.request_id) + ")", m.request_id);
    return false;
  }
  m.payload = protocol::WriteFrames{protocol::FrameView{inflated_}};
  return true;
}

// Which device kind a command message is for; nullopt for messages every kind takes (FENCE, STATUS,
// SUBSCRIBE, the lease, ...).
static std::optional<protocol::DeviceKind> kind_of_command(MsgType t) {
  switch (t) {
    case MsgType::WriteFrames:
    case MsgType::WriteFramesZ:
    case MsgType::ReadReg:
    case MsgType::Upload:
    case MsgType::Readback: return protocol::DeviceKind::Spigpu;
    case MsgType::Dmc1Words: return protocol::DeviceKind::Dmc1;
    default: return std::nullopt;
  }
}

bool RequestHandler::device_kind_fits(const Message& m) {
  const MsgType type = protocol::type_of(m.payload);
  const auto wanted = kind_of_command(type);
  const auto served = hub_.device_info().kind;
  if (!wanted || *wanted == served) return true;
  // Not fatal: the client learns what this daemon serves and may go on (STATUS, SUBSCRIBE, ...).
  const auto& have = protocol::device_kind_info(served);
  const auto& want = protocol::device_kind_info(*wanted);
  std::string what = std::string(protocol::to_string(type)) + " is a " + std::string(want.label) + " command, but this gpubridged serves a " +
                     std::string(have.label) + " (WELCOME's \"device_kind\": \"" + std::string(have.name) + "\"); ";
  what += served == protocol::DeviceKind::Dmc1
              ? "send DMC-1 command words (DMC1_WORDS; `gpubridge play STREAM.dmc1`), or start gpubridged with a spigpu backend"
              : "send spigpu register writes (WRITE_FRAMES), or start gpubridged with --backend dmc1";
  session_.reply_error(m.request_id, ErrorCode::WrongDevice, what);
  return false;
}

bool RequestHandler::require_lease(const Message& m) {
  if (hub_.lease().held_by(session_.id())) return true;
  session_.reply_error(m.request_id, ErrorCode::NoLease,
                       std::string(protocol::to_string(protocol::type_of(m.payload))) +
                           " needs the device lease (send LEASE_ACQUIRE first)");
  return false;
}

void RequestHandler::handle_write_frames(const Message& m) {
  if (!require_lease(m)) return;
  // No read-bit scan here: the parser already refused any read frame (fatal BAD_FRAME).
  // `frames` points into the parser buffer; the session reads nothing until the work is done.
  const auto frames = std::get<protocol::WriteFrames>(m.payload).frames;
  device_request<void>(m.request_id, [frames](backends::Backend& b) { return b.write_frames(frames); },
                       [](RequestHandler&) {});
}

void RequestHandler::handle_dmc1_words(const Message& m) {
  if (!require_lease(m)) return;
  // Copied out of the parser buffer as whole 64-bit words (the payload's alignment is arbitrary);
  // bounded by max_payload like every message.
  dmc1_words_ = protocol::dmc1_words_of(std::get<protocol::Dmc1Words>(m.payload).bytes);
  const std::span<const std::uint64_t> words = dmc1_words_;
  device_request<void>(m.request_id, [words](backends::Backend& b) { return b.write_dmc1_words(words); },
                       [](RequestHandler&) {});
}

void RequestHandler::handle_read_reg(const Message& m) {
  const auto index = std::get<protocol::ReadReg>(m.payload).index;
  const auto rid = m.request_id;
  if (index >= protocol::kRegisterCount) {
    session_.reply_error(rid, ErrorCode::Range, "register index " + std::to_string(index) + " is beyond 127");
    return;
  }
  auto read = [this, rid, index] {
    device_request<std::uint64_t>(
        rid, [index](backends::Backend& b) { return b.read_register(index); },
        [rid, index](RequestHandler& h, std::uint64_t v) { h.session_.reply(rid, protocol::RegValue{index, v}); });
  };
  if (hub_.lease().held_by(session_.id())) return read();  // the holder reads exactly as the device answers
  // Without the lease a read must not change anything a holder sees: no error flag, nothing folded
  // into the link CRC, no MEM_ADDR step (docs/daemon.md "Lease").
  const auto* reg = protocol::find_register(index);
  if (!reg) {
    session_.reply_error(rid, ErrorCode::Range,
                         "register " + hex_index(index) + " is not defined; only the lease holder may read undefined "
                         "registers (the device flags ERR_BAD_REGISTER)");
    return;
  }
  if (index == protocol::index_of(Reg::MEM_DATA)) {
    // Reading MEM_DATA advances MEM_ADDR: that changes device state, so it needs the lease.
    require_lease(m);
    return;
  }
  // ID, CAPS and CAPS2 are constants, known since the device was attached. CAPS2 is defined from
  // protocol 1.4 on: on an older device its index is undefined (the device would flag it).
  const bool caps2 = index == protocol::index_of(Reg::CAPS2);
  if (caps2 && protocol::protocol_minor(hub_.device_info().id) < 4) {
    session_.reply_error(rid, ErrorCode::Range,
                         "register 0x7D (CAPS2) is defined from protocol 1.4 on; this device is v1." +
                             std::to_string(protocol::protocol_minor(hub_.device_info().id)) +
                             " (only the lease holder may read undefined registers; the device flags ERR_BAD_REGISTER)");
    return;
  }
  if (index == protocol::index_of(Reg::ID) || index == protocol::index_of(Reg::CAPS) || caps2) {
    const auto& info = hub_.device_info();
    session_.reply(rid, protocol::RegValue{index, index == protocol::index_of(Reg::ID) ? info.id
                                                  : caps2                                ? info.caps2
                                                                                         : info.caps});
    return;
  }
  if (!hub_.lease().idle()) {
    session_.reply_error(rid, ErrorCode::Busy,
                         "READ_REG " + std::string(reg->name) + ": another client holds the device lease; while it "
                         "does, clients without the lease can read only ID, CAPS and CAPS2 (acquire the lease, or read after "
                         "it is released)");
    return;
  }
  hub_.lease().touched();  // the read counts in the link CRC: the next holder gets a reset device
  read();
}

void RequestHandler::handle_upload(const Message& m) {
  if (!require_lease(m)) return;
  const auto& u = std::get<protocol::Upload>(m.payload);
  const auto address = u.address;
  const auto data = u.data;  // a view into the parser buffer
  auto& device = hub_.device();
  device_request<void>(
      m.request_id,
      [&device, address, data](backends::Backend& b) -> Result<void> {
        // In slices, so a cancelled session or a shutdown stops a slow board's upload in between.
        for (std::size_t at = 0; at < data.size(); at += kUploadSlice) {
          if (device.aborted()) return DeviceWorker::cancelled_error();
          const auto n = std::min<std::size_t>(kUploadSlice, data.size() - at);
          if (auto r = b.upload(address + static_cast<std::uint32_t>(at), data.subspan(at, n)); !r) return r;
        }
        return {};
      },
      [rid = m.request_id, address, n = data.size()](RequestHandler& h) {
        h.session_.reply(rid, protocol::UploadAck{address, static_cast<std::uint32_t>(n)});
      });
}

void RequestHandler::handle_readback(const Message& m) {
  if (!require_lease(m)) return;
  const auto rb = std::get<protocol::Readback>(m.payload);
  if (rb.length == 0 || rb.length > protocol::kMaxReadbackBytes) {
    session_.reply_error(m.request_id, ErrorCode::Range,
                         "READBACK length must be 1.." + std::to_string(protocol::kMaxReadbackBytes));
    return;
  }
  readback_step(m.request_id, rb.address, rb.length, 0);
}

// One step of a streamed READBACK: read the next piece from the device, queue it as READBACK_DATA
// chunks, and take the next step only once it fits under queue_bytes. A 64 MiB readback to a
// client that reads slowly therefore holds at most one step in memory beyond the queue's bound.
void RequestHandler::readback_step(std::uint32_t rid, std::uint32_t address, std::uint32_t length, std::uint32_t done) {
  const std::uint64_t limit = session_.outgoing().limit();
  const auto step = static_cast<std::uint32_t>(
      std::max<std::uint64_t>(protocol::kMaxReadbackChunk,
                              std::min<std::uint64_t>(kReadbackStep, limit / 2) / protocol::kMaxReadbackChunk *
                                  protocol::kMaxReadbackChunk));
  const std::uint32_t n = std::min(step, length - done);
  const std::uint32_t at = address + done;
  device_request<std::vector<std::uint8_t>>(
      rid, [at, n](backends::Backend& b) { return b.readback(at, n); },
      [rid, address, length, done, n, step](RequestHandler& h, std::vector<std::uint8_t> data) {
        auto& s = h.session_;
        if (data.size() != n) {
          s.reply_error(rid, ErrorCode::DeviceError,
                        "backend returned " + std::to_string(data.size()) + " of " + std::to_string(n) + " bytes");
          return;
        }
        for (std::size_t off = 0; off < data.size(); off += protocol::kMaxReadbackChunk) {
          const std::size_t k = std::min<std::size_t>(protocol::kMaxReadbackChunk, data.size() - off);
          const bool last = done + off + k == length;
          s.reply(rid, protocol::ReadbackData{static_cast<std::uint32_t>(address + done + off), last,
                                              std::span<const std::uint8_t>(data.data() + off, k)});
        }
        const std::uint32_t next = done + n;
        if (next == length) return;
        // The message stays live: no resume() after this step (when_room may even run the next
        // step at once, inside this call).
        h.continues_ = true;
        auto self = s.shared_from_this();
        const std::uint64_t want = std::min(step, length - next) +
                                   (std::uint64_t{step} / protocol::kMaxReadbackChunk + 1) * kReadbackMessageOverhead;
        s.when_room(want, [self, rid, address, length, next] { self->handler().readback_step(rid, address, length, next); });
      });
}

void RequestHandler::handle_fence(const Message& m) {
  const auto fence_id = std::get<protocol::FenceMsg>(m.payload).id;
  if (!hub_.lease().held_by(session_.id())) {
    // A client without the lease has no device work in flight (its earlier requests completed
    // before this one was read): answered at once, the holder's device is not touched.
    session_.reply(m.request_id, protocol::FenceDone{fence_id});
    return;
  }
  device_request<void>(m.request_id, [](backends::Backend& b) { return b.flush(); },
                       [rid = m.request_id, fence_id](RequestHandler& h) {
                         h.session_.reply(rid, protocol::FenceDone{fence_id});
                       });
}

void RequestHandler::handle_subscribe(const Message& m) {
  const auto& s = std::get<protocol::Subscribe>(m.payload);
  const auto source = s.source.value_or(protocol::FrameSource::Board);
  if (source != protocol::FrameSource::Board && !hub_.options().mirror) {
    // Not fatal: the session (and any earlier subscription) stays as it was.
    session_.reply_error(m.request_id, ErrorCode::Unavailable,
                         "SUBSCRIBE source \"" + std::string(protocol::to_string(source)) +
                             "\" needs mirror mode, which this gpubridged does not run: start it with --mirror and a "
                             "board backend (e.g. --backend emulated:icebreaker --mirror), or subscribe to source "
                             "\"board\"");
    return;
  }
  auto& sub = session_.subscription();
  const bool switched = sub.active() && source != sub.source();
  sub.subscribe(s.format, source, s.max_fps);
  if (switched) hub_.offer_newest_frame(session_);
}

void RequestHandler::handle_lease_acquire(const Message& m) {
  const auto mode = std::get<protocol::LeaseAcquire>(m.payload).mode;
  switch (hub_.lease().acquire(session_.id(), mode)) {
    case Lease::Outcome::Granted: session_.reply(m.request_id, protocol::LeaseGranted{session_.id()}); return;
    case Lease::Outcome::Busy: session_.reply_error(m.request_id, ErrorCode::Busy, "another client holds the device lease"); return;
    case Lease::Outcome::Queued:
      // Keep the client's order: nothing after LEASE_ACQUIRE runs before the grant.
      session_.pause();
      lease_request_id_ = m.request_id;
      return;
  }
}

void RequestHandler::handle_lease_release(const Message& m) {
  if (!hub_.lease().release(session_.id())) {
    session_.reply_error(m.request_id, ErrorCode::NoLease,
                         "LEASE_RELEASE: this client does not hold the device lease (another client's lease is "
                         "never released for it)");
    return;
  }
  session_.reply(m.request_id, protocol::LeaseReleased{});
}

void RequestHandler::on_lease_granted() { session_.reply(lease_request_id_, protocol::LeaseGranted{session_.id()}); }

void RequestHandler::on_closed() {
  if (recorder_) recorder_->flush();
}

}  // namespace gpubridge::daemon
