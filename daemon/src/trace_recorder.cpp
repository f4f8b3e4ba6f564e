#include "gpubridge/daemon/trace_recorder.hpp"

#include <cctype>

#include <nlohmann/json.hpp>

#include "gpubridge/common/json_text.hpp"
#include "gpubridge/protocol/command_stream.hpp"
#include "gpubridge/protocol/trace.hpp"

namespace gpubridge::daemon {

Result<std::unique_ptr<TraceRecorder>> TraceRecorder::open(const std::filesystem::path& dir, std::uint32_t session,
                                                          const std::string& client_name, protocol::DeviceKind kind) {
  std::string safe = client_name;
  for (char& c : safe)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  const auto path = dir / ("session-" + std::to_string(session) + (safe.empty() ? "" : "-" + safe) + ".gbtrace");
  std::unique_ptr<TraceRecorder> r(new TraceRecorder);
  r->kind_ = kind;
  r->out_.open(path, std::ios::binary | std::ios::trunc);
  std::vector<std::uint8_t> header;
  const std::string meta = json_text(nlohmann::json{{"source", "gpubridged"},
                                                    {"client", client_name},
                                                    {"session", session},
                                                    {"device_kind", protocol::device_kind_info(kind).name}});
  if (!r->out_ || !protocol::append_trace_header(meta, header)) return make_error("cannot record to " + path.string());
  r->out_.write(reinterpret_cast<const char*>(header.data()), static_cast<std::streamsize>(header.size()));
  return r;
}

void TraceRecorder::record(const protocol::Message& m) {
  if (kind_ == protocol::DeviceKind::Dmc1) {
    const auto type = protocol::type_of(m.payload);
    if (type != protocol::MsgType::Dmc1Words && type != protocol::MsgType::Fence) return;
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start_).count();
    std::vector<std::uint8_t> bytes;
    protocol::append_trace_message(static_cast<std::uint64_t>(ns), protocol::Message{static_cast<std::uint32_t>(++records_), m.payload}, bytes);
    out_.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    return;
  }
  auto cmd = protocol::command_from_message(m);
  if (!cmd) return;
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start_).count();
  std::vector<std::uint8_t> bytes;
  if (!protocol::append_trace_record(protocol::TimedCommand{static_cast<std::uint64_t>(ns), std::move(*cmd)}, ++records_,
                                     bytes))
    return;
  out_.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

}  // namespace gpubridge::daemon
