// Attribute steppers of the small profile (iCE40): the same exact (q, r) stepping as
// core_stepper, for the colour channels and depth, but one datapath shared in time. Each
// attribute's state (q, r) and its three steps live in block RAM; a rasteriser move costs one
// cycle per attribute the draw interpolates (none for flat draws without depth, five for Gouraud
// with depth; two for depth alone, where the state read must follow its own write). Block RAM
// reads are issued a cycle ahead: the next move's first attribute is fetched with the
// rasteriser's next op while the current move finishes. The values after the last move stay in
// output registers for the pixel record.
//
// A value at the origin (setup's field 0) is written to the steps RAM (word {attr, 0}, which no
// move reads) and taken into the state two cycles later by the datapath itself, as a move from a
// state of zero (the state RAM's word 7, never written) by that step: q = 0 + wq, r = 0 + wr, no
// wrap since wr < 2|D|. So the state RAM and the output registers have one write source each
// (the datapath), not a second one for setup's writes (fit9, docs/gateware.md). Setup writes
// only while the rasteriser is idle (op = 0, no move computes) and its next write is a division
// (tens of cycles) later; the draw starts after setup's last write by more than two cycles.
module core_interp_tm #(
    parameter integer RW = 35,
    // quotient bits kept: 24 with depth; without a depth buffer (CAPS2) every attribute is a
    // colour, whose value is the quotient's low 8 bits (carries only move up), so 8 (fit9)
    parameter integer QW = 24
) (
    input  wire          clk,
    input  wire          rst,
    // setup's writes: field 0 value at the origin, 1 right, 2 left, 3 down
    input  wire          we,
    input  wire [2:0]    attr,
    input  wire [1:0]    field,
    input  wire [23:0]   wq,
    input  wire [RW-1:0] wr,
    input  wire [RW-1:0] den,
    input  wire [4:0]    mask,     // attributes this draw interpolates: R G B A Z
    // values that are not interpolated, loaded when the draw starts (the pipeline is idle): a flat
    // draw's colour, a clear's colour or depth (the core keeps no register of its own for them)
    input  wire          ld_rgba,
    input  wire          ld_z,
    input  wire [31:0]   ld_data,
    // the rasteriser's move to apply, and the one after it
    input  wire [1:0]    op,
    input  wire [1:0]    op_next,
    input  wire          pipe_ok,  // the pixel record may change this cycle
    output wire          adv,      // the move is complete: the rasteriser may advance
    output reg  [31:0]   rgba,
    output reg  [23:0]   z
);
  localparam integer SW = QW + RW;

  function [2:0] first_of(input [4:0] m);
    first_of = m[0] ? 3'd0 : m[1] ? 3'd1 : m[2] ? 3'd2 : m[3] ? 3'd3 : m[4] ? 3'd4 : 3'd0;
  endfunction
  function [3:0] next_of(input [4:0] m, input [2:0] a);  // {none, index} of the next after a
    integer i;
    begin
      next_of = 4'b1000;
      for (i = 4; i >= 0; i = i - 1)
        if (m[i] && i > a) next_of = {1'b0, 3'(i)};
    end
  endfunction

  (* ram_style = "block", no_rw_check *) reg [SW-1:0] state[0:7];
  (* ram_style = "block", no_rw_check *) reg [SW-1:0] steps[0:31];
  localparam [2:0] ZERO = 3'd7;  // the state word of zero (attributes are 0-4)
  initial state[ZERO] = {SW{1'b0}};
  reg  [SW-1:0] s_rd, c_rd;  // registered reads for attribute ph and op dop
  reg  [2:0]    ph;
  reg  [1:0]    dop;
  reg           dv;          // s_rd was read after the last write of state[ph]

  wire       any = (mask != 5'd0);
  wire [2:0] first = first_of(mask);
  wire [3:0] nx = next_of(mask, ph);
  wire       last = nx[3];
  wire       busy_op = any && (op != 2'd0);
  wire       move = busy_op && pipe_ok && dv && (dop == op);
  // setup's value at the origin: written to steps[{attr, 0}] (ini1: fetched with the zero state,
  // ini2: computed into state[attr] and the output register)
  reg        ini1, ini2;
  reg  [2:0] ini_attr;
  wire       compute = move || ini2;
  assign adv = pipe_ok && (!busy_op || (compute && last));

  // fetch: the next attribute of this move, or the first of the next move
  wire       to_next = !busy_op || (compute && last);
  wire [2:0] f_attr = ini1 ? ini_attr : to_next ? first : (move ? nx[2:0] : ph);
  wire [1:0] f_op = ini1 ? 2'd0 : to_next ? op_next : op;
  wire [2:0] f_state = ini1 ? ZERO : f_attr;

  // the datapath (a step left is stored as (~qx, 2D - 1 - rx) and taken with a carry in)
  wire [QW-1:0] q = s_rd[SW-1:RW];
  wire [RW-1:0] r = s_rd[RW-1:0];
  wire [RW:0]   t = {1'b0, r} + {1'b0, c_rd[RW-1:0]} + {{RW{1'b0}}, op == 2'd2};
  wire [RW+1:0] u = {1'b0, t} - {2'b0, den};
  wire          wrap = !u[RW+1];
  wire [QW-1:0] q_n = q + c_rd[SW-1:RW] + QW'(wrap);
  wire [RW-1:0] r_n = wrap ? u[RW-1:0] : t[RW-1:0];

  wire sw = we && field == 2'd0;
  always @(posedge clk) begin
    if (compute) state[ph] <= {q_n, r_n};
    s_rd <= state[f_state];
    if (we) steps[{attr, field}] <= {wq[QW-1:0], wr};
    c_rd <= steps[{f_attr, f_op}];
  end

  always @(posedge clk) begin
    if (rst) begin
      ph   <= 3'd0;
      dv   <= 1'b0;
      ini1 <= 1'b0;
      ini2 <= 1'b0;
    end else begin
      ph   <= f_attr;
      dop  <= f_op;
      // a read of the attribute being written this cycle returns its old state
      dv   <= !(compute && f_attr == ph);
      ini1 <= sw;
      ini2 <= ini1;
    end
    if (sw) ini_attr <= attr;
    if (compute) begin
      case (ph)
        3'd0: rgba[31:24] <= q_n[7:0];
        3'd1: rgba[23:16] <= q_n[7:0];
        3'd2: rgba[15:8] <= q_n[7:0];
        3'd3: rgba[7:0] <= q_n[7:0];
        default: z <= 24'(q_n);
      endcase
    end else begin
      if (ld_rgba) rgba <= ld_data;
      if (ld_z) z <= ld_data[23:0];
    end
  end

  wire unused_wq = &{1'b0, wq};  // bits above QW

`ifndef SYNTHESIS
  // what taking setup's value through the datapath relies on, checked in every co-simulation:
  // no move in its two cycles, no second write of setup's in them, wr below 2|D| (no wrap)
  always @(posedge clk) begin
    if (!rst && (ini1 || ini2) && (op != 2'd0 || busy_op)) begin
      $display("core_interp_tm: a move while setup's value at the origin is taken");
      $stop;
    end
    if (!rst && (ini1 || ini2) && we) begin
      $display("core_interp_tm: a setup write while its value at the origin is taken");
      $stop;
    end
    if (!rst && ini2 && wrap) begin
      $display("core_interp_tm: setup's remainder at the origin is not below 2|D|");
      $stop;
    end
  end
`endif
endmodule
