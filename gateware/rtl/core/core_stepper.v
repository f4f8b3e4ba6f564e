// One exact attribute stepper (docs/protocol.md section 9): the attribute's value q (modulo
// 2^QW) and the remainder r in [0, 2D) of its plane numerator, moved by the rasteriser's ops:
//   (q, r) += (qs, rs); if r >= 2D: r -= 2D, q += 1
// with (qs, rs) the plane's step right, left or down. The same integers as
// floor((2N + D) / 2D) at every pixel, with no division per pixel and no drift.
// The three steps live in registers, or (EBR = 1, for the iCE40) in a block RAM read one cycle
// ahead with the rasteriser's next op as the address.
module core_stepper #(
    parameter integer QW = 32,
    parameter integer RW = 35,
    parameter integer EBR = 0
) (
    input  wire          clk,
    input  wire          we,       // setup writes a field: 0 value at the origin, 1 right, 2 left, 3 down
    input  wire [1:0]    field,
    input  wire [QW-1:0] wq,
    input  wire [RW-1:0] wr,
    input  wire [RW-1:0] den,
    input  wire          en,
    input  wire [1:0]    op,       // 0 none, 1 right, 2 left, 3 down (the field numbers)
    input  wire [1:0]    op_next,  // the op of the next enabled cycle (EBR read address)
    output reg  [QW-1:0] q
);
  reg  [RW-1:0] r;
  wire [QW-1:0] sq;
  wire [RW-1:0] sr;
  generate
    if (EBR != 0) begin : ebr_steps
      reg [QW+RW-1:0] steps[0:3];
      reg [QW+RW-1:0] rd;
      always @(posedge clk) begin
        if (we && field != 2'd0) steps[field] <= {wq, wr};
        rd <= steps[op_next];
      end
      assign {sq, sr} = rd;
    end else begin : reg_steps
      reg [QW-1:0] sxq, sxlq, syq;
      reg [RW-1:0] sxr, sxlr, syr;
      always @(posedge clk) begin
        if (we) begin
          case (field)
            2'd1: begin sxq <= wq; sxr <= wr; end
            2'd2: begin sxlq <= wq; sxlr <= wr; end
            2'd3: begin syq <= wq; syr <= wr; end
            default: ;
          endcase
        end
      end
      assign sq = (op == 2'd1) ? sxq : (op == 2'd2) ? sxlq : syq;
      wire unused_op_next = &{1'b0, op_next};  // read ahead only by block RAM steps
      assign sr = (op == 2'd1) ? sxr : (op == 2'd2) ? sxlr : syr;
    end
  endgenerate

  // a step left is stored as (~qx, 2D - 1 - rx) and taken with a carry in: (q, r) - (qx, rx)
  wire [RW:0]   t = {1'b0, r} + {1'b0, sr} + {{RW{1'b0}}, op == 2'd2};
  wire [RW+1:0] u = {1'b0, t} - {2'b0, den};
  wire          wrap = !u[RW+1];  // t >= 2D

  always @(posedge clk) begin
    if (we && field == 2'd0) begin
      q <= wq;
      r <= wr;
    end else if (en && op != 2'd0) begin
      q <= q + sq + {{(QW-1){1'b0}}, wrap};
      r <= wrap ? u[RW-1:0] : t[RW-1:0];
    end
  end
endmodule
