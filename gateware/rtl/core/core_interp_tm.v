// Attribute steppers of the small profile (iCE40): the same exact (q, r) stepping as
// core_stepper, for up to eight attributes, but one datapath shared in time. Each attribute's
// state (q, r) and its three steps live in block RAM; a rasteriser move costs one cycle per
// attribute the draw interpolates (none for flat untextured draws, one for depth only, five for
// Gouraud with depth). Block RAM reads are issued a cycle ahead: the next move's first
// attribute is fetched with the rasteriser's next op while the current move finishes. The
// values of the last move stay in output registers for the pixel record.
module core_interp_tm #(
    parameter integer N = 5,     // attributes 0 .. N-1 (R, G, B, A, Z)
    parameter integer QW = 24,   // value bits kept (colour uses the low 8)
    parameter integer RW = 35
) (
    input  wire          clk,
    input  wire          rst,
    // setup's writes: field 0 value at the origin, 1 right, 2 left, 3 down
    input  wire          we,
    input  wire [2:0]    attr,
    input  wire [1:0]    field,
    input  wire [QW-1:0] wq,
    input  wire [RW-1:0] wr,
    input  wire [RW-1:0] den,
    input  wire [N-1:0]  mask,     // attributes this draw interpolates
    // the rasteriser's move to apply, and the one after it
    input  wire [1:0]    op,
    input  wire [1:0]    op_next,
    input  wire          pipe_ok,  // the pixel record may change this cycle
    output wire          adv,      // the move is complete: the rasteriser may advance
    output wire [N*QW-1:0] values  // attribute i in [i*QW +: QW]
);
  localparam integer SW = QW + RW;

  // first attribute of the mask, and the one after attribute a
  function [2:0] first_of(input [N-1:0] m);
    integer i;
    begin
      first_of = 3'd0;
      for (i = N - 1; i >= 0; i = i - 1)
        if (m[i]) first_of = 3'(i);
    end
  endfunction
  function [3:0] next_of(input [N-1:0] m, input [2:0] a);  // {none, index}
    integer i;
    begin
      next_of = 4'b1000;
      for (i = N - 1; i >= 0; i = i - 1)
        if (m[i] && i > a) next_of = {1'b0, 3'(i)};
    end
  endfunction

  (* ram_style = "block" *) reg [SW-1:0] state[0:7];
  (* ram_style = "block" *) reg [SW-1:0] steps[0:31];
  reg  [SW-1:0] s_rd, c_rd;   // registered reads: the attribute computed this cycle
  reg  [2:0]    ph;           // attribute computed this cycle
  reg  [QW-1:0] vals[0:N-1];

  wire       any = (mask != {N{1'b0}});
  wire [2:0] first = first_of(mask);
  wire [3:0] nx = next_of(mask, ph);
  wire       last = nx[3];
  wire       busy_op = any && (op != 2'd0);
  wire       compute = busy_op && pipe_ok;
  assign adv = pipe_ok && (!busy_op || last);

  // fetch: the next attribute of this move, or the first of the next move
  wire       to_next = !busy_op || (compute && last);
  wire [2:0] f_attr = to_next ? first : compute ? nx[2:0] : ph;
  wire [1:0] f_op = to_next ? op_next : op;

  // the datapath
  wire [QW-1:0] q = s_rd[SW-1:RW];
  wire [RW-1:0] r = s_rd[RW-1:0];
  wire [QW-1:0] sq = c_rd[SW-1:RW];
  wire [RW-1:0] sr = c_rd[RW-1:0];
  // a step left is stored as (~qx, 2D - 1 - rx) and taken with a carry in: (q, r) - (qx, rx)
  wire [RW:0]   t = {1'b0, r} + {1'b0, sr} + {{RW{1'b0}}, op == 2'd2};
  wire [RW+1:0] u = {1'b0, t} - {2'b0, den};
  wire          wrap = !u[RW+1];
  wire [QW-1:0] q_n = q + sq + {{(QW-1){1'b0}}, wrap};
  wire [RW-1:0] r_n = wrap ? u[RW-1:0] : t[RW-1:0];

  // the state write of this cycle and a read of the same attribute: forward the written value
  reg          fwd;
  reg [SW-1:0] fwd_data;
  wire [SW-1:0] s_data = fwd ? fwd_data : s_mem_rd;
  reg  [SW-1:0] s_mem_rd;

  always @(posedge clk) begin
    // state RAM: setup's field-0 writes, or the computed attribute
    if (we && field == 2'd0) state[attr] <= {wq, wr};
    else if (compute) state[ph] <= {q_n, r_n};
    s_mem_rd <= state[f_attr];
    if (we && field != 2'd0) steps[{attr, field}] <= {wq, wr};
    c_rd <= steps[{f_attr, f_op}];
  end

  always @(posedge clk) begin
    if (rst) begin
      ph  <= 3'd0;
      fwd <= 1'b0;
    end else begin
      fwd      <= compute && (f_attr == ph);
      fwd_data <= {q_n, r_n};
      ph       <= f_attr;
      if (compute) vals[ph] <= q_n;
      if (we && field == 2'd0 && attr < 3'(N)) vals[attr] <= wq;
    end
  end
  always @(*) s_rd = s_data;

  genvar i;
  generate
    for (i = 0; i < N; i = i + 1) begin : out
      assign values[i*QW +: QW] = vals[i];
    end
  endgenerate
endmodule
