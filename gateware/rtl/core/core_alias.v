// Decides whether a draw must run in serial mode: when a buffer it reads overlaps one it writes
// (colour and depth buffers, or the texture and either), the simulator's pixel order is
// observable and the core must finish each pixel before starting the next and emit rows left to
// right. Whole buffers are compared (W * H pixels), as the simulator does, in 16-byte blocks
// (buffers start on 16-byte boundaries; rounding their ends up can only add false alarms),
// clipped at 2^ADDR_W (accesses beyond it are dropped or read 0 in any order). Registered in
// three steps; the inputs are held during triangle setup, which takes longer.
module core_alias #(
    parameter integer ADDR_W = 32
) (
    input  wire        clk,
    input  wire [27:0] fb_draw16,
    input  wire [27:0] fb_z16,
    input  wire [27:0] tex16,
    input  wire [10:0] width,
    input  wire [10:0] height,
    input  wire [1:0]  fmt,        // colour buffer format
    input  wire [1:0]  tex_fmt,
    input  wire [3:0]  tex_wl,
    input  wire [3:0]  tex_hl,
    input  wire        colour_on,  // colour written
    input  wire        depth_on,   // depth read or written
    input  wire        z_write,
    input  wire        textured,   // texture sampled
    output reg         serial
);
  localparam integer BW = ADDR_W - 2;  // block address bits plus headroom for the end
  localparam [BW-1:0] TOP = {2'b01, {(BW - 2){1'b0}}};  // 2^ADDR_W / 16
  reg  [21:0] wh;
  reg  [BW-1:0] c0, c1, z0, z1, t0, t1;
  // buffer lengths in 16-byte blocks, rounded up
  wire [23:0] cbytes = (fmt == 2'd0) ? {wh, 2'd0} : (fmt == 2'd1) ? {1'd0, wh, 1'd0} : {2'd0, wh};
  wire [17:0] cblocks = 18'((cbytes + 24'd15) >> 4);
  wire [17:0] zblocks = 18'(({wh, 2'd0} + 24'd15) >> 4);
  wire [1:0]  tbl = (tex_fmt == 2'd0) ? 2'd2 : (tex_fmt == 2'd1) ? 2'd1 : 2'd0;
  wire [4:0]  tl = 5'(tex_wl) + 5'(tex_hl) + 5'(tbl) - 5'd4;  // >= 2
  function [BW-1:0] lo(input [27:0] b16);  // start, clipped at 2^ADDR_W
    lo = ((b16 >> (ADDR_W - 4)) != 28'd0) ? TOP : BW'(b16[ADDR_W-5:0]);
  endfunction
  localparam integer EW = ((BW > 18) ? BW : 18) + 1;
  function [BW-1:0] hi(input [BW-1:0] start, input [17:0] len);  // end, clipped
    reg [EW-1:0] e;
    begin
      e = {{(EW - BW){1'b0}}, start} + {{(EW - 18){1'b0}}, len};
      hi = (e > {{(EW - BW){1'b0}}, TOP}) ? TOP : e[BW-1:0];
    end
  endfunction
  function ov(input [BW-1:0] a0, input [BW-1:0] a1, input [BW-1:0] b0, input [BW-1:0] b1);
    ov = (a0 < b1) && (b0 < a1);
  endfunction
  always @(posedge clk) begin
    wh <= 22'(width * height);
    c0 <= lo(fb_draw16);
    c1 <= hi(lo(fb_draw16), cblocks);
    z0 <= lo(fb_z16);
    z1 <= hi(lo(fb_z16), zblocks);
    t0 <= lo(tex16);
    t1 <= hi(lo(tex16), 18'd1 << tl);
    serial <= (depth_on && colour_on && ov(c0, c1, z0, z1)) ||
              (textured && ov(t0, t1, c0, c1)) ||
              (textured && z_write && ov(t0, t1, z0, z1));
  end
endmodule
