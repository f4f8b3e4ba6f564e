// CLEAR and CLEAR_Z (docs/protocol.md section 12): fills the clipping rectangle of a buffer
// with one value, a word per cycle with byte enables at the row ends (packed pixels share
// words; rows of an odd-width RGB565 buffer start mid-word).
module core_clear (
    input  wire        clk,
    input  wire        rst,
    input  wire        start,      // pulse
    input  wire [27:0] base16,     // buffer byte address / 16
    input  wire [1:0]  bpp_log2,   // 0, 1 or 2
    input  wire [31:0] pattern,    // the pixel value replicated over a word
    input  wire [10:0] width,      // FB_FORMAT.WIDTH (the pitch in pixels)
    input  wire [10:0] x0, y0, x1, y1,  // clipping rectangle, non-empty
    output wire        busy,
    output reg         wr_valid,
    input  wire        wr_ready,
    output wire [29:0] wr_addr,
    output reg  [31:0] wr_data,
    output wire [3:0]  wr_be
);
  reg        run;
  reg [10:0] rows;        // rows left after this one
  reg [32:0] a_end;       // byte address one past the row's last pixel
  reg [30:0] w_cur, w_last;
  reg [1:0]  s_lane, e_lane;  // first lane of the row's first word, last lane of its last word
  reg        first;
  reg [22:0] pitch;       // bytes per row
  reg [32:0] a_row;       // byte address of the row's first pixel
  reg        setup;

  assign busy = run;
  wire [3:0] lo_mask = 4'b1111 >> s_lane;          // lanes >= s_lane
  wire [3:0] hi_mask = 4'b1111 << (2'd3 - e_lane);  // lanes <= e_lane
  wire last_word = (w_cur == w_last);
  assign wr_be   = (first ? lo_mask : 4'b1111) & (last_word ? hi_mask : 4'b1111);
  assign wr_addr = w_cur[30] ? 30'h3FFFFFFF : w_cur[29:0];

  wire [21:0] start_pix = 22'(y0 * width) + {11'd0, x0};
  wire [10:0] cols = x1 - x0;
  wire [32:0] row_bytes = {20'd0, cols, 2'd0} >> (2'd2 - bpp_log2);
  wire [32:0] a_end_n = a_row + row_bytes;

  always @(posedge clk) begin
    if (rst) begin
      run      <= 1'b0;
      wr_valid <= 1'b0;
      setup    <= 1'b0;
    end else if (start) begin
      run      <= 1'b1;
      setup    <= 1'b1;
      wr_valid <= 1'b0;
      wr_data  <= pattern;
      rows     <= y1 - y0 - 11'd1;
      pitch    <= {12'd0, width} << bpp_log2;
      a_row    <= {1'b0, base16, 4'd0} + ({11'd0, start_pix} << bpp_log2);
    end else if (setup) begin
      // start the row at a_row
      a_end    <= a_end_n;
      w_cur    <= a_row[32:2];
      w_last   <= 31'((a_end_n - 33'd1) >> 2);
      s_lane   <= a_row[1:0];
      e_lane   <= 2'(a_end_n - 33'd1);
      first    <= 1'b1;
      wr_valid <= 1'b1;
      setup    <= 1'b0;
    end else if (wr_valid && wr_ready) begin
      first <= 1'b0;
      if (!last_word) begin
        w_cur <= w_cur + 31'd1;
      end else if (rows != 11'd0) begin
        rows     <= rows - 11'd1;
        a_row    <= a_row + {10'd0, pitch};
        wr_valid <= 1'b0;
        setup    <= 1'b1;
      end else begin
        wr_valid <= 1'b0;
        run      <= 1'b0;
      end
    end
  end
endmodule
