#pragma once
// A command stream that uses every command kind (shared by the trace tests).
#include "gpubridge/protocol/command_stream.hpp"

namespace gpubridge::protocol::testing {

inline CommandStream sample_stream() {
  CommandStream s;
  s.metadata_json = R"({"created_by":"protocol_tests","device":{"backend":"sim"}})";
  FramesCmd a;
  a.push(write_frame(Reg::FB_FORMAT, (480ull << 16) | 640));
  a.push(write_frame(Reg::CLEAR, 0));
  a.push(write_frame(Reg::VERTEX, 0x00FF'FFFF'0010'0020ull));
  a.push(Frame{false, 0x42, 0xDEAD});            // undefined register: raw in text form
  a.push(write_frame(Reg::VERTEX, 1ull << 60));  // reserved bits: raw in text form
  FramesCmd b;
  b.push(write_frame(Reg::FENCE, 9));
  s.commands.push_back({0, a});
  s.commands.push_back({10, b});  // two adjacent batches must stay two messages
  s.commands.push_back({10, UploadCmd{0x1000, {0, 1, 2, 0xFE, 0xFF}}});
  s.commands.push_back({25, FenceCmd{~0ull}});
  s.commands.push_back({30, ReadRegCmd{index_of(Reg::STATUS)}});
  s.commands.push_back({31, ReadRegCmd{0x55}});
  s.commands.push_back({40, ReadbackCmd{0x2000, 64u << 20}});
  return s;
}

inline void expect_same_commands(const CommandStream& a, const CommandStream& b, bool timestamps) {
  ASSERT_EQ(a.commands.size(), b.commands.size());
  for (std::size_t i = 0; i < a.commands.size(); ++i) {
    EXPECT_EQ(a.commands[i].command, b.commands[i].command) << "command " << i;
    if (timestamps) {
      EXPECT_EQ(a.commands[i].timestamp_ns, b.commands[i].timestamp_ns) << "command " << i;
    }
  }
}

}  // namespace gpubridge::protocol::testing
