// gateware/boards/ulx3s/tmds_encoder.v (the ULX3S's DVI output) Verilated: every 8-bit value encodes to
// a symbol that decodes back to it (DVI 1.0 section 3.2.3), the running disparity of the sent
// symbols stays bounded for random data and for the constant data that would drift without DC
// balancing (0x00, 0xFF, 0x0F ...), and outside data enable the four control symbols appear.
#include <gtest/gtest.h>

#include <bitset>
#include <cstdint>
#include <random>

#include "Vtmds_encoder.h"

namespace {

int decode(unsigned q) {
  const unsigned d = (q & 0x200) ? ~q & 0xFF : q & 0xFF;
  int out = d & 1;
  for (int i = 1; i < 8; ++i) {
    const unsigned b = ((d >> i) ^ (d >> (i - 1))) & 1;
    out |= int((q & 0x100) ? b : b ^ 1) << i;
  }
  return out;
}

class Encoder {
 public:
  unsigned encode(int data, bool de = true, int c = 0) {
    m_.en = 1;
    m_.de = de;
    m_.d = static_cast<std::uint8_t>(data);
    m_.c = static_cast<std::uint8_t>(c);
    clock();
    // the encoder's second stage takes the pixel one clock later (en low: nothing new enters)
    m_.en = 0;
    clock();
    const unsigned q = m_.q;
    disparity_ += 2 * int(std::bitset<10>(q).count()) - 10;
    return q;
  }
  int disparity() const { return disparity_; }
  void clock() {
    m_.clk = 0;
    m_.eval();
    m_.clk = 1;
    m_.eval();
  }
  void reset_disparity() { disparity_ = 0; }

 private:
  Vtmds_encoder m_;
  int disparity_ = 0;
};

TEST(Tmds, EveryByteDecodesBack) {
  Encoder e;
  for (int pass = 0; pass < 3; ++pass)
    for (int v = 0; v < 256; ++v) ASSERT_EQ(decode(e.encode(v)), v) << "value " << v << " pass " << pass;
}

TEST(Tmds, DisparityStaysBounded) {
  Encoder e;
  std::mt19937 rng(20261126);
  int worst = 0;
  for (int i = 0; i < 200000; ++i) {
    const int v = int(rng() & 0xFF);
    ASSERT_EQ(decode(e.encode(v)), v);
    worst = std::max(worst, std::abs(e.disparity()));
  }
  EXPECT_LE(worst, 20) << "random data";
  for (int v : {0x00, 0xFF, 0x0F, 0xF0, 0x01, 0x7F, 0x80, 0xFE}) {
    e.encode(0, false);  // blanking: the encoder's count restarts (control symbols are balanced)
    e.reset_disparity();
    for (int i = 0; i < 10000; ++i) {
      ASSERT_EQ(decode(e.encode(v)), v);
      ASSERT_LE(std::abs(e.disparity()), 20) << "constant 0x" << std::hex << v << " after " << std::dec << i << " symbols";
    }
  }
}

TEST(Tmds, ControlSymbolsOutsideDataEnable) {
  Encoder e;
  EXPECT_EQ(e.encode(0x12, false, 0), 0b1101010100u);
  EXPECT_EQ(e.encode(0x34, false, 1), 0b0010101011u);
  EXPECT_EQ(e.encode(0x56, false, 2), 0b0101010100u);
  EXPECT_EQ(e.encode(0x78, false, 3), 0b1010101011u);
}

}  // namespace
