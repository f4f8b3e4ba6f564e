// The standalone SOC's UART link: framing, escapes, the receiver model, cut streams, baud
// mismatch on the wire, and a golden stream through framer, wire and receiver into the GPU.
#include <gtest/gtest.h>

#include "gpubridge/dmc1/command.hpp"
#include "gpubridge/dmc1/device.hpp"
#include "gpubridge/dmc1/link.hpp"
#include "gpubridge/dmc1/uart.hpp"
#include "golden_data.hpp"

namespace gpubridge::dmc1 {
namespace {

struct Capture {
  std::vector<std::uint64_t> words;
  std::vector<ScreenCommand> screen;
  SocReceiver receiver{[this](std::uint64_t w) { words.push_back(w); }, [this](const ScreenCommand& c) { screen.push_back(c); }};
};

TEST(UartFramer, SyncThenEightBytesMostSignificantFirst) {
  UartFramer f;
  std::vector<std::uint8_t> out;
  f.command(0x0123456789ABCDEFull, out);
  EXPECT_EQ(out, (std::vector<std::uint8_t>{0x00, 0xAA, 0x01, 0x23, 0x45, 0x67, 0x89, 0xAB, 0xCD, 0xEF}));
}

TEST(SocReceiver, IgnoresBytesBeforeSyncAndDeliversWords) {
  Capture c;
  c.receiver.bytes(std::vector<std::uint8_t>{0x12, 0x00, 0x34, 0xAA, 1, 2, 3, 4, 5, 6, 7, 8, 0xAA, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_TRUE(c.receiver.synced());
  EXPECT_EQ(c.receiver.stats().ignored_before_sync, 3u);
  EXPECT_EQ(c.words, (std::vector<std::uint64_t>{0x0102030405060708ull, 0xAA00000000000000ull}));  // 0xAA is data once synced
  EXPECT_TRUE(c.screen.empty());
}

TEST(SocReceiver, TheFirstZeroWordAfterSyncIsNotAnEscape) {
  Capture c;
  std::vector<std::uint8_t> bytes{0x00, 0xAA};
  for (int w = 0; w < 3; ++w) bytes.insert(bytes.end(), 8, 0);  // zero, zero (escape), zero (screen)
  c.receiver.bytes(bytes);
  EXPECT_EQ(c.receiver.stats().escapes, 1u);
  ASSERT_EQ(c.screen.size(), 1u);
  EXPECT_EQ(c.screen[0], screen_byte(false, 0));  // the ST7789's NOP
  EXPECT_EQ(c.words.size(), 3u);                  // every word also reaches the GPU
}

TEST(SocReceiver, TwoZeroWordsInARowAreNotBothEscapes) {
  Capture c;
  UartFramer f;
  std::vector<std::uint8_t> bytes;
  f.command(end_of_column(), bytes);  // arms the tracker
  for (int w = 0; w < 4; ++w) bytes.insert(bytes.end(), 8, 0);
  c.receiver.bytes(bytes);
  // zero = escape, zero = screen word (NOP), zero = escape, zero = screen word
  EXPECT_EQ(c.receiver.stats().escapes, 2u);
  EXPECT_EQ(c.screen.size(), 2u);
}

TEST(UartFramer, ScreenCommandsReachTheScreenAndCommandsTheGpu) {
  UartFramer f;
  std::vector<std::uint8_t> bytes;
  f.screen(screen_reset(true), bytes);  // right after start: a no-op arms the tracker first
  f.screen(screen_byte(false, 0x11), bytes);
  f.command(wall({0, 239, 15, 0}, 0xFFFF, 0, 0), bytes);
  f.screen(screen_byte(true, 0x55), bytes);
  f.command(end_of_column(), bytes);
  Capture c;
  c.receiver.bytes(bytes);
  EXPECT_EQ(c.screen, (std::vector<ScreenCommand>{screen_reset(true), screen_byte(false, 0x11), screen_byte(true, 0x55)}));
  const std::vector<std::uint64_t> want{UartFramer::kNoOpWord, 0, screen_word(screen_reset(true)),
                                        0, screen_word(screen_byte(false, 0x11)),
                                        wall({0, 239, 15, 0}, 0xFFFF, 0, 0),
                                        0, screen_word(screen_byte(true, 0x55)),
                                        end_of_column()};
  EXPECT_EQ(c.words, want);
  EXPECT_EQ(c.receiver.partial_bytes(), 0u);
}

TEST(UartFramer, AZeroGpuWordIsNotTakenForAnEscape) {
  UartFramer f;
  std::vector<std::uint8_t> bytes;
  f.command(0, bytes);  // first word after sync: cannot be an escape, sent as is
  f.command(0, bytes);  // would be an escape: sent as the same pixel with light 1
  f.command(0, bytes);
  Capture c;
  c.receiver.bytes(bytes);
  EXPECT_EQ(c.receiver.stats().escapes, 0u);
  EXPECT_TRUE(c.screen.empty());
  EXPECT_EQ(c.words, (std::vector<std::uint64_t>{0, UartFramer::kZeroStandIn, UartFramer::kZeroStandIn}));
}

// The stand-in draws exactly what the zero word draws (texture 0 forces light 15).
TEST(UartFramer, TheZeroStandInDrawsLikeTheZeroWord) {
  std::vector<std::uint16_t> screens[2];
  for (int i = 0; i < 2; ++i) {
    auto dev = Device::create({}, test::golden_textures(), test::golden_palette());
    ASSERT_TRUE(dev.ok());
    std::vector<std::uint64_t> words{end_of_column(), i ? UartFramer::kZeroStandIn : 0, end_of_column(), end_of_column()};
    (*dev)->submit(words);
    (*dev)->flush();
    screens[i].assign((*dev)->screen().begin(), (*dev)->screen().end());
  }
  EXPECT_EQ(screens[0], screens[1]);
  EXPECT_NE(screens[0][kRows], 0u);  // the pixel was drawn (row 0 of column 1)
}

TEST(SocReceiver, AStreamCutMidCommandMisalignsTheNextSessionUntilReset) {
  UartFramer f;
  std::vector<std::uint8_t> first;
  f.command(view_z(7), first);
  first.resize(first.size() - 3);  // the host dies 5 bytes into the word
  Capture c;
  c.receiver.bytes(first);
  EXPECT_EQ(c.receiver.partial_bytes(), 5u);
  EXPECT_TRUE(c.words.empty());
  // A new session (monitor_send.py restarted) opens with 0x00 0xAA again, but the SOC is synced:
  // those bytes complete the cut word and everything after is shifted.
  UartFramer again;
  std::vector<std::uint8_t> second;
  again.commands(std::vector<std::uint64_t>{end_of_column(), end_of_column()}, second);
  c.receiver.bytes(second);
  // 5 + 18 bytes: the cut word, one misaligned word, 7 bytes waiting.
  ASSERT_EQ(c.words.size(), 2u);
  EXPECT_EQ(c.words[0] & 0xFFFFFF, 0x00AA00u);
  EXPECT_NE(c.words[1], end_of_column());
  EXPECT_EQ(c.receiver.partial_bytes(), 7u);
  // After the board's reset the same session is read correctly.
  Capture fresh;
  fresh.receiver.bytes(first);
  fresh.receiver.reset();
  fresh.receiver.bytes(second);
  EXPECT_EQ(fresh.words, (std::vector<std::uint64_t>{end_of_column(), end_of_column()}));
}

TEST(UartLine, MatchingBaudRatesDeliverEveryByte) {
  std::vector<std::uint8_t> bytes(2000);
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<std::uint8_t>(i * 37 + (i >> 3));
  LineStats st;
  EXPECT_EQ(uart_transfer(bytes, 115200, 115200, &st), bytes);
  EXPECT_EQ(st.framing_errors, 0u);
  // 4% apart still samples every bit inside its cell; 7% apart does not.
  EXPECT_EQ(uart_transfer(bytes, 115200 * 1.04, 115200), bytes);
  EXPECT_NE(uart_transfer(bytes, 115200 * 1.07, 115200), bytes);
}

TEST(UartLine, ABaudMismatchGarblesAndRaisesFramingErrors) {
  UartFramer f;
  std::vector<std::uint8_t> bytes;
  f.commands(test::golden_stream("edge"), bytes);
  LineStats st;
  const auto got = uart_transfer(bytes, 9600, kStandaloneBaud, &st);  // host at 9,600, SOC at 115,200
  EXPECT_NE(got, bytes);
  EXPECT_GT(st.framing_errors, 0u);
  LineStats fast;
  const auto too_fast = uart_transfer(bytes, 230400, kStandaloneBaud, &fast);
  EXPECT_NE(too_fast, bytes);
  EXPECT_GT(fast.framing_errors + fast.false_starts, 0u);
}

// A golden stream as the host sends it: framed, over the wire at the SOC's baud rate, through the
// receiver into the GPU: the frame is the golden one.
TEST(UartLink, GoldenStreamEndToEnd) {
  for (const char* name : {"mixed", "terrain"}) {
    UartFramer f;
    std::vector<std::uint8_t> bytes;
    f.commands(test::golden_stream(name), bytes);
    const auto wire = uart_transfer(bytes, kStandaloneBaud, kStandaloneBaud);
    auto dev = Device::create({}, test::golden_textures(), test::golden_palette());
    ASSERT_TRUE(dev.ok());
    std::vector<std::uint16_t> frame;
    (*dev)->set_frame_callback([&](const Frame& fr) { frame.assign(fr.rgb565.begin(), fr.rgb565.end()); });
    SocReceiver rx([&](std::uint64_t w) { (*dev)->submit(std::span(&w, 1)); }, nullptr);
    rx.bytes(wire);
    (*dev)->flush();
    EXPECT_EQ(rx.stats().escapes, 0u) << name;
    EXPECT_TRUE(frame == test::golden_pixels(name)) << name;
  }
}

TEST(UartLink, TheRecordedFrameNeedsAboutTwoAndAHalfSecondsAt115200) {
  // frame.nfo: 3,777 commands; the sheet: about 0.38 frames/s.
  EXPECT_NEAR(uart_frames_per_second(3777, kStandaloneBaud), 0.381, 0.001);
}

}  // namespace
}  // namespace gpubridge::dmc1

namespace gpubridge::dmc1 {
namespace {

TEST(LinkModel, At115200TheLinkSetsThePace) {
  const auto words = test::golden_stream("mixed");
  auto e = estimate_link(words, kStandaloneBaud, test::golden_textures());
  ASSERT_TRUE(e.ok()) << e.error().message;
  EXPECT_EQ(e->frames, 1u);
  // 3,699 commands of 80 bits at 115,200 baud: 2.57 s; the GPU needs 43 ms of it.
  EXPECT_NEAR(e->seconds, 3699 * 80.0 / 115200, 0.01);
  EXPECT_LT(e->gpu_busy, 0.05);
  EXPECT_FALSE(e->overflow);
  EXPECT_LE(e->max_fifo, 1u);
}

TEST(LinkModel, AFastLinkFillsTheFifoWithoutFlowControl) {
  const auto words = test::golden_stream("mixed");
  auto fast = estimate_link(words, 20e6, test::golden_textures());
  ASSERT_TRUE(fast.ok());
  EXPECT_TRUE(fast->overflow);
  EXPECT_GT(fast->max_fifo, kStandaloneFifoDepth);
  auto limit = fastest_lossless_baud(words, test::golden_textures());
  ASSERT_TRUE(limit.ok());
  EXPECT_GT(*limit, 115200.0);
  EXPECT_LT(*limit, 20e6);
  auto at = estimate_link(words, *limit, test::golden_textures());
  EXPECT_FALSE(at->overflow);
  auto above = estimate_link(words, *limit * 1.05, test::golden_textures());
  EXPECT_TRUE(above->overflow);
}

}  // namespace
}  // namespace gpubridge::dmc1
