// The board path over a real serial port: SerialLink (and `gpubridge render --device dmc1 --board`)
// writing into a pseudo-terminal, the SOC's receiver model reading the other end and feeding the
// DMC-1 simulator: the frame that comes out is the RTL's golden one. A pty takes the same termios
// calls as a USB-UART's tty, so the raw 8N1 set-up is checked too (0x0A bytes must not become
// 0x0D 0x0A, nothing may be echoed back into the stream).
#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <thread>

#include <gtest/gtest.h>

#include "gpubridge/dmc1/device.hpp"
#include "gpubridge/dmc1/serial_link.hpp"
#include "gpubridge/dmc1/uart.hpp"
#include "golden_data.hpp"
#include "pty.hpp"

namespace gpubridge::dmc1 {
namespace {

using test::Pty;

// The SOC's receiver feeding the DMC-1: the frames the board would show.
struct Board {
  std::unique_ptr<Device> gpu;
  std::vector<std::uint16_t> frames;  // every completed frame, back to back
  SocReceiver receiver{[this](std::uint64_t w) { gpu->submit(std::span(&w, 1)); }, nullptr};
  Board() {
    auto d = Device::create({}, test::golden_textures(), test::golden_palette());
    if (!d) throw std::runtime_error(d.error().message);
    gpu = std::move(*d);
    gpu->set_frame_callback([this](const Frame& f) { frames.insert(frames.end(), f.rgb565.begin(), f.rgb565.end()); });
  }
};

TEST(SerialLink, GoldenStreamsThroughAPseudoTerminal) {
  for (const char* name : {"mixed", "edge"}) {
    SCOPED_TRACE(name);
    Pty pty;
    auto link = SerialLink::open(pty.slave_path());
    ASSERT_TRUE(link) << link.error().message;
    // The port as the SOC needs it: 115,200 baud, 8N1, no flow control, no output processing, no echo.
    termios t{};
    ASSERT_EQ(::tcgetattr(pty.slave_fd(), &t), 0);
    EXPECT_EQ(::cfgetospeed(&t), static_cast<speed_t>(B115200));
    EXPECT_EQ(t.c_cflag & CSIZE, static_cast<tcflag_t>(CS8));
    EXPECT_EQ(t.c_cflag & (PARENB | CSTOPB | CRTSCTS), 0u);
    EXPECT_EQ(t.c_oflag & OPOST, 0u);
    EXPECT_EQ(t.c_lflag & (ECHO | ICANON), 0u);

    Board board;
    std::atomic<bool> sent{false};
    const auto words = test::golden_stream(name);
    std::thread host([&] {
      EXPECT_TRUE((*link)->send(words));
      EXPECT_TRUE((*link)->drain());
      sent = true;
    });
    pty.read_until(sent, [&](std::span<const std::uint8_t> b) { board.receiver.bytes(b); });
    host.join();
    board.gpu->flush();
    EXPECT_EQ(board.receiver.stats().words, words.size());
    EXPECT_EQ(board.receiver.stats().escapes, 0u);
    EXPECT_EQ((*link)->stats().bytes, 2 + 8 * words.size());
    EXPECT_EQ((*link)->stats().words, words.size());
    EXPECT_TRUE(board.frames == test::golden_pixels(name));
  }
}

TEST(SerialLink, ACancelStopsAtAWordBoundary) {
  Pty pty;
  auto link = SerialLink::open(pty.slave_path());
  ASSERT_TRUE(link) << link.error().message;
  std::atomic<bool> cancel{false}, done{false};
  (*link)->set_cancel_flag(&cancel);
  Board board;
  // 20 frames (600 KB): more than the kernel's tty buffers hold, so the cancel lands mid-stream.
  std::vector<std::uint64_t> words;
  for (int i = 0; i < 20; ++i) {
    const auto frame = test::golden_stream("mixed");
    words.insert(words.end(), frame.begin(), frame.end());
  }
  Result<void> result;
  std::thread host([&] {
    result = (*link)->send(words);
    done = true;
  });
  std::uint64_t received = 0;
  pty.read_until(done, [&](std::span<const std::uint8_t> b) {
    received += b.size();
    board.receiver.bytes(b);
    if (received > 3000) cancel = true;  // Ctrl-C part-way through
  });
  host.join();
  ASSERT_FALSE(result);
  EXPECT_EQ(result.error().code, kSerialCancelled);
  EXPECT_LT((*link)->stats().words, words.size());
  EXPECT_EQ(received, (*link)->stats().bytes);
  EXPECT_EQ((received - 2) % 8, 0u);                // whole words only
  EXPECT_EQ(board.receiver.partial_bytes(), 0u);     // the SOC holds no half command
  EXPECT_EQ(board.receiver.stats().words, (*link)->stats().words);
}

TEST(SerialLink, OpenErrorsSayWhatToFix) {
  auto missing = SerialLink::open("/dev/ttyUSB-gpubridge-absent");
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().message.find("no such serial port"), std::string::npos) << missing.error().message;
  EXPECT_NE(missing.error().message.find("gpubridge probe"), std::string::npos);
  auto not_a_tty = SerialLink::open("/dev/null");
  ASSERT_FALSE(not_a_tty);
  EXPECT_NE(not_a_tty.error().message.find("not a serial port"), std::string::npos) << not_a_tty.error().message;
  Pty pty;
  auto odd_rate = SerialLink::open(pty.slave_path(), 123457);
  ASSERT_FALSE(odd_rate);
  EXPECT_NE(odd_rate.error().message.find("does not take 123457 baud"), std::string::npos) << odd_rate.error().message;
}

#ifdef GPUBRIDGE_CLI
// The README's board command with the port named (no adapter on a test machine): the bytes that
// `gpubridge render --device dmc1 STREAM --board icebreaker-dmc1 --tty PORT` writes make the SOC
// draw the golden frame; the images it writes are the simulator's (the same frame).
TEST(SerialLink, RenderStreamsToTheBoardThroughItsPort) {
  Pty pty;
  const auto out = std::filesystem::temp_directory_path() / ("dmc1-board-" + std::to_string(::getpid()));
  std::filesystem::create_directories(out);
  const std::string data = test::kDataDir.string();
  const std::string cmd = std::string("\"") + GPUBRIDGE_CLI + "\" render --device dmc1 \"" + data + "/streams/mixed.dmc1\" --textures \"" +
                          data + "/textures.bin.gz\" --palette \"" + data + "/palette.bin\" --raw \"" + (out / "sim.rgb565").string() +
                          "\" --board icebreaker-dmc1 --tty " + pty.slave_path() + " > \"" + (out / "stdout.txt").string() + "\" 2>&1";
  Board board;
  std::atomic<bool> done{false};
  int rc = -1;
  std::thread cli([&] {
    rc = std::system(cmd.c_str());
    done = true;
  });
  pty.read_until(done, [&](std::span<const std::uint8_t> b) { board.receiver.bytes(b); });
  cli.join();
  board.gpu->flush();
  const auto text = test::read_bytes(out / "stdout.txt");
  const std::string printed(text.begin(), text.end());
  EXPECT_EQ(rc, 0) << printed;
  const auto words = test::golden_stream("mixed").size();
  EXPECT_NE(printed.find("sent " + std::to_string(2 + 8 * words) + " bytes (" + std::to_string(words) + " words)"), std::string::npos)
      << printed;
  EXPECT_NE(printed.find("at 115200 baud"), std::string::npos) << printed;
  EXPECT_TRUE(board.frames == test::golden_pixels("mixed"));
  const auto sim = test::read_bytes(out / "sim.rgb565");
  EXPECT_EQ(sim, test::read_bytes(test::kDataDir / "golden" / "mixed.rgb565"));
  std::filesystem::remove_all(out);
}
#endif

}  // namespace
}  // namespace gpubridge::dmc1
