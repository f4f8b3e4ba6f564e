// Decides whether a draw must run in serial mode: when a buffer it reads overlaps one it writes
// (colour and depth buffers, or the texture and either), the simulator's pixel order is
// observable and the core must finish each pixel before starting the next and emit rows left to
// right. Whole buffers are compared (W * H pixels), as the simulator does, in 16-byte blocks
// (buffers start on 16-byte boundaries; rounding their ends up can only add false alarms),
// clipped at 2^ADDR_W (accesses beyond it are dropped or read 0 in any order). The inputs are held
// during triangle setup, which takes longer than the two register steps here.
//
// Buffers [a, a + la) and [b, b + lb), each clipped at TOP = 2^ADDR_W / 16, overlap when both start
// below TOP and a - b < lb and b - a < la: one subtractor per pair of buffers and two comparisons
// of its difference with the lengths, instead of the clipped ends (two adders and two clamps per
// buffer) and comparisons of ends with starts. A length of ceil(bytes / 16) blocks is compared as
// 16 (a - b) < bytes, the same for an integer a - b, so no rounding adders: for the colour and
// depth buffers (a - b) << k < W * H with k = 2 (4 bytes a pixel), 3 (2) or 4 (1).
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
  localparam integer SW = ADDR_W - 4;  // block address bits below TOP
  localparam integer LW = 19;          // a texture's length in blocks: up to 2^18
  localparam integer MW = (SW + 4 > 22) ? SW + 4 : 22;  // (a - b) << k against W * H
  localparam integer TW = (SW > LW) ? SW : LW;          // a - b against a texture's length
  reg  [21:0] wh;
  reg         c_in, z_in, t_in;                        // the buffer starts below TOP
  reg  [SW:0] d_cz, d_zc, d_tc, d_ct, d_tz, d_zt;      // differences of starts, SW + 1 bits signed
  wire [2:0]  kc = (fmt == 2'd0) ? 3'd2 : (fmt == 2'd1) ? 3'd3 : 3'd4;  // colour: 16 / bytes a pixel
  wire [1:0]  tbl = (tex_fmt == 2'd0) ? 2'd2 : (tex_fmt == 2'd1) ? 2'd1 : 2'd0;
  wire [4:0]  tl = 5'(tex_wl) + 5'(tex_hl) + 5'(tbl) - 5'd4;  // 2..18
  reg  [LW-1:0] tblocks;
  function below(input [27:0] b16);
    below = (b16 >> SW) == 28'd0;
  endfunction
  // a - b < ceil(W * H * 2^k / 16), d = a - b (both below TOP: d fits SW + 1 bits signed)
  function before_wh(input [SW:0] d, input [2:0] k);
    before_wh = d[SW] || ((MW'(d[SW-1:0]) << k) < MW'(wh));
  endfunction
  // a - b < a texture's length in blocks
  function before_tex(input [SW:0] d);
    before_tex = d[SW] || (TW'(d[SW-1:0]) < TW'(tblocks));
  endfunction
  wire [SW-1:0] c = fb_draw16[SW-1:0], z = fb_z16[SW-1:0], t = tex16[SW-1:0];
  always @(posedge clk) begin
    wh <= 22'(width * height);
    tblocks <= LW'(1) << tl;
    c_in <= below(fb_draw16);
    z_in <= below(fb_z16);
    t_in <= below(tex16);
    d_cz <= {1'b0, c} - {1'b0, z};
    d_zc <= {1'b0, z} - {1'b0, c};
    d_tc <= {1'b0, t} - {1'b0, c};
    d_ct <= {1'b0, c} - {1'b0, t};
    d_tz <= {1'b0, t} - {1'b0, z};
    d_zt <= {1'b0, z} - {1'b0, t};
    serial <= (depth_on && colour_on && c_in && z_in && before_wh(d_cz, 3'd2) && before_wh(d_zc, kc)) ||
              (textured && t_in && c_in && before_wh(d_tc, kc) && before_tex(d_ct)) ||
              (textured && z_write && t_in && z_in && before_wh(d_tz, 3'd2) && before_tex(d_zt));
  end
endmodule
