// CommandStreamWriter: register writes become WRITE_FRAMES commands that each fit one message, and
// uploads keep their place among them.
#include <gtest/gtest.h>

#include "gpubridge/protocol/command_stream.hpp"
#include "gpubridge/protocol/registers.hpp"

namespace gpubridge::protocol {
namespace {

TEST(CommandStreamWriter, SplitsWritesIntoMessageSizedBatchesAndKeepsUploadsInOrder) {
  CommandStream s;
  CommandStreamWriter w(s);
  const std::size_t n = kMaxFramesPerBatch + 3;
  for (std::size_t i = 0; i < n; ++i) w.write(Reg::CLEAR_COLOR, i);
  w.upload(0x100, {1, 2, 3, 4, 5, 6, 7, 8});
  w.write(Reg::CLEAR, 0);
  ASSERT_EQ(s.commands.size(), 3u) << "the last write stays open until flush()";
  w.flush();
  w.flush();  // nothing open: no empty batch
  ASSERT_EQ(s.commands.size(), 4u);
  const auto* first = std::get_if<FramesCmd>(&s.commands[0].command);
  const auto* second = std::get_if<FramesCmd>(&s.commands[1].command);
  const auto* upload = std::get_if<UploadCmd>(&s.commands[2].command);
  const auto* last = std::get_if<FramesCmd>(&s.commands[3].command);
  ASSERT_TRUE(first && second && upload && last);
  EXPECT_EQ(first->bytes.size(), kMaxFramesPerBatch * kFrameBytes);
  EXPECT_EQ(second->bytes.size(), 3 * kFrameBytes);
  EXPECT_EQ(upload->address, 0x100u);
  EXPECT_EQ(last->bytes.size(), kFrameBytes);
  for (const auto& c : s.commands) EXPECT_TRUE(command_problem(c.command).empty());
}

}  // namespace
}  // namespace gpubridge::protocol
