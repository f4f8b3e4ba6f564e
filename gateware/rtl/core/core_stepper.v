// One exact attribute stepper (docs/protocol.md section 9): the attribute's value q (modulo
// 2^QW) and the remainder r in [0, 2D) of its plane numerator, moved by the rasteriser's ops:
//   (q, r) += (qs, rs); if r >= 2D: r -= 2D, q += 1
// with (qs, rs) the plane's step right, left or down. The same integers as
// floor((2N + D) / 2D) at every pixel, with no division per pixel and no drift.
module core_stepper #(
    parameter integer QW = 32,
    parameter integer RW = 35
) (
    input  wire          clk,
    input  wire          load,   // setup writes the plane (value at the box origin and steps)
    input  wire [QW-1:0] q0,
    input  wire [RW-1:0] r0,
    input  wire [QW-1:0] qx,
    input  wire [RW-1:0] rx,
    input  wire [QW-1:0] qxl,
    input  wire [RW-1:0] rxl,
    input  wire [QW-1:0] qy,
    input  wire [RW-1:0] ry,
    input  wire [RW-1:0] den,
    input  wire          en,
    input  wire [1:0]    op,     // 0 none, 1 right, 2 left, 3 down
    output reg  [QW-1:0] q
);
  reg [RW-1:0] r;
  reg [QW-1:0] sxq, sxlq, syq;
  reg [RW-1:0] sxr, sxlr, syr;

  wire [QW-1:0] sq = (op == 2'd1) ? sxq : (op == 2'd2) ? sxlq : syq;
  wire [RW-1:0] sr = (op == 2'd1) ? sxr : (op == 2'd2) ? sxlr : syr;
  wire [RW:0]   t = {1'b0, r} + {1'b0, sr};
  wire [RW+1:0] u = {1'b0, t} - {2'b0, den};
  wire          wrap = !u[RW+1];  // t >= 2D

  always @(posedge clk) begin
    if (load) begin
      q    <= q0;
      r    <= r0;
      sxq  <= qx;
      sxr  <= rx;
      sxlq <= qxl;
      sxlr <= rxl;
      syq  <= qy;
      syr  <= ry;
    end else if (en && op != 2'd0) begin
      q <= q + sq + {{(QW-1){1'b0}}, wrap};
      r <= wrap ? u[RW-1:0] : t[RW-1:0];
    end
  end
endmodule
