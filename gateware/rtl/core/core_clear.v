// CLEAR and CLEAR_Z (docs/protocol.md section 12): fills the clipping rectangle of a buffer
// with one value, a word per cycle with byte enables at the row ends (packed pixels share
// words; rows of an odd-width RGB565 buffer start mid-word). One cycle per row to start it, and
// 11 at the start for the first row's offset (y0 * pitch, shift-and-add).
module core_clear #(
    parameter integer ADDR_W = 32
) (
    input  wire        clk,
    input  wire        rst,
    input  wire        start,      // pulse; inputs held until busy falls
    input  wire [27:0] base16,     // buffer byte address / 16
    input  wire [1:0]  bpp_log2,   // 0, 1 or 2
    input  wire [31:0] pattern,    // the pixel value replicated over a word
    input  wire [10:0] width,      // FB_FORMAT.WIDTH (the pitch in pixels)
    input  wire [10:0] x0, y0, x1, y1,  // clipping rectangle, non-empty
    output wire        busy,
    output reg         wr_valid,
    input  wire        wr_ready,
    output wire [29:0] wr_addr,
    output wire [31:0] wr_data,
    output wire [3:0]  wr_be
);
`include "core_addr.vh"
  localparam integer WW = BA_W - 1;  // word address bits of a sum that may pass 2^ADDR_W
  reg          run, first, setup;
  reg  [3:0]   mul;          // offset multiply steps left
  reg  [10:0]  rows;         // rows left after this one
  reg  [23:0]  row_off;      // byte offset of the row's first pixel
  reg  [WW-1:0] w_cur, w_last;
  reg  [1:0]   s_lane, e_lane;
  wire [23:0]  pitch = {13'd0, width} << bpp_log2;
  wire         base_hi = (base16 >> (ADDR_W - 4)) != 28'd0;

  assign busy = run;
  assign wr_data = pattern;
  wire [3:0] lo_mask = 4'b1111 >> s_lane;          // lanes >= s_lane
  wire [3:0] hi_mask = 4'b1111 << (2'd3 - e_lane);  // lanes <= e_lane
  wire last_word = (w_cur == w_last);
  assign wr_be   = (first ? lo_mask : 4'b1111) & (last_word ? hi_mask : 4'b1111);
  assign wr_addr = (base_hi || (w_cur >> (ADDR_W - 2)) != 0) ? 30'h3FFFFFFF : 30'(w_cur[ADDR_W-3:0]);

  wire [23:0]   row_bytes = {13'd0, x1 - x0} << bpp_log2;
  wire [BA_W:0] a_row = {{(BA_W + 1 - ADDR_W){1'b0}}, base16[ADDR_W-5:0], 4'd0} + {{(BA_W - 23){1'b0}}, row_off};
  wire [BA_W:0] a_end = a_row + {{(BA_W - 23){1'b0}}, row_bytes} - 1'b1;  // the row's last byte

  always @(posedge clk) begin
    if (rst) begin
      run      <= 1'b0;
      wr_valid <= 1'b0;
      setup    <= 1'b0;
    end else if (start) begin
      run      <= 1'b1;
      setup    <= 1'b0;
      mul      <= 4'd11;
      wr_valid <= 1'b0;
      rows     <= y1 - y0 - 11'd1;
      row_off  <= 24'd0;
    end else if (mul != 4'd0) begin
      // row_off = y0 * pitch + x0 * bpp, most significant bit of y0 first
      row_off <= (row_off << 1) + (y0[mul - 4'd1] ? pitch : 24'd0) +
                 ((mul == 4'd1) ? ({13'd0, x0} << bpp_log2) : 24'd0);
      mul     <= mul - 4'd1;
      setup   <= (mul == 4'd1);
    end else if (setup) begin
      w_cur    <= a_row[BA_W:2];
      w_last   <= a_end[BA_W:2];
      s_lane   <= a_row[1:0];
      e_lane   <= a_end[1:0];
      first    <= 1'b1;
      wr_valid <= 1'b1;
      setup    <= 1'b0;
    end else if (wr_valid && wr_ready) begin
      first <= 1'b0;
      if (!last_word) begin
        w_cur <= w_cur + 1'b1;
      end else if (rows != 11'd0) begin
        rows     <= rows - 11'd1;
        row_off  <= row_off + pitch;
        wr_valid <= 1'b0;
        setup    <= 1'b1;
      end else begin
        wr_valid <= 1'b0;
        run      <= 1'b0;
      end
    end
  end
endmodule
