#pragma once
// One representative message of every type (shared by the message tests).
#include <vector>

#include "gpubridge/protocol/messages.hpp"

namespace gpubridge::protocol::testing {

// Byte storage for the spans inside the sample payloads; lives as long as the samples.
struct Samples {
  std::vector<std::uint8_t> frames, upload, readback, pixels, dmc1;
  std::vector<Message> messages;
};

inline Samples make_samples() {
  Samples s;
  append(s.frames, write_frame(Reg::VERTEX, 0x0000'0123'0040'0050ull));
  append(s.frames, write_frame(Reg::COLOR, 0xFFFF'FFFF'FF00'00FFull));
  s.upload = {1, 2, 3, 4, 5, 0xFF};
  s.readback = {9, 8, 7};
  s.pixels.assign(3 * 2 * 2, 0xA5);  // 3x2 RGB565
  auto& m = s.messages;
  m.push_back({1, Hello{1, "viewer", "secret"}});
  m.push_back({2, Welcome{1, 1u << 20, 77, R"({"backend":"sim","width":640})"}});
  m.push_back({3, ErrorMsg{ErrorCode::NoLease, 41, "no lease: send LEASE_ACQUIRE first"}});
  m.push_back({4, Ping{{1, 2, 3}}});
  m.push_back({5, Pong{{1, 2, 3}}});
  m.push_back({6, Bye{}});
  m.push_back({7, WriteFrames{FrameView{s.frames}}});
  m.push_back({8, ReadReg{0x10}});
  m.push_back({9, RegValue{0x7F, 0x5350'4755'0100'0000ull}});
  m.push_back({10, Upload{0x1000, s.upload}});
  m.push_back({11, UploadAck{0x1000, 6}});
  m.push_back({12, Readback{0x2000, 3}});
  m.push_back({13, ReadbackData{0x2000, true, s.readback}});
  m.push_back({14, FenceMsg{0x0123'4567'89AB'CDEFull}});
  m.push_back({15, FenceDone{0x0123'4567'89AB'CDEFull}});
  m.push_back({16, StatusReq{}});
  m.push_back({17, StatusReply{R"({"fifo":3})"}});
  m.push_back({18, Subscribe{FrameFormat::RGB565, 30}});
  m.push_back({19, Unsubscribe{}});
  m.push_back({20, FrameData{5, 3, 2, PixelFormat::RGB565, 0xDEADBEEF, 123456789, s.pixels}});
  m.push_back({21, LeaseAcquire{LeaseMode::FailIfBusy}});
  m.push_back({22, LeaseGranted{99}});
  m.push_back({23, LeaseRelease{}});
  m.push_back({24, LeaseReleased{}});
  m.push_back({0xFFFFFFFFu, DeviceEvent{R"({"event":"unplugged"})"}});
  m.push_back({25, WriteFramesZ{Codec::Zstd, 18, s.upload}});  // decoding does not inflate
  m.push_back({26, Hello{1, "z", "", codec_bit(Codec::Zstd)}});
  append_dmc1_words(std::vector<std::uint64_t>{0x0000'FFFF'3FBC'0000ull, 0x8000'0000'0000'0000ull}, s.dmc1);
  m.push_back({27, Dmc1Words{s.dmc1}});
  return s;
}

}  // namespace gpubridge::protocol::testing
