#include "gpubridge/client/client.hpp"

#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "gpubridge/client/daemon_owner.hpp"
#include "gpubridge/client/tls.hpp"

#include <fstream>
#include <sys/stat.h>

namespace gpubridge::client {
namespace {

using Clock = std::chrono::steady_clock;
using protocol::Message;
using protocol::MsgType;

Error io_error(std::string what) { return make_error(std::move(what), kConnectionError); }

int remaining_ms(Clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return left <= 0 ? 0 : static_cast<int>(std::min<long long>(left, 1 << 30));
}

std::string errno_text(int err) {
  switch (err) {
    case ENOENT: return "no such file";
    case ECONNREFUSED: return "connection refused";
    case EACCES: return "permission denied";
    default: return std::strerror(err);
  }
}

// Waits for a non-blocking connect to finish.
Result<void> finish_connect(int fd, Clock::time_point deadline, const std::string& where) {
  pollfd p{fd, POLLOUT, 0};
  const int n = ::poll(&p, 1, remaining_ms(deadline));
  if (n == 0) return make_error("cannot connect to " + where + ": timed out", kTimeoutError);
  int err = 0;
  socklen_t len = sizeof err;
  ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &len);
  if (n < 0 || err != 0) return io_error("cannot connect to " + where + ": " + errno_text(n < 0 ? errno : err));
  return {};
}

Result<int> open_unix(const Address& a, Clock::time_point deadline) {
  const std::string where = a.to_string();
  sockaddr_un sa{};
  sa.sun_family = AF_UNIX;
  if (a.path.size() >= sizeof sa.sun_path) return io_error("cannot connect to " + where + ": path too long");
  std::memcpy(sa.sun_path, a.path.c_str(), a.path.size() + 1);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) return io_error("socket(): " + errno_text(errno));
  // A Unix connect completes at once or fails; EAGAIN means the daemon's listen queue is full (it
  // is busy accepting), not "in progress": the socket is not connected, so try again.
  while (::connect(fd, reinterpret_cast<const sockaddr*>(&sa), sizeof sa) != 0) {
    const int err = errno;
    if (err == EINTR) continue;
    if (err == EAGAIN && Clock::now() < deadline) {
      ::usleep(2000);
      continue;
    }
    ::close(fd);
    if (err == EAGAIN)
      return make_error("cannot connect to " + where + ": timed out (the daemon's listen queue stayed full)", kTimeoutError);
    std::string hint = (err == ENOENT || err == ECONNREFUSED) ? "; is gpubridged running?" : "";
    return io_error("cannot connect to " + where + ": " + errno_text(err) + hint);
  }
  return fd;
}

Result<int> open_tcp(const Address& a, Clock::time_point deadline) {
  const std::string where = a.to_string();
  addrinfo hints{};
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* list = nullptr;
  const std::string port = std::to_string(a.port);
  if (const int rc = ::getaddrinfo(a.host.c_str(), port.c_str(), &hints, &list); rc != 0)
    return io_error("cannot resolve " + a.host + ": " + ::gai_strerror(rc));
  Error last = io_error("cannot connect to " + where + ": no addresses");
  for (addrinfo* ai = list; ai; ai = ai->ai_next) {
    const int fd = ::socket(ai->ai_family, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
    if (fd < 0) continue;
    const int one = 1;
    ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    if (::connect(fd, ai->ai_addr, ai->ai_addrlen) == 0) {
      ::freeaddrinfo(list);
      return fd;
    }
    if (errno != EINPROGRESS) {
      const int err = errno;
      last = io_error("cannot connect to " + where + ": " + errno_text(err) +
                      (err == ECONNREFUSED ? "; is gpubridged listening on TCP?" : ""));
      ::close(fd);
      continue;
    }
    if (auto r = finish_connect(fd, deadline, where); r) {
      ::freeaddrinfo(list);
      return fd;
    } else {
      last = r.error();
    }
    ::close(fd);
  }
  ::freeaddrinfo(list);
  return last;
}

Error interrupted_error() { return make_error("interrupted", kInterrupted); }

Error from_error_msg(const protocol::ErrorMsg& e) {
  return make_error(std::string(protocol::to_string(e.code)) + ": " + e.text,
                    kProtocolErrorBase + static_cast<int>(e.code));
}

}  // namespace

Client::Client(Client&& o) noexcept { *this = std::move(o); }
Client& Client::operator=(Client&& o) noexcept {
  if (this != &o) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(o.fd_, -1);
    address_ = std::move(o.address_);
    session_ = std::move(o.session_);
    request_counter_ = o.request_counter_;
    parser_ = std::move(o.parser_);
    inbox_ = std::move(o.inbox_);
    readback_chunks_ = std::move(o.readback_chunks_);
    latest_frame_ = std::move(o.latest_frame_);
    events_ = std::move(o.events_);
    async_error_ = std::move(o.async_error_);
    pongs_ = std::move(o.pongs_);
    interrupt_ = o.interrupt_;
    tls_ = std::move(o.tls_);
    fences_ = std::move(o.fences_);
    async_uploads_ = std::move(o.async_uploads_);
    fences_done_ = o.fences_done_;
    fence_callback_ = std::move(o.fence_callback_);
    deflater_ = std::move(o.deflater_);
    deflated_ = std::move(o.deflated_);
    wire_ = o.wire_;
  }
  return *this;
}
Client::~Client() {
  tls_.reset();  // before the socket it uses
  if (fd_ >= 0) ::close(fd_);
}

Result<std::string> token_from_environment() {
  if (const char* env = std::getenv(kTokenEnv); env && *env) return std::string(env);
  const char* file = std::getenv(kTokenFileEnv);
  if (!file || !*file) return std::string();
  const std::string where = std::string(kTokenFileEnv) + "=" + file;
  struct stat st{};
  if (::stat(file, &st) != 0) return make_error(where + ": " + errno_text(errno));
  if (!S_ISREG(st.st_mode)) return make_error(where + ": not a regular file");
  if (st.st_size > 4096) return make_error(where + ": larger than 4 KiB; the token goes on the first line");
  std::ifstream in(file);
  std::string line;
  if (!in || !std::getline(in, line)) return make_error(where + ": cannot read it (or it is empty)");
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t')) line.pop_back();
  if (line.empty()) return make_error(where + ": the first line is empty; put the token there");
  return line;
}

Result<Client> Client::connect(std::string_view address, Timeout timeout) {
  auto addr = parse_connect_address(address);
  if (!addr) return addr.error();
  const auto deadline = Clock::now() + timeout;
  auto fd = addr->kind == Address::Kind::Unix ? open_unix(*addr, deadline) : open_tcp(*addr, deadline);
  if (!fd) return fd.error();
  if (addr->kind == Address::Kind::Unix) {
    if (auto r = check_daemon_owner(*fd, addr->to_string()); !r) {
      ::close(*fd);
      return r.error();
    }
  }
  Client c;
  c.fd_ = *fd;
  c.address_ = *addr;
  if (addr->tls) {
    auto t = TlsConnection::establish(*fd, *addr, deadline);
    if (!t) return t.error();  // c closes the socket
    c.tls_ = std::move(*t);
  }
  c.parser_ = std::make_unique<protocol::MessageParser>(protocol::kMaxPayload);
  return c;
}

void Client::close() {
  if (fd_ < 0) return;
  (void)send_message(Message{next_request_id(), protocol::Bye{}}, Timeout{200});
  tls_.reset();
  ::close(fd_);
  fd_ = -1;
}

long Client::read_some(std::span<std::uint8_t> room) {
  if (tls_) return tls_->read(room);
  const ssize_t n = ::recv(fd_, room.data(), room.size(), 0);
  return n < 0 ? -errno : n;
}

long Client::write_some(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b) {
  if (tls_) {
    // One TLS record per call; a small header goes together with what follows it.
    if (!a.empty() && a.size() < 64 && !b.empty()) {
      std::uint8_t joined[64 + 16384];
      const std::size_t nb = std::min(b.size(), sizeof joined - a.size());
      std::memcpy(joined, a.data(), a.size());
      std::memcpy(joined + a.size(), b.data(), nb);
      return tls_->write({joined, a.size() + nb});
    }
    return tls_->write(!a.empty() ? a : b);
  }
  iovec iov[2];
  int n_iov = 0;
  if (!a.empty()) iov[n_iov++] = {const_cast<std::uint8_t*>(a.data()), a.size()};
  if (!b.empty()) iov[n_iov++] = {const_cast<std::uint8_t*>(b.data()), b.size()};
  msghdr msg{};
  msg.msg_iov = iov;
  msg.msg_iovlen = static_cast<std::size_t>(n_iov);
  // MSG_NOSIGNAL: a daemon that went away is an error to return, not a SIGPIPE to die of.
  const ssize_t n = ::sendmsg(fd_, &msg, MSG_NOSIGNAL);
  return n < 0 ? -errno : n;
}

bool Client::read_buffered() const { return tls_ && tls_->pending(); }

Result<void> Client::send_message(const Message& m, Timeout timeout) {
  const auto bytes = protocol::encode(m);
  return send_raw(bytes, {}, timeout);
}

Result<void> Client::send_raw(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b, Timeout timeout) {
  if (auto r = send_pongs(timeout); !r) return r;
  return write_all(a, b, timeout);
}

Result<void> Client::send_pongs(Timeout timeout) {
  // Called only between messages: a PONG never lands inside another message on the wire.
  while (!pongs_.empty()) {
    const auto bytes = protocol::encode(Message{0, protocol::Pong{std::move(pongs_.front())}});
    pongs_.erase(pongs_.begin());
    if (auto r = write_all(bytes, {}, timeout); !r) return r;
  }
  return {};
}

Result<void> Client::write_all(std::span<const std::uint8_t> a, std::span<const std::uint8_t> b, Timeout timeout) {
  if (fd_ < 0) return io_error("not connected");
  const auto deadline = Clock::now() + timeout;
  while (!a.empty() || !b.empty()) {
    if (interrupted()) return interrupted_error();
    const long n = write_some(a, b);
    if (n > 0) {
      std::size_t done = static_cast<std::size_t>(n);
      wire_.bytes_sent += done;
      const std::size_t from_a = std::min(done, a.size());
      a = a.subspan(from_a);
      b = b.subspan(done - from_a);
      continue;
    }
    if (n < 0 && -n != EAGAIN && -n != EINTR) {
      const std::string why = errno_text(static_cast<int>(-n));
      if (auto words = daemon_last_words()) return *words;
      return io_error("lost connection to " + address_.to_string() + ": " + why);
    }
    // The daemon may be talking to us (errors, frames): read while waiting so neither side stalls.
    pollfd p{fd_, POLLOUT | POLLIN, 0};
    const int rc = ::poll(&p, 1, remaining_ms(deadline));
    if (rc == 0) return make_error("timed out sending to " + address_.to_string(), kTimeoutError);
    if ((rc > 0 && (p.revents & POLLIN)) || read_buffered()) {
      if (auto r = pump(deadline, false); !r) return r;
    }
  }
  return {};
}

std::optional<Error> Client::daemon_last_words() {
  auto error_in_inbox = [this]() -> std::optional<Error> {
    for (auto& m : inbox_)
      if (auto* e = std::get_if<protocol::ErrorMsg>(&m.payload)) return from_error_msg(*e);
    return std::nullopt;
  };
  // The bytes the daemon wrote before closing stay readable after our send failed; read until
  // its end of stream (or a short deadline: a reset connection may have lost them).
  const auto deadline = Clock::now() + std::chrono::milliseconds(200);
  while (Clock::now() < deadline) {
    const auto r = pump(deadline, true);
    if (auto e = error_in_inbox()) return e;
    if (!r) break;
  }
  return std::nullopt;
}

Result<void> Client::pump(Clock::time_point deadline, bool block) {
  if (fd_ < 0) return io_error("not connected");
  if (!read_buffered()) {  // decrypted bytes TLS already holds are not visible to poll
    pollfd p{fd_, POLLIN, 0};
    const int rc = ::poll(&p, 1, block ? remaining_ms(deadline) : 0);
    if (rc < 0 && errno != EINTR) return io_error("poll: " + errno_text(errno));
    if (rc <= 0) return {};
  }
  // Read straight into the parser's buffer (no copy per read; frames can be 4 MiB). The span is
  // empty only once the stream has failed to parse, which was already reported.
  const auto room = parser_->prepare(256 * 1024);
  if (room.empty()) return io_error("bad data from daemon: " + parser_->error().message);
  const long n = read_some(room);
  if (n == 0) {
    // Report the daemon's last words (e.g. SERVER_FULL, SHUTTING_DOWN) if it sent any.
    for (auto& m : inbox_)
      if (auto* e = std::get_if<protocol::ErrorMsg>(&m.payload)) return from_error_msg(*e);
    return io_error("daemon at " + address_.to_string() + " closed the connection");
  }
  if (n < 0) {
    if (-n == EAGAIN || -n == EINTR) return {};
    if (tls_ && -n == EPROTO) return make_error("TLS error from " + address_.to_string() + ": " + tls_->last_error(), kSecurityError);
    return io_error("lost connection to " + address_.to_string() + ": " + errno_text(static_cast<int>(-n)));
  }
  parser_->commit(static_cast<std::size_t>(n));
  for (;;) {
    Message m;
    const auto st = parser_->next(m);
    if (st == protocol::MessageParser::Status::NeedMore) break;
    if (st == protocol::MessageParser::Status::Error)
      return io_error("bad data from daemon: " + parser_->error().message);
    if (auto* f = std::get_if<protocol::FrameData>(&m.payload)) {
      ReceivedFrame rf;
      rf.number = f->number;
      rf.width = f->width;
      rf.height = f->height;
      rf.format = f->format;
      rf.crc = f->crc;
      rf.swap_ns = f->swap_ns;
      rf.source = f->source;
      rf.pixels.assign(f->pixels.begin(), f->pixels.end());
      latest_frame_ = std::move(rf);  // newest wins, like the daemon
    } else if (auto* ev = std::get_if<protocol::DeviceEvent>(&m.payload)) {
      if (events_.size() < 1024) events_.push_back(ev->json);
    } else if (auto* ping = std::get_if<protocol::Ping>(&m.payload)) {
      // The daemon's keepalive: answered by the next send_pongs() (never from inside a message).
      if (pongs_.size() < 16) pongs_.push_back(ping->data);
    } else if (auto* fd = std::get_if<protocol::FenceDone>(&m.payload)) {
      // Fences complete in order: this one and every earlier one are done.
      fences_done_ = std::max(fences_done_, fd->id);
      while (!fences_.empty() && fences_.front() <= fences_done_) {
        const auto h = fences_.front();
        fences_.pop_front();
        if (fence_callback_) fence_callback_(h);
      }
    } else if (std::holds_alternative<protocol::UploadAck>(m.payload) && !async_uploads_.empty() &&
               async_uploads_.front() <= m.request_id) {
      // An upload_async() chunk executed; nobody waits for its ACK. Ids before it were answered
      // with an ERROR instead (kept as the async error).
      while (!async_uploads_.empty() && async_uploads_.front() < m.request_id) async_uploads_.pop_front();
      if (!async_uploads_.empty() && async_uploads_.front() == m.request_id) async_uploads_.pop_front();
      else inbox_.push_back(std::move(m));
    } else if (auto* rd = std::get_if<protocol::ReadbackData>(&m.payload)) {
      // The span points into the parser buffer: keep an owning copy.
      readback_chunks_.push_back(ReadbackChunk{m.request_id, rd->last, {rd->data.begin(), rd->data.end()}});
    } else {
      inbox_.push_back(std::move(m));
    }
  }
  return {};
}

Result<void> Client::take_async_error() {
  if (async_error_) {
    Error e = std::move(*async_error_);
    async_error_.reset();
    return e;
  }
  return {};
}

Result<Message> Client::wait_for(std::uint32_t request_id, MsgType type, Timeout timeout) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    for (auto it = inbox_.begin(); it != inbox_.end(); ++it) {
      if (auto* e = std::get_if<protocol::ErrorMsg>(&it->payload)) {
        if (e->ref == request_id || e->ref == 0) {
          Error err = from_error_msg(*e);
          inbox_.erase(it);
          return err;
        }
        // An error for an earlier fire-and-forget request: remember the first one.
        if (!async_error_) async_error_ = from_error_msg(*e);
        inbox_.erase(it);
        it = inbox_.begin();
        if (it == inbox_.end()) break;
        continue;
      }
      if (it->request_id == request_id && protocol::type_of(it->payload) == type) {
        Message m = std::move(*it);
        inbox_.erase(it);
        return m;
      }
    }
    if (interrupted()) return interrupted_error();
    if (Clock::now() >= deadline)
      return make_error("timed out waiting for " + std::string(protocol::to_string(type)) + " from " + address_.to_string(),
                        kTimeoutError);
    if (auto r = pump(deadline, true); !r) return r.error();
    if (auto r = send_pongs(timeout); !r) return r.error();
  }
}

Result<SessionInfo> Client::handshake(std::string_view name, std::string_view token, Timeout timeout,
                                      Compression compression) {
  protocol::Hello h;
  h.name = std::string(name.substr(0, protocol::kMaxNameBytes));
  h.token = std::string(token);
  if (h.token.empty()) {
    auto env = token_from_environment();
    if (!env) return env.error();
    // The daemon asks only TCP clients for a token; a Unix socket client keeps it to itself.
    if (address_.kind == Address::Kind::Tcp) h.token = *env;
  }
  const bool remote = address_.kind == Address::Kind::Tcp && !is_loopback_host(address_.host);
  if (!h.token.empty() && remote && !tls_)
    return make_error("refusing to send the token in clear to " + address_.to_string() + ": connect with tls:" +
                          address_.to_string().substr(4) + " (the daemon's TCP listeners speak TLS) or through an "
                          "SSH tunnel to a loopback address (docs/daemon.md \"Remote use\")",
                      kSecurityError);
  if (compression == Compression::Auto)
    if (const char* env = std::getenv(kCompressEnv); env && *env) {
      const std::string v = env;
      if (v == "zstd") compression = Compression::Zstd;
      else if (v == "none") compression = Compression::None;
      else if (v != "auto") return make_error(std::string(kCompressEnv) + "=" + v + ": expected zstd, none or auto");
    }
  if (compression == Compression::Zstd || (compression == Compression::Auto && remote))
    h.codecs = protocol::codec_bit(protocol::Codec::Zstd);
  const auto id = next_request_id();
  if (auto r = send_message(Message{id, h}, timeout); !r) return r.error();
  auto reply = wait_for(id, MsgType::Welcome, timeout);
  if (!reply) return reply.error();
  const auto& w = std::get<protocol::Welcome>(reply->payload);
  if (w.max_payload < protocol::kMinMaxPayload || w.max_payload > protocol::kMaxPayload)
    return io_error("the daemon at " + address_.to_string() + " announced max_payload " + std::to_string(w.max_payload) +
                    ", outside the protocol's " + std::to_string(protocol::kMinMaxPayload) + ".." +
                    std::to_string(protocol::kMaxPayload) + " bytes (docs/protocol.md 17.1); is it a gpubridged?");
  session_ = SessionInfo{w.session_id, w.max_payload, w.json, false};
  for (const auto& k : protocol::device_kinds())
    if (w.json.find("\"device_kind\":\"" + std::string(k.name) + "\"") != std::string::npos) session_.device_kind = k.kind;
  // The daemon's choice is in the device description; a daemon that predates compression says
  // nothing, and gets plain WRITE_FRAMES.
  if (h.codecs && w.json.find("\"compression\":\"zstd\"") != std::string::npos) {
    session_.compressed = true;
    deflater_ = std::make_unique<protocol::FrameDeflater>();
  }
  return session_;
}

Result<void> Client::acquire_lease(protocol::LeaseMode mode, Timeout timeout) {
  const auto id = next_request_id();
  if (auto r = send_message(Message{id, protocol::LeaseAcquire{mode}}, timeout); !r) return r;
  auto reply = wait_for(id, MsgType::LeaseGranted, timeout);
  if (!reply) return reply.error();
  return {};
}

Result<void> Client::release_lease(Timeout timeout) {
  const auto id = next_request_id();
  if (auto r = send_message(Message{id, protocol::LeaseRelease{}}, timeout); !r) return r;
  auto reply = wait_for(id, MsgType::LeaseReleased, timeout);
  if (!reply) return reply.error();
  return {};
}

Result<void> Client::write_frames(protocol::FrameView frames, Timeout timeout) {
  const std::size_t max_payload = session_.max_payload ? session_.max_payload : protocol::kMaxPayload;
  const std::size_t per_message = std::max<std::size_t>(1, max_payload / protocol::kFrameBytes) * protocol::kFrameBytes;
  auto bytes = frames.bytes;
  while (!bytes.empty()) {
    const auto chunk = bytes.first(std::min(per_message, bytes.size()));
    const auto before = wire_.bytes_sent;
    if (deflater_ && deflater_->deflate(protocol::FrameView{chunk}, deflated_)) {
      // WRITE_FRAMES_Z: header, codec, frames_bytes, then the compressed bytes.
      std::uint8_t head[protocol::kHeaderBytes + 5];
      protocol::encode_header(MsgType::WriteFramesZ, static_cast<std::uint32_t>(deflated_.size() + 5), next_request_id(),
                              head);
      head[protocol::kHeaderBytes] = static_cast<std::uint8_t>(protocol::Codec::Zstd);
      for (int i = 0; i < 4; ++i)
        head[protocol::kHeaderBytes + 1 + i] = static_cast<std::uint8_t>(chunk.size() >> (8 * i));
      if (auto r = send_raw(head, deflated_, timeout); !r) return r;
    } else {
      std::uint8_t header[protocol::kHeaderBytes];
      protocol::encode_header(MsgType::WriteFrames, static_cast<std::uint32_t>(chunk.size()), next_request_id(), header);
      if (auto r = send_raw(header, chunk, timeout); !r) return r;
    }
    wire_.frame_bytes += chunk.size();
    wire_.frame_wire_bytes += wire_.bytes_sent - before;  // includes any PONG sent first (a few bytes, rarely)
    bytes = bytes.subspan(chunk.size());
  }
  return take_async_error();
}

Result<void> Client::write_dmc1_words(std::span<const std::uint64_t> words, Timeout timeout) {
  const std::size_t max_payload = session_.max_payload ? session_.max_payload : protocol::kMaxPayload;
  const std::size_t per_message = std::max<std::size_t>(1, max_payload / protocol::kDmc1WordBytes);
  std::vector<std::uint8_t> bytes;
  while (!words.empty()) {
    const auto chunk = words.first(std::min(per_message, words.size()));
    bytes.clear();
    protocol::append_dmc1_words(chunk, bytes);
    std::uint8_t header[protocol::kHeaderBytes];
    protocol::encode_header(MsgType::Dmc1Words, static_cast<std::uint32_t>(bytes.size()), next_request_id(), header);
    if (auto r = send_raw(header, bytes, timeout); !r) return r;
    words = words.subspan(chunk.size());
  }
  return take_async_error();
}

Result<std::uint64_t> Client::read_register(std::uint8_t index, Timeout timeout) {
  const auto id = next_request_id();
  if (auto r = send_message(Message{id, protocol::ReadReg{index}}, timeout); !r) return r.error();
  auto reply = wait_for(id, MsgType::RegValue, timeout);
  if (!reply) return reply.error();
  return std::get<protocol::RegValue>(reply->payload).value;
}

Result<void> Client::upload(std::uint32_t address, std::span<const std::uint8_t> bytes, const Progress& progress,
                            Timeout timeout) {
  const std::size_t max_payload = session_.max_payload ? session_.max_payload : protocol::kMaxPayload;
  const std::size_t chunk_max = std::min<std::size_t>(1u << 20, max_payload - 4);
  const std::uint64_t total = bytes.size();
  std::uint64_t done = 0;
  while (done < total) {
    const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(chunk_max, total - done));
    const std::uint64_t at = std::uint64_t{address} + done;
    if (at > 0xFFFFFFFFull) return make_error("upload runs past the 32-bit address space", 1);
    std::uint8_t head[protocol::kHeaderBytes + 4];
    const auto id = next_request_id();
    protocol::encode_header(MsgType::Upload, static_cast<std::uint32_t>(n + 4), id, head);
    for (int i = 0; i < 4; ++i) head[protocol::kHeaderBytes + i] = static_cast<std::uint8_t>(at >> (8 * i));
    if (auto r = send_raw(head, bytes.subspan(static_cast<std::size_t>(done), n), timeout); !r) return r;
    auto reply = wait_for(id, MsgType::UploadAck, timeout);
    if (!reply) return reply.error();
    done += n;
    if (progress) progress(done, total);
  }
  return take_async_error();
}

Result<void> Client::upload_async(std::uint32_t address, std::span<const std::uint8_t> bytes, Timeout timeout) {
  const std::size_t max_payload = session_.max_payload ? session_.max_payload : protocol::kMaxPayload;
  const std::size_t chunk_max = std::min<std::size_t>(1u << 20, max_payload - 4);
  for (std::size_t done = 0; done < bytes.size();) {
    const std::size_t n = std::min(chunk_max, bytes.size() - done);
    const std::uint64_t at = std::uint64_t{address} + done;
    if (at > 0xFFFFFFFFull) return make_error("upload runs past the 32-bit address space", 1);
    std::uint8_t head[protocol::kHeaderBytes + 4];
    const auto id = next_request_id();
    protocol::encode_header(MsgType::Upload, static_cast<std::uint32_t>(n + 4), id, head);
    for (int i = 0; i < 4; ++i) head[protocol::kHeaderBytes + i] = static_cast<std::uint8_t>(at >> (8 * i));
    async_uploads_.push_back(id);  // before sending: the ACK may be read while the send waits
    if (auto r = send_raw(head, bytes.subspan(done, n), timeout); !r) return r;
    done += n;
  }
  return take_async_error();
}

Result<std::vector<std::uint8_t>> Client::readback(std::uint32_t address, std::uint32_t length, const Progress& progress,
                                                   Timeout timeout) {
  constexpr std::uint32_t kMaxRequest = 64u << 20;
  std::vector<std::uint8_t> out;
  out.reserve(length);
  while (out.size() < length) {
    const std::uint64_t at = std::uint64_t{address} + out.size();
    if (at > 0xFFFFFFFFull) return make_error("readback runs past the 32-bit address space", 1);
    const auto n = static_cast<std::uint32_t>(std::min<std::uint64_t>(kMaxRequest, length - out.size()));
    const auto id = next_request_id();
    if (auto r = send_message(Message{id, protocol::Readback{static_cast<std::uint32_t>(at), n}}, timeout); !r)
      return r.error();
    const std::size_t goal = out.size() + n;
    const auto deadline = Clock::now() + timeout;
    for (bool last = false; !last;) {
      while (!readback_chunks_.empty() && readback_chunks_.front().request_id != id)
        readback_chunks_.pop_front();  // chunks of an abandoned earlier request
      if (readback_chunks_.empty()) {
        // An ERROR for this request ends the wait; otherwise keep reading until a chunk arrives.
        for (auto it = inbox_.begin(); it != inbox_.end(); ++it)
          if (auto* e = std::get_if<protocol::ErrorMsg>(&it->payload); e && (e->ref == id || e->ref == 0)) {
            Error err = from_error_msg(*e);
            inbox_.erase(it);
            return err;
          }
        if (interrupted()) return interrupted_error();
        if (Clock::now() >= deadline) return make_error("timed out waiting for readback data", kTimeoutError);
        if (auto r = pump(deadline, true); !r) return r.error();
        if (auto r = send_pongs(timeout); !r) return r.error();
        continue;
      }
      ReadbackChunk chunk = std::move(readback_chunks_.front());
      readback_chunks_.pop_front();
      if (chunk.data.size() > goal - out.size()) return io_error("daemon sent more readback data than asked for");
      out.insert(out.end(), chunk.data.begin(), chunk.data.end());
      last = chunk.last;
      if (progress) progress(out.size(), length);
    }
    if (out.size() != goal) return io_error("daemon ended a readback early");
  }
  if (auto r = take_async_error(); !r) return r.error();
  return out;
}

Result<void> Client::fence(Timeout timeout) {
  auto h = fence_async(timeout);
  if (!h) return h.error();
  return wait_fence(*h, timeout);
}

Result<Client::FenceHandle> Client::fence_async(Timeout timeout) {
  const auto id = next_request_id();
  if (auto r = send_message(Message{id, protocol::FenceMsg{id}}, timeout); !r) return r.error();
  fences_.push_back(id);
  return FenceHandle{id};
}

Result<void> Client::wait_fence(FenceHandle handle, Timeout timeout) {
  if (auto r = wait_until([&] { return fence_done(handle); }, "FENCE_DONE", timeout); !r) return r;
  return take_async_error();
}

Result<void> Client::wait_fences(std::size_t max_in_flight, Timeout timeout) {
  if (auto r = wait_until([&] { return fences_.size() <= max_in_flight; }, "FENCE_DONE", timeout); !r) return r;
  return take_async_error();
}

Result<void> Client::wait_until(const std::function<bool()>& done, const char* what, Timeout timeout) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    for (auto it = inbox_.begin(); it != inbox_.end();) {
      auto* e = std::get_if<protocol::ErrorMsg>(&it->payload);
      if (!e) {
        ++it;
        continue;
      }
      Error err = from_error_msg(*e);
      const bool fatal = e->ref == 0 || std::find(fences_.begin(), fences_.end(), FenceHandle{e->ref}) != fences_.end();
      it = inbox_.erase(it);
      if (fatal) return err;
      if (!async_error_) async_error_ = std::move(err);  // for an earlier fire-and-forget write
    }
    if (done()) return {};
    if (interrupted()) return interrupted_error();
    if (Clock::now() >= deadline)
      return make_error("timed out waiting for " + std::string(what) + " from " + address_.to_string(), kTimeoutError);
    if (auto r = pump(deadline, true); !r) return r.error();
    if (auto r = send_pongs(timeout); !r) return r.error();
  }
}

Result<std::string> Client::status(Timeout timeout) {
  const auto id = next_request_id();
  if (auto r = send_message(Message{id, protocol::StatusReq{}}, timeout); !r) return r.error();
  auto reply = wait_for(id, MsgType::StatusReply, timeout);
  if (!reply) return reply.error();
  return std::get<protocol::StatusReply>(reply->payload).json;
}

Result<void> Client::ping(Timeout timeout) {
  const auto id = next_request_id();
  if (auto r = send_message(Message{id, protocol::Ping{}}, timeout); !r) return r;
  auto reply = wait_for(id, MsgType::Pong, timeout);
  if (!reply) return reply.error();
  return {};
}

Result<void> Client::subscribe(protocol::FrameFormat format, std::uint16_t max_fps, Timeout timeout) {
  return subscribe(protocol::Subscribe{format, max_fps}, timeout);
}

Result<void> Client::subscribe(const protocol::Subscribe& request, Timeout timeout) {
  // SUBSCRIBE has no reply of its own; a PING behind it confirms the daemon accepted it.
  const auto id = next_request_id();
  if (auto r = send_message(Message{id, request}, timeout); !r) return r;
  if (auto r = ping(timeout); !r) return r;
  return take_async_error();
}

Result<void> Client::unsubscribe(Timeout timeout) {
  if (auto r = send_message(Message{next_request_id(), protocol::Unsubscribe{}}, timeout); !r) return r;
  if (auto r = ping(timeout); !r) return r;
  latest_frame_.reset();
  return take_async_error();
}

Result<ReceivedFrame> Client::next_frame(Timeout timeout) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    if (latest_frame_) {
      ReceivedFrame f = std::move(*latest_frame_);
      latest_frame_.reset();
      return f;
    }
    for (auto it = inbox_.begin(); it != inbox_.end(); ++it) {
      if (auto* e = std::get_if<protocol::ErrorMsg>(&it->payload)) {
        Error err = from_error_msg(*e);
        inbox_.erase(it);
        return err;
      }
    }
    if (interrupted()) return interrupted_error();
    if (Clock::now() >= deadline) return make_error("no frame from " + address_.to_string() + " within the timeout", kTimeoutError);
    if (auto r = pump(deadline, true); !r) return r.error();
    if (auto r = send_pongs(timeout); !r) return r.error();
  }
}

std::vector<std::string> Client::take_device_events() { return std::exchange(events_, {}); }

RegisterWriter::RegisterWriter(Client& client, std::size_t batch_frames)
    : client_(client), batch_frames_(std::max<std::size_t>(1, batch_frames)) {
  bytes_.reserve(batch_frames_ * protocol::kFrameBytes);
}

Result<void> RegisterWriter::write(std::uint8_t index, std::uint64_t data) {
  protocol::append(bytes_, protocol::Frame{false, static_cast<std::uint8_t>(index & 0x7F), data});
  if (pending() >= batch_frames_) return flush();
  return {};
}

Result<void> RegisterWriter::write_raw(protocol::FrameView frames) {
  if (auto r = flush(); !r) return r;
  return client_.write_frames(frames);
}

Result<void> RegisterWriter::flush() {
  if (bytes_.empty()) return {};
  auto r = client_.write_frames(protocol::FrameView{bytes_});
  bytes_.clear();
  return r;
}

}  // namespace gpubridge::client
