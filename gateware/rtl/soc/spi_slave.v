// SPI slave (docs/protocol.md section 2): mode 0, 72-bit frames, MSB first, bursts under one CS,
// aborted frames, the status byte and same-frame register reads on MISO.
//
// SCK, CS and MOSI are asynchronous pins sampled in the core clock domain through two-flip-flop
// synchronisers (no logic runs on SCK). An SCK edge is acted on in the cycle after it reaches the
// second synchroniser stage, 1..2 core clocks after it happened. MOSI goes through the same chain,
// so it is sampled where SCK was first seen high, i.e. within one core clock after the rising edge.
//
// MISO changes on falling SCK edges (section 2.1): combinationally from the cycle the falling edge is
// recognised, so bit k+1 is on the pin 1..2 core clocks (+ output delay) after falling edge k, and
// stays there until 1..2 core clocks after falling edge k+1. Requirements, with Tc the core clock
// period and T the SCK period (docs/gateware.md "Clocking"):
//   - every SCK half period lasts at least one core clock plus the synchroniser's setup window
//     (T/2 > Tc), so no edge is missed and MOSI is stable where it is sampled;
//   - a host sampling MISO on the falling edge (FTDI "read on -ve edge", the board profiles'
//     read_edge "falling") sees bit k+1 when T >= 2 Tc + t_out + t_setup(host);
//   - a host sampling on the rising edge needs T/2 >= 2 Tc + t_out + t_setup(host).
// CS must be asserted at least 2 core clocks before the first rising SCK edge and released at least
// 2 core clocks after the last falling edge (ordering through the synchronisers).
//
// Reads: when bit 64 (the last index bit) is sampled, rd_strobe asks for the register. Live values
// (rd_live) are taken in that cycle; values held in the register file's shadow RAM (rd_from_ram)
// arrive one cycle later on rd_ram. The first data bit is needed at the next falling edge, at least
// one cycle later, so both are in time for any SCK the rules above allow.
module spi_slave (
  input  wire        clk,
  input  wire        rst,
  // pins (asynchronous)
  input  wire        spi_sck,
  input  wire        spi_cs_n,
  input  wire        spi_mosi,
  output wire        spi_miso,
  output wire        spi_miso_oe,
  // status byte shifted out in bits [71:64] (bits 7:6 are the constant marker 10); bits 5:0 are
  // captured at the frame's second falling edge, so they include the previous frame's effects
  input  wire [5:0]  status_flags,
  // register reads
  output wire        rd_strobe,     // one cycle: bit 64 of a read frame sampled
  output wire [6:0]  rd_idx,        // valid with rd_strobe
  input  wire [63:0] rd_live,       // the value of rd_idx in the rd_strobe cycle
  input  wire        rd_from_ram,   // rd_strobe cycle: the value comes on rd_ram in the next cycle
  input  wire [63:0] rd_ram,
  // every complete MOSI byte (for the link CRC), in the clock its last bit is sampled (combinational:
  // no copy of the byte, the link takes it in that clock); byte_first marks byte 0 of a frame
  output wire        byte_valid,
  output wire        byte_first,
  output wire [7:0]  byte_data,
  // complete frames (one-cycle pulse; rw, idx and data are valid in that cycle)
  output reg         frame_valid,
  output wire        frame_rw,
  output wire [6:0]  frame_idx,
  output wire [63:0] frame_data,
  // CS rose after 1..71 bits (one-cycle pulse)
  output reg         frame_abort
);
  // --- synchronisers: [0] may go metastable, [1] is the synchronised level, [2] the previous one
  reg [2:0] sck_s;
  reg [2:0] cs_s;
  reg [1:0] mosi_s;
  always @(posedge clk) begin
    sck_s  <= {sck_s[1:0], spi_sck};
    cs_s   <= {cs_s[1:0], spi_cs_n};
    mosi_s <= {mosi_s[0], spi_mosi};
  end
  wire cs_active = !cs_s[1];
  wire cs_rise   = !cs_s[2] && cs_s[1];
  wire sck_rise  = cs_active && !sck_s[2] && sck_s[1];
  wire sck_fall  = cs_active && sck_s[2] && !sck_s[1];
  wire mosi      = mosi_s[1];

  reg  [6:0]  bit_cnt;    // bits of the current frame received, 0..71
  reg  [63:0] sh;         // header bits while they arrive, then read value out / data in
  reg  [7:0]  hdr;        // {R/W, index} of the current frame
  reg  [5:0]  stat;       // status flags of this frame
  reg         ram_pend;   // the read value arrives on rd_ram this cycle
  reg         miso_q;     // MISO between falling edges
`include "const_compare.vh"

  wire header_done = sck_rise && bit_cnt == 7'd7;
  wire frame_done  = sck_rise && bit_cnt == 7'd71;
  assign rd_strobe = header_done && sh[6];
  assign rd_idx    = {sh[5:0], mosi};
  assign frame_rw   = hdr[7];
  assign frame_idx  = hdr[6:0];
  assign frame_data = sh;
  assign byte_valid = sck_rise && bit_cnt[2:0] == 3'd7;
  assign byte_first = bit_cnt == 7'd7;
  assign byte_data  = {sh[6:0], mosi};

  // The bit launched at this falling edge: bit_cnt bits have been received.
  reg miso_next;
  always @* begin
    if (bit_cnt == 7'd0)      miso_next = 1'b1;                  // MARKER1 of the next frame
    else if (bit_cnt == 7'd1) miso_next = 1'b0;                  // MARKER0
    else if (!ge_const(16'(bit_cnt), 8)) miso_next = stat[3'd7 - bit_cnt[2:0]];
    else if (ram_pend)        miso_next = rd_ram[63];
    else                      miso_next = sh[63];
  end
  assign spi_miso    = sck_fall ? miso_next : miso_q;
  assign spi_miso_oe = !spi_cs_n;   // driven while selected (tri-state control needs no synchroniser)

  always @(posedge clk) begin
    frame_valid <= 1'b0;
    frame_abort <= 1'b0;
    if (rst) begin
      bit_cnt  <= 7'd0;
      ram_pend <= 1'b0;
      miso_q   <= 1'b1;
      stat     <= 6'd0;
      hdr      <= 8'h00;
      sh       <= 64'h0;
    end else begin
      if (!cs_active) begin
        if (cs_rise && bit_cnt != 7'd0) frame_abort <= 1'b1;
        bit_cnt  <= 7'd0;
        miso_q   <= 1'b1;
        ram_pend <= 1'b0;
      end else begin
        if (ram_pend) sh <= rd_ram;
        ram_pend <= 1'b0;
        if (sck_rise) begin
          bit_cnt <= frame_done ? 7'd0 : bit_cnt + 7'd1;
          if (header_done) begin
            hdr      <= {sh[6:0], mosi};
            sh       <= sh[6] ? rd_live : 64'h0;
            ram_pend <= sh[6] && rd_from_ram;
          end else begin
            sh <= {sh[62:0], mosi};
          end
          if (frame_done) frame_valid <= 1'b1;
        end
        if (sck_fall) begin
          miso_q <= miso_next;
          if (bit_cnt == 7'd1) stat <= status_flags;
        end
      end
    end
  end
endmodule
