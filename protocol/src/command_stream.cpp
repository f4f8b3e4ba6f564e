// Commands <-> socket messages, and the limits a command must respect to fit one message.
#include "gpubridge/protocol/command_stream.hpp"

#include <algorithm>

namespace gpubridge::protocol {
namespace {
template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;
}  // namespace

Message to_message(const Command& c, std::uint32_t request_id) {
  Message m;
  m.request_id = request_id;
  m.payload = std::visit(Overloaded{
                             [](const FramesCmd& f) -> Payload { return WriteFrames{f.view()}; },
                             [](const UploadCmd& u) -> Payload { return Upload{u.address, u.data}; },
                             [](const FenceCmd& f) -> Payload { return FenceMsg{f.id}; },
                             [](const ReadRegCmd& r) -> Payload { return ReadReg{r.index}; },
                             [](const ReadbackCmd& r) -> Payload { return Readback{r.address, r.length}; },
                         },
                         c);
  return m;
}

std::optional<Command> command_from_message(const Message& m) {
  return std::visit(Overloaded{
                        [](const WriteFrames& w) -> std::optional<Command> {
                          return FramesCmd{{w.frames.bytes.begin(), w.frames.bytes.end()}};
                        },
                        [](const Upload& u) -> std::optional<Command> {
                          return UploadCmd{u.address, {u.data.begin(), u.data.end()}};
                        },
                        [](const FenceMsg& f) -> std::optional<Command> { return FenceCmd{f.id}; },
                        [](const ReadReg& r) -> std::optional<Command> { return ReadRegCmd{r.index}; },
                        [](const Readback& r) -> std::optional<Command> { return ReadbackCmd{r.address, r.length}; },
                        [](const auto&) -> std::optional<Command> { return std::nullopt; },
                    },
                    m.payload);
}

MsgType message_type_of(const Command& c) {
  return std::visit(Overloaded{
                        [](const FramesCmd&) { return MsgType::WriteFrames; },
                        [](const UploadCmd&) { return MsgType::Upload; },
                        [](const FenceCmd&) { return MsgType::Fence; },
                        [](const ReadRegCmd&) { return MsgType::ReadReg; },
                        [](const ReadbackCmd&) { return MsgType::Readback; },
                    },
                    c);
}

std::string command_problem(const Command& c) {
  return std::visit(
      Overloaded{
          [](const FramesCmd& f) -> std::string {
            if (f.bytes.empty()) return "frame batch is empty; a WRITE_FRAMES carries at least one frame";
            if (f.bytes.size() % kFrameBytes != 0)
              return "frame batch of " + std::to_string(f.bytes.size()) + " bytes is not a multiple of 9";
            if (f.size() > kMaxFramesPerBatch)
              return "frame batch of " + std::to_string(f.size()) + " frames exceeds " +
                     std::to_string(kMaxFramesPerBatch) + "; split it";
            if (const std::size_t i = first_read_frame(FrameView{f.bytes}); i < f.size())
              return "frame " + std::to_string(i) + " has the read bit set; use a register read";
            return {};
          },
          [](const UploadCmd& u) -> std::string {
            if (u.data.empty()) return "UPLOAD of 0 bytes; an upload carries at least 1 byte";
            if (u.data.size() > kMaxUploadBytes)
              return "UPLOAD of " + std::to_string(u.data.size()) + " bytes exceeds " + std::to_string(kMaxUploadBytes) +
                     "; split it";
            return {};
          },
          [](const FenceCmd&) -> std::string { return {}; },
          [](const ReadRegCmd& r) -> std::string {
            if (r.index >= kRegisterCount) return "register index " + std::to_string(r.index) + " exceeds 127";
            return {};
          },
          [](const ReadbackCmd& r) -> std::string {
            if (r.length == 0 || r.length > kMaxReadbackBytes)
              return "READBACK length " + std::to_string(r.length) + " is outside 1.." + std::to_string(kMaxReadbackBytes);
            return {};
          },
      },
      c);
}

void CommandStreamWriter::upload(std::uint32_t address, std::vector<std::uint8_t> data) {
  flush();
  s_.commands.push_back({0, UploadCmd{address, std::move(data)}});
}

void CommandStreamWriter::flush() {
  for (std::size_t i = 0; i < frames_.size(); i += kMaxFramesPerBatch) {
    FramesCmd cmd;
    const std::size_t end = std::min(frames_.size(), i + kMaxFramesPerBatch);
    cmd.bytes.reserve((end - i) * kFrameBytes);
    for (std::size_t k = i; k < end; ++k) cmd.push(frames_[k]);
    s_.commands.push_back({0, std::move(cmd)});
  }
  frames_.clear();
}

}  // namespace gpubridge::protocol
