// Triangle setup of the large profile (docs/protocol.md sections 8 and 9): a sequencer around one
// accumulator with one adder, a dual multiply-accumulate and the exact dividers. The small
// profile's setup is core_setup_tm (the same integers, operands in block RAM).
//
// Everything is computed in kick order. Section 8.1 exchanges P1 and P2 when D < 0; the three
// edges of the exchanged triangle are the kick-order edges reversed, so the exchange is done by
// negation instead of by moving vertices: the rasteriser steps the edge values with the opposite
// sign (`flip`), the edge values and the plane steps are computed negated, the top-left biases
// are taken on the reversed edges, and 2D is |2D|. The planes' numerator at the origin,
//   M0 = 2(d1*E20 + d2*E01) + D   (d = a - a0, E raw edge values, section 9)
// is then, in both cases, 2(d1*e1 + d2*e2) + (d1 if e1's bias is -1) + (d2 if e2's) + |D| with
// the biased edge values e1, e2 the rasteriser holds; the steps are -32(d1*dy20 + d2*dy01) per
// pixel right and 32(d1*dx20 + d2*dx01) per pixel down, negated with the exchange.
//   1. edge deltas (dx, dy of 1->2, 2->0, 0->1), D = dx20*dy01 - dx01*dy20; D = 0 draws nothing;
//   2. rows of the sample points inside the vertices, clipped; columns: the clip rectangle's, the
//      walk starting below the top vertex; the index y0 * width + x_start of the first pixel;
//   3. each edge value at the first pixel's sample point: dx*(sy - Ya) - dy*(sx - Xa), biased;
//   4. per interpolated attribute: the three numerators divided by 2D into (quotient,
//      remainder) plane fields; the step left is written as (~qx, 2D - 1 - rx), which the steppers
//      add with a carry in. A clear (rect) sets up only the clip rectangle and its first index.
// Multiplies are a1*m1 +/- a2*m2, both products at once, over three registered clocks (operands,
// products, sum). A multiply overlaps the previous
// division. The vertex inputs are read while the command waits on
// the port (held stable by the soc).
module core_setup #(
    parameter integer TEX = 1,       // S, T, Q planes exist (33-bit deltas)
    parameter integer IDX_W = 20,
    parameter integer SKIP = 1,      // divider skips leading zero quotient bits (faster, larger)
    parameter integer XREJECT = 1,   // drop triangles wholly left or right of the clip rectangle
    parameter integer NDIV = 1       // dividers: 1, or 3 (one per numerator of a plane)
) (
    input  wire         clk,
    input  wire         rst,
    input  wire         start,        // pulse: a triangle (or a clear) waits on the command port
    input  wire         rect,         // a clear: the clip rectangle only
    output wire         busy,
    output reg          done,         // pulse: results valid; `draw` says whether to rasterise
    output reg          draw,
    input  wire [183:0] v0,
    input  wire [183:0] v1,
    input  wire [183:0] v2,
    input  wire [10:0]  clip_x0,
    input  wire [10:0]  clip_y0,
    input  wire [10:0]  clip_x1,   // exclusive, already min(SCISSOR.X1, WIDTH)
    input  wire [10:0]  clip_y1,
    input  wire [10:0]  width,     // FB_FORMAT.WIDTH
    input  wire [7:0]   need,         // planes to set up: R G B A Z S T Q (bit 0 = R)
    // held for the rasteriser: kick-order edges 1->2, 2->0, 0->1 and the exchange
    output reg  signed [16:0] dx0, dx1, dx2, dy0, dy1, dy2,
    output reg          flip,
    // biased edge values at the first pixel's sample point, written into the rasteriser's
    // registers (which keep them until the walk starts; e1 and e2 come back for the planes)
    output reg  [2:0]   e_we,
    output wire signed [35:0] e_data,
    input  wire signed [35:0] e1,
    input  wire signed [35:0] e2,
    output reg  [10:0]  box_x0, box_y0, box_xl, box_y1, x_start,  // walk: clip columns, rows
    output reg  [IDX_W-1:0] origin_idx,
    output reg  [34:0]  den,          // |2D|
    // plane writes: field 0 value at the origin, 1 step right, 2 step left, 3 step down
    output reg          pw_en,
    output reg  [2:0]   pw_attr,
    output reg  [1:0]   pw_field,
    output wire [31:0]  pw_q,
    output wire [34:0]  pw_r
);
  localparam integer AW = (TEX != 0) ? 33 : 25;     // attribute delta bits
  // accumulator / numerator bits. Without S, T, Q the widest value is M0 = 2(d1 e1 + d2 e2) +
  // 2 d1 + 2 d2 + |D| with |d| < 2^24 (Z), |e| < 2^33 (see mop), |D| < 2^33: |M0| < 2^60, so 61
  // bits; the steps are below 2^47. With them |d| < 2^33 and N needs 70 bits (section 9).
  localparam integer ACC_W = (TEX != 0) ? 72 : 61;

  // ---------------------------------------------------------------- vertices (kick order)
  // Copied when a triangle starts (S_DELTA takes the edges a clock later): the command port's
  // words come through the soc's command FIFO and executor, which leave no time in the same
  // clock for the arithmetic behind them (the ULX3S clock, docs/gateware.md "Clock estimate").
  reg  [183:0] r_v0, r_v1, r_v2;
  reg  [10:0]  r_clip_x0, r_clip_y0, r_clip_x1, r_clip_y1, r_width;
  wire signed [15:0] x0 = r_v0[15:0], y0 = r_v0[31:16];
  wire signed [15:0] x1 = r_v1[15:0], y1 = r_v1[31:16];
  wire signed [15:0] x2 = r_v2[15:0], y2 = r_v2[31:16];
  function signed [16:0] sub16(input signed [15:0] b, input signed [15:0] a);
    sub16 = $signed({b[15], b}) - $signed({a[15], a});
  endfunction
  // top-left rule on the edge as drawn (reversed when exchanged): bias 0, otherwise -1
  function tl(input signed [16:0] dx, input signed [16:0] dy, input f);
    tl = f ? ((dy == 0 && dx < 0) || dy > 0) : ((dy == 0 && dx > 0) || dy < 0);
  endfunction
  wire tl0 = tl(dx0, dy0, flip), tl1 = tl(dx1, dy1, flip), tl2 = tl(dx2, dy2, flip);

  // ---------------------------------------------------------------- rows and first column
  function signed [15:0] pick3(input [1:0] k, input signed [15:0] a, input signed [15:0] b,
                               input signed [15:0] c);
    pick3 = (k == 2'd0) ? a : (k == 2'd1) ? b : c;
  endfunction
  // index of the smallest / largest of (p0, p1, p2) given d10 = p1 - p0, d21 = p2 - p1, d02 = p0 - p2
  function [1:0] argmin(input signed [16:0] d10, input signed [16:0] d21, input signed [16:0] d02);
    argmin = (d10 >= 0 && d02 <= 0) ? 2'd0 : (d10 < 0 && d21 >= 0) ? 2'd1 : 2'd2;
  endfunction
  function [1:0] argmax(input signed [16:0] d10, input signed [16:0] d21, input signed [16:0] d02);
    argmax = (d10 <= 0 && d02 >= 0) ? 2'd0 : (d10 > 0 && d21 <= 0) ? 2'd1 : 2'd2;
  endfunction
  // One vertex multiplexer (xa, ya) serves the box (S_BOX: the top vertex) and the edge values
  // (the edge's start vertex), selected by `pv`.
  reg  [1:0] pv;
  wire signed [15:0] xa = pick3(pv, x0, x1, x2);
  wire signed [15:0] ya = pick3(pv, y0, y1, y2);
  // samples 16p + 8 inside [min, max]: p from (min + 7) >> 4 to (max + 8) >> 4, exclusive
  wire signed [12:0] fy = 13'(($signed({ya[15], ya}) + 17'sd7) >>> 4);
  reg  signed [12:0] xt;  // the top vertex's first column (S_BOX)
  wire signed [12:0] cx0 = $signed({2'b0, r_clip_x0}), cx1 = $signed({2'b0, r_clip_x1});
  wire signed [12:0] cy0 = $signed({2'b0, r_clip_y0}), cy1 = $signed({2'b0, r_clip_y1});
  // The rows to walk, registered in S_BOX: the top vertex's first row through `pv` (the top
  // vertex there), the bottom vertex's last through a multiplexer of its own (argmax of the
  // edges, there since S_DELTA), so S_BOX2's decision starts at registers. It took the bottom
  // vertex through `pv`, the adder and the clamp before the decision and the box registers'
  // enables (`ek` / `pv` -> `raster.box_y0`, 18.5 ns by the ULX3S clock estimate, docs/gateware.md
  // "The texture cache's fill target"). No clock added.
  wire signed [15:0] yb = pick3(argmax(dy2, dy0, dy1), y0, y1, y2);
  wire signed [12:0] fyb = 13'(($signed({yb[15], yb}) + 17'sd8) >>> 4);
  reg  signed [12:0] by0, by1;
  // Columns: with XREJECT a triangle wholly beside the clip rectangle is dropped here; without
  // (the small profile) it costs its empty rows, about two cycles each, and its setup.
  wire x_out;
  generate
    if (XREJECT != 0) begin : columns
      wire signed [15:0] mnx = pick3(argmin(dx2, dx0, dx1), x0, x1, x2);
      wire signed [15:0] mxx = pick3(argmax(dx2, dx0, dx1), x0, x1, x2);
      wire signed [12:0] fx0 = 13'(($signed({mnx[15], mnx}) + 17'sd7) >>> 4);
      wire signed [12:0] fx1 = 13'((($signed({mxx[15], mxx}) + 17'sd8) >>> 4));
      assign x_out = (fx0 >= cx1) || (fx1 <= cx0);
    end else begin : no_columns
      assign x_out = 1'b0;
    end
  endgenerate
  // x_out is registered in S_BOX (its operands are the edges and vertices, there since S_AREA), so
  // S_BOX2's decision does not carry the column arithmetic too (the ULX3S clock)
  reg  x_out_r;
  wire box_empty = (by0 >= by1) || x_out_r;
  // box_xl (the last column, clip_x1 - 1, loaded at the start) is the clamp's upper bound too
  wire [10:0] xs = (xt < cx0) ? r_clip_x0 : (xt > $signed({2'b0, box_xl})) ? box_xl : xt[10:0];

  // ---------------------------------------------------------------- attribute deltas
  function [AW-1:0] attr(input [151:0] v, input [2:0] k);  // v: vertex bits [183:32]
    case (k)
      3'd0: attr = AW'({1'b0, v[55:48]});
      3'd1: attr = AW'({1'b0, v[47:40]});
      3'd2: attr = AW'({1'b0, v[39:32]});
      3'd3: attr = AW'({1'b0, v[31:24]});
      3'd4: attr = AW'({1'b0, v[23:0]});
      3'd5: attr = AW'({v[119], v[119:88]});
      3'd6: attr = AW'({v[151], v[151:120]});
      default: attr = AW'({1'b0, v[87:56]});
    endcase
  endfunction
  reg  [2:0] ak;  // attribute being set up
  wire [2:0] akv = (TEX != 0 || ak < 3'd5) ? ak : 3'd4;
  wire signed [AW-1:0] a0 = attr(r_v0[183:32], akv);
  wire signed [AW-1:0] d1c = attr(r_v1[183:32], akv) - a0, d2c = attr(r_v2[183:32], akv) - a0;  // |d| < 2^(AW-1)
  // registered (a clock after `ak` moves: S_ANEXT is at least two clocks before their first use)
  // so that the vertex multiplexer and the subtraction end here, not in the multiply's operands
  reg  signed [AW-1:0] d1, d2;
  always @(posedge clk) begin
    d1 <= d1c;
    d2 <= d2c;
  end

  // ---------------------------------------------------------------- operands
  localparam [3:0] O_DX0 = 4'd0, O_DY0 = 4'd1, O_DX1 = 4'd2, O_DY1 = 4'd3, O_DX2 = 4'd4,
                   O_DY2 = 4'd5, O_W = 4'd6, O_XS = 4'd7, O_E1 = 4'd8, O_E2 = 4'd9, O_D1 = 4'd10,
                   O_D2 = 4'd11, O_D = 4'd12, O_ONE = 4'd13;
  // Two m operand buses: `osel` (the first product's) and `osel2` (the second product's), so that
  // a multiply registers all its operands in one clock (a single addition's operand is `aop`).
  reg  [3:0] osel;
  reg        sh5;   // the delta operands times 32
  function signed [35:0] moper(input [3:0] k, input s5, input signed [35:0] ea, input signed [35:0] eb,
                               input signed [AW-1:0] da, input signed [AW-1:0] db);
    reg signed [16:0] n;
    begin
      case (k)
        O_DX0: n = dx0;  O_DY0: n = dy0;
        O_DX1: n = dx1;  O_DY1: n = dy1;
        O_DX2: n = dx2;  O_DY2: n = dy2;
        O_W:   n = {6'd0, r_width};
        O_XS:  n = {6'd0, x_start};
        default: n = 17'sd1;
      endcase
      moper = (k == O_E1) ? ea : (k == O_E2) ? eb : (k == O_D1) ? 36'(da) : (k == O_D2) ? 36'(db) :
              (k == O_D) ? {2'b0, den[34:1]} : s5 ? (36'(n) <<< 5) : 36'(n);
    end
  endfunction
  wire signed [35:0] mop = moper(osel, sh5, e1, e2, d1, d2);
  wire signed [35:0] mop2 = moper(osel2, sh5, e1, e2, d1, d2);

  // a operands (multiplier bits), by `asel`
  localparam [1:0] A_AREA = 2'd0, A_ORIGIN = 2'd1, A_EDGE = 2'd2, A_ATTR = 2'd3;
  reg  [1:0] asel;
  wire signed [17:0] sx = $signed({3'b0, x_start, 4'b1000});  // 16x + 8
  wire signed [17:0] sy = $signed({3'b0, box_y0, 4'b1000});
  reg  [1:0] ek;    // edge being evaluated (its start vertex, pv, is ek + 1 modulo 3)
  wire signed [17:0] ey_a = sy - 18'(ya), ex_a = sx - 18'(xa);  // sample point minus Pa
  reg signed [32:0] ma1, ma2;
  always @(*) begin
    case (asel)
      A_AREA:   begin ma1 = 33'(dx1); ma2 = 33'(dx2); end      // dx20*dy01 - dx01*dy20
      A_ORIGIN: begin ma1 = {22'd0, box_y0}; ma2 = 33'd1; end  // y0*width + x_start
      A_EDGE:   begin ma1 = 33'(ey_a); ma2 = 33'(ex_a); end
      default:  begin ma1 = 33'(d1); ma2 = 33'(d2); end
    endcase
  end

  // ---------------------------------------------------------------- accumulator
  // acc <- (dbl ? 2 acc : acc) +/- mop
  reg [ACC_W-1:0] acc;
  wire signed [ACC_W-1:0] acc_s = $signed(acc);
  assign e_data = acc_s[35:0];
  reg        c_dbl, c_neg, c_en;  // this cycle's accumulator operation
  // A single addition's operand, complemented when it subtracts, is registered by the sequencer
  // as it asks for the addition (its sources, d1, d2, den and 1, hold from there to the addition),
  // so the addition starts at a register: through the operand multiplexer (`moper`, shared with
  // the multiply's operands) it was the ULX3S clock estimate's worst cone (`add_osel` -> `acc`,
  // 18.7 ns, docs/gateware.md "The texture cache's fill target").
  reg  [ACC_W-1:0] aop;
  wire [ACC_W-1:0] acc_sum = (c_dbl ? acc << 1 : acc) + aop + {{(ACC_W-1){1'b0}}, c_neg};

  // multiply: osel1/osel2 sources, negate (mneg), subtract the second (msub)
  reg  [3:0] osel1, osel2;
  reg        mneg, msub;
  reg        mac_go;     // pulse
  reg        mac_run, ph;
  // single additions requested by the sequencer
  reg        add_go, add_dbl, add_neg;
  wire signed [35:0] aop_b = moper(O_ONE, sh5, e1, e2, d1, d2);   // S_BIAS's

  // A multiply in three clocks, each ending in registers (the ULX3S clock, docs/gateware.md
  // "Clock estimate"): the mac_go clock takes the operands (the sequencer set their selects with
  // mac_go), ph 0 the two products (MULT18X18D and the adders of their partial products), ph 1
  // their sum, negated when asked, into the accumulator.
  reg signed [32:0] ma1_r, ma2_r;
  reg signed [35:0] m1, m2;
  reg signed [ACC_W-1:0] p1, p2;   // |a| < 2^(AW-1), |m| < 2^35
  wire signed [ACC_W-1:0] s12 = p1 + (msub ? -p2 : p2);
  always @(*) begin
    osel  = osel1;
    c_en  = add_go && !mac_run;
    c_dbl = add_dbl;
    c_neg = add_neg;
  end
  always @(posedge clk) begin
    if (rst) begin
      mac_run <= 1'b0;
    end else if (mac_go) begin
      mac_run <= 1'b1;
      ph      <= 1'b0;
      m1      <= mop;
      m2      <= mop2;
      ma1_r   <= ma1;
      ma2_r   <= ma2;
    end else if (mac_run) begin
      if (!ph) begin
        p1 <= ACC_W'(ma1_r) * ACC_W'(m1);
        p2 <= ACC_W'(ma2_r) * ACC_W'(m2);
        ph <= 1'b1;
      end else begin
        acc     <= mneg ? -s12 : s12;
        mac_run <= 1'b0;
      end
    end else if (c_en) begin
      acc <= acc_sum;
    end
  end
  wire mac_busy = mac_run || mac_go;

  // ---------------------------------------------------------------- dividers
  // NDIV = 1: one divider takes a plane's three numerators in turn; NDIV = 3: one per numerator
  // (step right, step down, value at the origin), so a plane's divisions overlap each other and
  // the next plane's multiplies. A finished division is written to the steppers through the one
  // plane-write port (the step right followed by the step left) before its divider starts again.
  localparam integer ND = (NDIV >= 3) ? 3 : 1;
  localparam integer SW = (ND == 1) ? 1 : 2;  // divider index bits
  reg  [ND-1:0]    dv_go;
  wire [ND-1:0]    dv_done;
  wire [ND*32-1:0] dv_q;
  wire [ND*35-1:0] dv_r, dv_rc;
  wire [ND-1:0]    dv_neg;           // its remainders exchanged (core_divider)
  reg  [ND-1:0]    dv_pend;          // running, or its results not yet written
  reg  [ND-1:0]    dv_rdy;           // finished, not yet written
  reg  [ND*2-1:0]  dv_field;         // the plane field it produces
  reg  [ND*3-1:0]  dv_attr;
  reg  [ND*32-1:0] dv_a0;
  genvar gd;
  generate
    for (gd = 0; gd < ND; gd = gd + 1) begin : dividers
      /* verilator lint_off PINCONNECTEMPTY */
      core_divider #(.NW(ACC_W), .DW(35), .QW(32), .SKIP(SKIP)) divider (
          .clk(clk), .rst(rst), .start(dv_go[gd]), .num(acc_s), .narrow(1'b0), .den(den), .comp(1'b0), .busy(), .done(dv_done[gd]),
          .quo(dv_q[gd*32 +: 32]), .rem(dv_r[gd*35 +: 35]), .rem_c(dv_rc[gd*35 +: 35]),
          .neg(dv_neg[gd]));
      /* verilator lint_on PINCONNECTEMPTY */
    end
  endgenerate
  // the divider a field's numerator goes to, and whether it can take it now
  function integer div_of(input [1:0] field);
    div_of = (ND == 1) ? 0 : (field == 2'd1) ? 0 : (field == 2'd3) ? 1 : ND - 1;
  endfunction
  wire free_x = !dv_pend[div_of(2'd1)] && !dv_go[div_of(2'd1)];
  wire free_y = !dv_pend[div_of(2'd3)] && !dv_go[div_of(2'd3)];
  wire free_0 = !dv_pend[div_of(2'd0)] && !dv_go[div_of(2'd0)];
  wire all_free = (dv_pend == {ND{1'b0}}) && (dv_go == {ND{1'b0}});

  // plane writes come from a divider's held results
  reg  [SW-1:0] wsel;  // the divider being written
  reg        xl_next;  // the step left follows the step right's write
  wire [31:0] w_q  = dv_q[wsel*32 +: 32];
  wire [31:0] w_a0 = dv_a0[wsel*32 +: 32];
  assign pw_q = (pw_field == 2'd0) ? w_a0 + w_q : (pw_field == 2'd2) ? ~w_q : w_q;
  assign pw_r = ((pw_field == 2'd2) ^ dv_neg[wsel]) ? dv_rc[wsel*35 +: 35] : dv_r[wsel*35 +: 35];
  // the lowest finished divider
  reg [SW-1:0] rdy_sel;
  integer gi;
  always @(*) begin
    rdy_sel = {SW{1'b0}};
    for (gi = ND - 1; gi >= 0; gi = gi - 1)
      if (dv_rdy[gi]) rdy_sel = SW'(gi);
  end

  // ---------------------------------------------------------------- sequencer
  localparam [4:0] S_IDLE = 5'd0, S_AREA = 5'd1, S_FLIP = 5'd2, S_BOX = 5'd3, S_ORIGIN = 5'd4,
                   S_EDGE = 5'd5, S_BIAS = 5'd6, S_ANEXT = 5'd7, S_GX = 5'd8, S_GY = 5'd9,
                   S_M0 = 5'd10, S_M0_C = 5'd11, S_M0_D = 5'd12, S_DRAIN = 5'd13, S_END = 5'd14,
                   S_WAIT = 5'd15, S_GX_W = 5'd16, S_BOX2 = 5'd17, S_DELTA = 5'd18;
  reg [4:0]  st, ret;   // S_WAIT: until the multiply is done, then ret
  reg [1:0]  cstep;     // M0 corrections
  wire signed [35:0] aop_c = moper((cstep == 2'd1) ? O_D1 : (cstep == 2'd2) ? O_D2 : O_D, sh5, e1, e2, d1, d2);  // S_M0_C's
  reg [7:0]  todo;

  assign busy = (st != S_IDLE);

  // the numerator in acc goes to its divider (which latches it in the next cycle)
  task start_div(input [1:0] field);
    begin
      dv_go[div_of(field)]                 <= 1'b1;
      dv_pend[div_of(field)]               <= 1'b1;
      dv_field[div_of(field)*2 +: 2]       <= field;
      dv_attr[div_of(field)*3 +: 3]        <= ak;
      dv_a0[div_of(field)*32 +: 32]        <= 32'(a0);
    end
  endtask

  always @(posedge clk) begin
    done   <= 1'b0;
    pw_en  <= 1'b0;
    dv_go  <= {ND{1'b0}};
    mac_go <= 1'b0;
    add_go <= 1'b0;
    e_we   <= 3'b000;
    xl_next <= 1'b0;
    if (rst) begin
      st          <= S_IDLE;
      flip        <= 1'b0;
      draw        <= 1'b0;
      dv_pend     <= {ND{1'b0}};
      dv_rdy      <= {ND{1'b0}};
      xl_next     <= 1'b0;
    end else begin
      // division results become plane writes: the step right is followed by the step left
      dv_rdy <= dv_rdy | dv_done;
      if (xl_next) begin
        pw_en    <= 1'b1;
        pw_field <= 2'd2;
        dv_pend[wsel] <= 1'b0;
      end else if (dv_rdy != {ND{1'b0}}) begin
        pw_en    <= 1'b1;
        wsel     <= rdy_sel;
        pw_attr  <= dv_attr[rdy_sel*3 +: 3];
        pw_field <= dv_field[rdy_sel*2 +: 2];
        xl_next  <= (dv_field[rdy_sel*2 +: 2] == 2'd1);
        dv_rdy[rdy_sel] <= 1'b0;
        if (dv_field[rdy_sel*2 +: 2] != 2'd1) dv_pend[rdy_sel] <= 1'b0;
      end
      case (st)
        S_IDLE: if (start) begin
          box_x0 <= clip_x0;
          box_xl <= clip_x1 - 11'd1;  // clip_x1 > clip_x0 >= 0: a setup starts only then
          flip  <= 1'b0;
          sh5   <= 1'b0;
          cstep <= 2'd0;
          r_v0 <= v0; r_v1 <= v1; r_v2 <= v2;
          r_clip_x0 <= clip_x0; r_clip_y0 <= clip_y0;
          r_clip_x1 <= clip_x1; r_clip_y1 <= clip_y1;
          r_width <= width;
          if (rect) begin
            box_y0  <= clip_y0;
            box_y1  <= clip_y1;
            x_start <= clip_x0;
            draw    <= 1'b1;
            st      <= S_ORIGIN;
          end else begin
            st  <= S_DELTA;
          end
        end
        S_DELTA: begin
          dx0 <= sub16(x2, x1); dy0 <= sub16(y2, y1);
          dx1 <= sub16(x0, x2); dy1 <= sub16(y0, y2);
          dx2 <= sub16(x1, x0); dy2 <= sub16(y1, y0);
          st  <= S_AREA;
        end
        S_AREA: begin  // D = dx20*dy01 - dx01*dy20
          asel <= A_AREA; osel1 <= O_DY2; osel2 <= O_DY1; msub <= 1'b1; mneg <= 1'b0;
          mac_go <= 1'b1;
          st <= S_WAIT; ret <= S_FLIP;
        end
        S_WAIT: if (!mac_busy) st <= ret;
        S_FLIP: begin
          if (acc == 0) begin
            draw <= 1'b0;
            st   <= S_END;
          end else if (acc_s[ACC_W-1]) begin
            // D < 0: exchanged; |D| by the area multiply again, negated (no negator for 2D)
            flip   <= 1'b1;
            mneg   <= 1'b1;
            mac_go <= 1'b1;
            st <= S_WAIT; ret <= S_FLIP;
          end else begin
            den <= 35'(acc_s <<< 1);
            pv  <= argmin(dy2, dy0, dy1);  // the top vertex
            st  <= S_BOX;
          end
        end
        S_BOX: begin
          x_out_r <= x_out;
          by0  <= (fy > cy0) ? fy : cy0;
          by1  <= (fyb < cy1) ? fyb : cy1;
          xt   <= 13'(xa >>> 4);
          st   <= S_BOX2;
        end
        S_BOX2: begin
          if (box_empty) begin
            draw <= 1'b0;
            st   <= S_END;
          end else begin
            box_y0  <= by0[10:0];
            box_y1  <= by1[10:0];
            x_start <= xs;
            draw    <= 1'b1;
            st      <= S_ORIGIN;
          end
        end
        S_ORIGIN: begin  // y0 * width + x_start
          asel <= A_ORIGIN; osel1 <= O_W; osel2 <= O_XS; msub <= 1'b0; mneg <= 1'b0;
          mac_go <= 1'b1;
          ek <= 2'd0;
          pv <= 2'd1;
          st <= S_WAIT; ret <= S_EDGE;
        end
        S_EDGE: begin
          if (ek == 2'd0) origin_idx <= acc[IDX_W-1:0];
          if (rect) begin
            st <= S_END;
          end else begin
            // dx*(sy - Ya) - dy*(sx - Xa), negated when exchanged
            asel <= A_EDGE;
            osel1 <= (ek == 2'd0) ? O_DX0 : (ek == 2'd1) ? O_DX1 : O_DX2;
            osel2 <= (ek == 2'd0) ? O_DY0 : (ek == 2'd1) ? O_DY1 : O_DY2;
            msub <= 1'b1; mneg <= flip;
            mac_go <= 1'b1;
            st <= S_WAIT; ret <= S_BIAS;
          end
        end
        S_BIAS: begin  // -1 unless the edge (as drawn) is top or left; then into the rasteriser
          if (!cstep[0] && !((ek == 2'd0) ? tl0 : (ek == 2'd1) ? tl1 : tl2)) begin
            add_go <= 1'b1; aop <= ~(ACC_W'(aop_b)); add_neg <= 1'b1; add_dbl <= 1'b0;
            cstep[0] <= 1'b1;
          end else if (!add_go) begin
            cstep[0] <= 1'b0;
            e_we <= (ek == 2'd0) ? 3'b001 : (ek == 2'd1) ? 3'b010 : 3'b100;
            ek   <= ek + 2'd1;
            pv   <= (ek == 2'd0) ? 2'd2 : 2'd0;
            if (ek == 2'd2) begin
              todo <= need;
              st   <= S_ANEXT;
            end else begin
              st <= S_EDGE;
            end
          end
        end
        S_ANEXT: begin
          if (todo == 8'd0) begin
            st <= S_DRAIN;
          end else begin
            ak   <= todo[0] ? 3'd0 : todo[1] ? 3'd1 : todo[2] ? 3'd2 : todo[3] ? 3'd3 :
                    todo[4] ? 3'd4 : todo[5] ? 3'd5 : todo[6] ? 3'd6 : 3'd7;
            todo <= todo & (todo - 8'd1);
            st   <= S_GX;
          end
        end
        S_GX: begin  // -32 Gx (negated when exchanged)
          asel <= A_ATTR; osel1 <= O_DY1; osel2 <= O_DY2; sh5 <= 1'b1; msub <= 1'b0;
          mneg <= !flip;
          mac_go <= 1'b1;
          st <= S_GX_W;
        end
        S_GX_W: if (!mac_busy && free_x) begin
          start_div(2'd1);
          osel1 <= O_DX1; osel2 <= O_DX2; mneg <= flip;  // 32 Gy
          st <= S_GY;
        end
        S_GY: begin  // the divider latches acc this cycle; the step down's multiply follows
          mac_go <= 1'b1;
          st <= S_M0;
        end
        S_M0: if (!mac_busy && free_y) begin
          start_div(2'd3);
          sh5 <= 1'b0; osel1 <= O_E1; osel2 <= O_E2; mneg <= 1'b0;
          cstep <= 2'd0;
          st <= S_M0_C;
        end
        S_M0_C: begin
          // (the divider latches acc in the first cycle here) 2(d1 e1 + d2 e2) + bias
          // corrections + |D|: the products, d1 and d2 where the bias is -1, then 2 acc + D
          if (cstep == 2'd0) begin
            mac_go <= 1'b1;
            cstep  <= 2'd1;
          end else if (!mac_busy && !add_go) begin
            add_go   <= (cstep == 2'd1) ? !tl1 : (cstep == 2'd2) ? !tl2 : 1'b1;
            aop      <= ACC_W'(aop_c);
            add_neg  <= 1'b0;
            add_dbl  <= (cstep == 2'd3);
            cstep    <= cstep + 2'd1;
            if (cstep == 2'd3) st <= S_M0_D;
          end
        end
        S_M0_D: if (!add_go && free_0) begin
          start_div(2'd0);
          st <= S_ANEXT;
        end
        S_DRAIN: if (all_free) st <= S_END;
        default: begin  // S_END
          done <= 1'b1;
          st   <= S_IDLE;
        end
      endcase
    end
  end
endmodule
