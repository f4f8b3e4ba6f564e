#pragma once
// RequestHandler: what one session's messages mean. Session hands it each parsed message in order;
// it checks the handshake and the lease, runs device work through one device_request() helper,
// streams READBACK replies a step at a time, keeps subscriptions and records the session's trace.
// Clients without the lease never reach the device while someone else holds it (docs/daemon.md
// "Lease"). Network thread only.
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>

#include "gpubridge/common/result.hpp"
#include "gpubridge/daemon/trace_recorder.hpp"
#include "gpubridge/protocol/compression.hpp"
#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::daemon {

class Hub;
class Session;

class RequestHandler {
 public:
  RequestHandler(Session& session, Hub& hub) : session_(session), hub_(hub) {}

  void dispatch(protocol::Message& m);
  void on_lease_granted();
  void on_closed();  // the connection ended: flush the recording

 private:
  void handle_hello(const protocol::Message& m);
  void handle_write_frames(const protocol::Message& m);
  void handle_dmc1_words(const protocol::Message& m);
  // False (and an ERROR WRONG_DEVICE reply) when m is a command for another device kind than the
  // one this daemon serves (docs/protocol.md 17.7).
  bool device_kind_fits(const protocol::Message& m);
  // WRITE_FRAMES_Z: inflates into inflated_ (bounded by max_message_bytes before it starts) and
  // turns m into the WRITE_FRAMES it stands for. False when the session was failed or answered.
  bool inflate(protocol::Message& m);
  void handle_read_reg(const protocol::Message& m);
  void handle_upload(const protocol::Message& m);
  void handle_readback(const protocol::Message& m);
  void readback_step(std::uint32_t request_id, std::uint32_t address, std::uint32_t length, std::uint32_t done);
  void handle_fence(const protocol::Message& m);
  void handle_subscribe(const protocol::Message& m);
  void handle_lease_acquire(const protocol::Message& m);
  void handle_lease_release(const protocol::Message& m);
  bool require_lease(const protocol::Message& m);
  void reply_device_error(std::uint32_t request_id, const Error& e);

  // Pauses the session, runs work(Backend&) -> Result<T> on the device and then, on the network
  // thread, on_ok(handler[, T]) or an ERROR reply, and resumes the session. Work is cancelled
  // when the session ends.
  template <class T, class Work, class OnOk>
  void device_request(std::uint32_t request_id, Work work, OnOk on_ok);

  Session& session_;
  Hub& hub_;
  std::unique_ptr<TraceRecorder> recorder_;
  std::uint32_t lease_request_id_ = 0;
  bool continues_ = false;  // set by a device_request step that started the next step of its message
  // WRITE_FRAMES compression, when HELLO offered it (docs/protocol.md 17.6). inflated_ holds one
  // message's frames while its device work runs (the session reads nothing meanwhile).
  std::unique_ptr<protocol::FrameInflater> inflater_;
  std::vector<std::uint8_t> inflated_;
  std::vector<std::uint64_t> dmc1_words_;  // one DMC1_WORDS message's words while its device work runs
};

}  // namespace gpubridge::daemon
