// Triangle setup (docs/protocol.md sections 8 and 9): a sequencer around one accumulator, a
// dual multiply-accumulate and the exact divider.
//   1. edge deltas dx, dy of the edges 1->2, 2->0, 0->1 (kept here; the rasteriser steps with
//      them), the area D = dx20*dy01 - dx01*dy20 (section 8.1); D = 0 draws nothing; D < 0
//      exchanges P1 and P2 and the deltas are taken again;
//   2. bounding box of the sample points inside the vertices, clipped to the clip rectangle,
//      and the linear index y0 * width + x0 of its origin pixel;
//   3. each edge function E_ab(s) = dx*(sy - Ya) - dy*(sx - Xa) at the origin's sample point,
//      minus 1 unless the edge is top or left (the bias);
//   4. per interpolated attribute (d1 = a1 - a0, d2 = a2 - a0), the exact plane stepper of
//      section 9: the numerator M = 2(d1*E20 + d2*E01) + D changes by
//      Mx = -32(d1*dy20 + d2*dy01) per pixel right and My = 32(d1*dx20 + d2*dx01) per pixel down;
//      each is split by the divider into a quotient and a remainder of 2D; the value at the
//      origin is a0 + floor(M0 / 2D). The step left is written as (~qx, 2D - 1 - rx), which the
//      steppers add with a carry in.
// A clear (rect) only sets up the clip rectangle as the box and its origin index.
// Multiplies are a1*m1 +/- a2*m2 into the accumulator: in parallel (SERIAL = 0), or bit-serially
// by Horner's rule, two cycles per bit of the a operands (SERIAL = 1: small, for the iCE40).
// A multiply overlaps the previous division. The vertex inputs are read while the command waits
// on the port (held stable by the soc).
module core_setup #(
    parameter integer SERIAL = 0,
    parameter integer TEX = 1,       // S, T, Q planes exist (33-bit deltas)
    parameter integer IDX_W = 20,
    parameter integer SKIP = 1       // divider skips leading zero quotient bits (faster, larger)
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
    input  wire [10:0]  clip_x1,      // exclusive, already min(SCISSOR.X1, WIDTH)
    input  wire [10:0]  clip_y1,
    input  wire [10:0]  width,        // FB_FORMAT.WIDTH
    input  wire [7:0]   need,         // planes to set up: R G B A Z S T Q (bit 0 = R)
    // held for the rasteriser: edges 1->2, 2->0, 0->1
    output reg  signed [16:0] dx0, dx1, dx2, dy0, dy1, dy2,
    // biased edge values at the origin's sample point, written into the rasteriser's registers
    // (which keep them until the walk starts; E20 and E01 come back for the planes)
    output reg  [2:0]   e_we,
    output wire signed [35:0] e_data,
    input  wire signed [35:0] e1,
    input  wire signed [35:0] e2,
    // the walk: rows box_y0 .. box_y1 - 1, columns box_x0 .. box_x1 - 1 (the clip rectangle's),
    // starting at column x_start of row box_y0 (below the top vertex)
    output reg  [10:0]  box_x0, box_y0, box_x1, box_y1, x_start,
    output reg  [IDX_W-1:0] origin_idx,
    output reg  [34:0]  den,          // 2D
    // plane writes: field 0 value at the origin, 1 step right, 2 step left, 3 step down
    output reg          pw_en,
    output reg  [2:0]   pw_attr,
    output reg  [1:0]   pw_field,
    output wire [31:0]  pw_q,
    output wire [34:0]  pw_r
);
  localparam integer AW = (TEX != 0) ? 33 : 25;     // attribute delta bits
  localparam integer ACC_W = (TEX != 0) ? 72 : 64;  // accumulator / numerator bits

  // ---------------------------------------------------------------- vertices
  reg flip;
  wire signed [15:0] x0 = v0[15:0], y0 = v0[31:16];
  wire signed [15:0] x1 = flip ? v2[15:0] : v1[15:0], y1 = flip ? v2[31:16] : v1[31:16];
  wire signed [15:0] x2 = flip ? v1[15:0] : v2[15:0], y2 = flip ? v1[31:16] : v2[31:16];
  function signed [16:0] sub16(input signed [15:0] b, input signed [15:0] a);
    sub16 = $signed({b[15], b}) - $signed({a[15], a});
  endfunction

  // top or left edge: bias 0, otherwise -1
  wire tl0 = (dy0 == 0 && dx0 > 0) || dy0 < 0;
  wire tl1 = (dy1 == 0 && dx1 > 0) || dy1 < 0;
  wire tl2 = (dy2 == 0 && dx2 > 0) || dy2 < 0;

  // ---------------------------------------------------------------- rows and start column
  // vertex order along each axis from the signs of the deltas
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
  wire [1:0] top = argmin(dy2, dy0, dy1);
  wire signed [15:0] mnx = pick3(argmin(dx2, dx0, dx1), x0, x1, x2);
  wire signed [15:0] mxx = pick3(argmax(dx2, dx0, dx1), x0, x1, x2);
  wire signed [15:0] mny = pick3(top, y0, y1, y2);
  wire signed [15:0] mxy = pick3(argmax(dy2, dy0, dy1), y0, y1, y2);
  wire signed [15:0] xtop = pick3(top, x0, x1, x2);
  // samples 16p + 8 inside [min, max]: p from (min + 7) >> 4 to (max + 8) >> 4, exclusive
  wire signed [12:0] fx0 = 13'(($signed({mnx[15], mnx}) + 17'sd7) >>> 4);
  wire signed [12:0] fy0 = 13'(($signed({mny[15], mny}) + 17'sd7) >>> 4);
  wire signed [12:0] fx1 = 13'((($signed({mxx[15], mxx}) + 17'sd8) >>> 4));
  wire signed [12:0] fy1 = 13'((($signed({mxy[15], mxy}) + 17'sd8) >>> 4));
  wire signed [12:0] cx0 = $signed({2'b0, clip_x0}), cx1 = $signed({2'b0, clip_x1});
  wire signed [12:0] cy0 = $signed({2'b0, clip_y0}), cy1 = $signed({2'b0, clip_y1});
  wire signed [12:0] by0 = (fy0 > cy0) ? fy0 : cy0;
  wire signed [12:0] by1 = (fy1 < cy1) ? fy1 : cy1;
  wire box_empty = (fx0 >= cx1) || (fx1 <= cx0) || (by0 >= by1);
  // the walk starts below the top vertex, inside the clip columns
  wire signed [12:0] xt = 13'(xtop >>> 4);
  wire [10:0] xs = (xt < cx0) ? clip_x0 : (xt >= cx1) ? clip_x1 - 11'd1 : xt[10:0];

  // ---------------------------------------------------------------- attribute deltas
  function [AW-1:0] attr(input [183:0] v, input [2:0] k);
    reg [32:0] a;
    begin
      case (k)
        3'd0: a = {25'b0, v[87:80]};
        3'd1: a = {25'b0, v[79:72]};
        3'd2: a = {25'b0, v[71:64]};
        3'd3: a = {25'b0, v[63:56]};
        3'd4: a = {9'b0, v[55:32]};
        3'd5: a = {v[151], v[151:120]};
        3'd6: a = {v[183], v[183:152]};
        default: a = {1'b0, v[119:88]};
      endcase
      attr = a[AW-1:0];
    end
  endfunction
  reg  [2:0] ak;  // attribute being set up
  wire [2:0] akv = (TEX != 0 || ak < 3'd5) ? ak : 3'd0;
  wire signed [AW-1:0] a0 = attr(v0, akv), k1 = attr(v1, akv), k2 = attr(v2, akv);
  wire signed [AW-1:0] kd1 = k1 - a0, kd2 = k2 - a0;        // kick order; |d| < 2^(AW-1)
  wire signed [AW-1:0] d1 = flip ? kd2 : kd1, d2 = flip ? kd1 : kd2;
  wire flat_attr = (kd1 == 0) && (kd2 == 0);
  // multiplier width of the attribute's deltas: 9 (colour), 25 (Z), 33 (S, T, Q)
  wire [5:0] abits = (ak < 3'd4) ? 6'd9 : (ak == 3'd4) ? 6'd25 : 6'd33;

  // ---------------------------------------------------------------- accumulator
  localparam [2:0] A_AREA = 3'd0, A_ORIGIN = 3'd1, A_EDGE = 3'd2, A_ATTR = 3'd3;
  localparam [3:0] M_AREA = 4'd0, M_WIDTH = 4'd1, M_E0 = 4'd2, M_E1 = 4'd3, M_E2 = 4'd4,
                   M_GX = 4'd5, M_GY = 4'd6, M_M0 = 4'd7, M_D = 4'd8, M_ONE = 4'd9, M_DEN = 4'd10;
  reg  [2:0] asel;
  reg  [3:0] msel;
  reg        msub;  // subtract the second product
  reg        mneg;  // negate both products
  reg [ACC_W-1:0] acc;
  wire signed [ACC_W-1:0] acc_s = $signed(acc);
  assign e_data = acc_s[35:0];
  wire signed [17:0] sx = $signed({3'b0, x_start, 4'b1000});  // 16x + 8
  wire signed [17:0] sy = $signed({3'b0, box_y0, 4'b1000});
  reg signed [15:0] xa, ya;  // the current edge's start vertex
  always @(*) begin
    case (msel)
      M_E0: begin xa = x1; ya = y1; end
      M_E1: begin xa = x2; ya = y2; end
      default: begin xa = x0; ya = y0; end
    endcase
  end
  wire signed [17:0] ey_a = sy - 18'(ya), ex_a = sx - 18'(xa);  // sample point minus Pa
  reg signed [32:0] ma1, ma2;   // a operands (sign-extended)
  reg [5:0] mbits;              // bits in the a operands
  always @(*) begin
    case (asel)
      A_AREA:   begin ma1 = 33'(dx1); ma2 = 33'(dx2); mbits = 6'd17; end
      A_ORIGIN: begin ma1 = {21'd0, 1'b0, box_y0}; ma2 = 33'd1; mbits = 6'd12; end  // y0*w + x0
      A_EDGE:   begin ma1 = 33'(ey_a); ma2 = 33'(ex_a); mbits = 6'd18; end
      default:  begin ma1 = 33'(d1); ma2 = 33'(d2); mbits = abits; end
    endcase
  end
  // m operands: a narrow (delta, width, constant) or a wide (edge value, attribute delta, D) one
  reg signed [16:0] n1, n2;
  reg signed [35:0] w1, w2;
  reg               wide, sh5;
  always @(*) begin
    n1 = 17'sd0; n2 = 17'sd0; w1 = 36'sd0; w2 = 36'sd0; wide = 1'b0; sh5 = 1'b0;
    case (msel)
      M_AREA:  begin n1 = dy2; n2 = dy1; end                  // dx20*dy01 - dx01*dy20
      M_WIDTH: begin n1 = {6'd0, width}; n2 = {6'd0, x_start}; end
      M_E0:    begin n1 = dx0; n2 = dy0; end
      M_E1:    begin n1 = dx1; n2 = dy1; end
      M_E2:    begin n1 = dx2; n2 = dy2; end
      M_GX:    begin n1 = dy1; n2 = dy2; sh5 = 1'b1; end       // negated: -32 Gx
      M_GY:    begin n1 = dx1; n2 = dx2; sh5 = 1'b1; end
      M_ONE:   begin n1 = 17'sd1; end
      M_M0:    begin w1 = e1; w2 = e2; wide = 1'b1; end         // biased E20, E01
      M_D:     begin w1 = 36'(d1); w2 = 36'(d2); wide = 1'b1; end
      default: begin w1 = {2'b0, den[34:1]}; wide = 1'b1; end  // M_DEN: D
    endcase
  end
  wire signed [35:0] mm1 = wide ? w1 : sh5 ? (36'(n1) <<< 5) : 36'(n1);
  wire signed [35:0] mm2 = wide ? w2 : sh5 ? (36'(n2) <<< 5) : 36'(n2);

  // acc <- A + (+/-)B: A = 0, acc or 2 acc; B = one of the m operands or 0
  reg        s_clr, s_dbl, s_use1, s_use2, s_neg;
  wire signed [ACC_W-1:0] bop = s_use1 ? ACC_W'(mm1) : s_use2 ? ACC_W'(mm2) : {ACC_W{1'b0}};
  wire [ACC_W-1:0] aop = s_clr ? {ACC_W{1'b0}} : s_dbl ? (acc << 1) : acc;
  wire [ACC_W-1:0] acc_sum = aop + (bop ^ {ACC_W{s_neg}}) + {{(ACC_W-1){1'b0}}, s_neg};

  // single additions requested by the sequencer (registered, applied in the next cycle)
  reg        add_go;
  reg        add_use2, add_neg, add_dbl, add_clr;  // add_clr: acc <- 0 (no operand)
  reg        mac_go;   // pulse: start a multiply-accumulate into acc (from 0)
  wire       mac_busy;
  generate
    if (SERIAL != 0) begin : serial_mac
      // Horner's rule, most significant bit first, alternating the two products:
      //   acc = 2 acc +/- a1[k] m1;  acc = acc +/- a2[k] m2   (bit k = mbits-1 weighs negative)
      reg [5:0] k;
      reg       ph, run, first;
      wire      b1 = ma1[k - 6'd1], b2 = ma2[k - 6'd1];
      wire      msb = (k == mbits);
      assign mac_busy = run;
      always @(*) begin
        s_clr  = run ? first : add_clr;
        s_dbl  = run ? (!ph && !first) : add_dbl;
        s_use1 = run ? (!ph && b1) : (!add_use2 && !add_clr);
        s_use2 = run ? (ph && b2) : (add_use2 && !add_clr);
        s_neg  = run ? (ph ? (mneg ^ msb ^ msub) : (mneg ^ msb)) : add_neg;
      end
      always @(posedge clk) begin
        if (rst) begin
          run <= 1'b0;
        end else if (mac_go) begin
          run   <= 1'b1;
          k     <= mbits;
          ph    <= 1'b0;
          first <= 1'b1;
        end else if (run) begin
          acc   <= acc_sum;
          first <= 1'b0;
          ph    <= !ph;
          if (ph) begin
            k <= k - 6'd1;
            if (k == 6'd1) run <= 1'b0;
          end
        end else if (add_go) begin
          acc <= acc_sum;
        end
      end
    end else begin : parallel_mac
      reg run;
      wire signed [68:0] p1 = 69'(ma1) * 69'(mm1);
      wire signed [68:0] p2 = 69'(ma2) * 69'(mm2);
      wire signed [ACC_W-1:0] s12 = ACC_W'(p1) + (msub ? -(ACC_W'(p2)) : ACC_W'(p2));
      assign mac_busy = run;
      always @(*) begin
        s_clr  = add_clr;
        s_dbl  = add_dbl;
        s_use1 = !add_use2 && !add_clr;
        s_use2 = add_use2 && !add_clr;
        s_neg  = add_neg;
      end
      always @(posedge clk) begin
        if (rst) begin
          run <= 1'b0;
        end else if (mac_go) begin
          run <= 1'b1;
        end else if (run) begin
          acc <= mneg ? -s12 : s12;
          run <= 1'b0;
        end else if (add_go) begin
          acc <= acc_sum;
        end
      end
    end
  endgenerate

  // ---------------------------------------------------------------- divider
  reg          div_go;
  wire         div_done;
  wire [31:0]  div_q;
  wire [34:0]  div_r, div_rc;
  /* verilator lint_off PINCONNECTEMPTY */
  core_divider #(.NW(ACC_W), .DW(35), .QW(32), .SKIP(SKIP)) divider (
      .clk(clk), .rst(rst), .start(div_go), .num(acc_s), .den(den),
      .busy(), .done(div_done), .quo(div_q), .rem(div_r), .rem_c(div_rc));
  /* verilator lint_on PINCONNECTEMPTY */
  reg  [2:0]  div_attr;     // the attribute whose division runs
  reg  [1:0]  div_field;    // the plane field it produces
  reg         div_pending;  // running, or its results not yet written
  reg         xl_next;      // the step left follows the step right's write
  reg  [31:0] div_a0;

  // plane writes come from the divider's held results
  assign pw_q = (pw_field == 2'd0) ? div_a0 + div_q : (pw_field == 2'd2) ? ~div_q : div_q;
  assign pw_r = (pw_field == 2'd2) ? div_rc : div_r;

  // ---------------------------------------------------------------- sequencer
  localparam [4:0] S_IDLE = 5'd0, S_DELTA = 5'd1, S_AREA = 5'd2, S_FLIP = 5'd3, S_BOX = 5'd4,
                   S_ORIGIN = 5'd5, S_EDGE = 5'd6, S_EDGE_B = 5'd7, S_ANEXT = 5'd8, S_GX = 5'd9,
                   S_GX_W = 5'd10, S_GY = 5'd11, S_GY_W = 5'd12, S_M0 = 5'd13, S_M0_C = 5'd14,
                   S_M0_D = 5'd15, S_DRAIN = 5'd16, S_END = 5'd17, S_WAIT = 5'd18, S_ORIG_W = 5'd19;
  reg [4:0]  st, ret;   // S_WAIT: until the multiply is done, then ret
  reg [1:0]  ek;        // edge being evaluated
  reg [1:0]  cstep;     // M0 corrections
  reg        bflag;     // edge bias subtracted
  reg [7:0]  todo;

  assign busy = (st != S_IDLE);
  wire div_free = !div_pending && !div_go;

  always @(posedge clk) begin
    done   <= 1'b0;
    pw_en  <= 1'b0;
    div_go <= 1'b0;
    mac_go <= 1'b0;
    add_go <= 1'b0;
    add_clr <= 1'b0;
    e_we <= 3'b000;
    if (rst) begin
      st          <= S_IDLE;
      flip        <= 1'b0;
      draw        <= 1'b0;
      div_pending <= 1'b0;
    end else begin
      // division results become plane writes: the step right is followed by the step left
      xl_next <= 1'b0;
      if (div_done) begin
        pw_en    <= 1'b1;
        pw_attr  <= div_attr;
        pw_field <= div_field;
        xl_next  <= (div_field == 2'd1);
        if (div_field != 2'd1) div_pending <= 1'b0;
      end else if (xl_next) begin
        pw_en       <= 1'b1;
        pw_field    <= 2'd2;
        div_pending <= 1'b0;
      end
      case (st)
        S_IDLE: if (start) begin
          flip <= 1'b0;
          box_x0 <= clip_x0;
          box_x1 <= clip_x1;
          if (rect) begin
            box_y0  <= clip_y0;
            box_y1  <= clip_y1;
            x_start <= clip_x0;
            draw    <= 1'b1;
            st      <= S_ORIGIN;
          end else begin
            st  <= S_DELTA;
            ret <= S_AREA;
          end
        end
        S_DELTA: begin  // edge deltas of the (possibly exchanged) vertices
          dx0 <= sub16(x2, x1); dy0 <= sub16(y2, y1);
          dx1 <= sub16(x0, x2); dy1 <= sub16(y0, y2);
          dx2 <= sub16(x1, x0); dy2 <= sub16(y1, y0);
          st  <= ret;
        end
        S_AREA: begin
          asel <= A_AREA; msel <= M_AREA; msub <= 1'b1; mneg <= 1'b0;
          mac_go <= 1'b1;
          st <= S_WAIT; ret <= S_FLIP;
        end
        S_WAIT: if (!mac_busy && !mac_go) st <= ret;
        S_FLIP: begin
          if (acc == 0) begin
            draw <= 1'b0;
            st   <= S_END;
          end else begin
            den <= acc_s[ACC_W-1] ? 35'(-(acc_s <<< 1)) : 35'(acc_s <<< 1);
            if (acc_s[ACC_W-1]) begin
              flip <= 1'b1;
              st   <= S_DELTA;
              ret  <= S_BOX;
            end else begin
              st <= S_BOX;
            end
          end
        end
        S_BOX: begin
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
        S_ORIGIN: begin
          asel <= A_ORIGIN; msel <= M_WIDTH; msub <= 1'b0; mneg <= 1'b0;
          mac_go <= 1'b1;
          ek <= 2'd0;
          st <= S_WAIT; ret <= S_ORIG_W;
        end
        S_ORIG_W: begin
          origin_idx <= acc[IDX_W-1:0];
          st <= rect ? S_END : S_EDGE;
        end
        S_EDGE: begin
          bflag <= 1'b0;
          asel <= A_EDGE; msel <= (ek == 2'd0) ? M_E0 : (ek == 2'd1) ? M_E1 : M_E2;
          msub <= 1'b1; mneg <= 1'b0;
          mac_go <= 1'b1;
          st <= S_WAIT; ret <= S_EDGE_B;
        end
        S_EDGE_B: begin
          // the bias: -1 unless the edge is top or left
          if (!((ek == 2'd0) ? tl0 : (ek == 2'd1) ? tl1 : tl2) && !bflag) begin
            msel <= M_ONE; add_go <= 1'b1; add_use2 <= 1'b0; add_neg <= 1'b1; add_dbl <= 1'b0;
            bflag <= 1'b1;
          end else if (!add_go) begin
            e_we <= (ek == 2'd0) ? 3'b001 : (ek == 2'd1) ? 3'b010 : 3'b100;
            ek <= ek + 2'd1;
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
        S_GX: begin
          asel <= A_ATTR; msel <= M_GX; msub <= 1'b0; mneg <= 1'b1;
          if (flat_attr) begin
            add_go <= 1'b1; add_clr <= 1'b1; add_dbl <= 1'b0; add_neg <= 1'b0; add_use2 <= 1'b0;
            st <= S_GX_W;  // no products: acc <- 0
          end else begin
            mac_go <= 1'b1;
            st <= S_WAIT; ret <= S_GX_W;
          end
        end
        S_GX_W: if (div_free && !add_go) begin
          div_go <= 1'b1; div_pending <= 1'b1; div_field <= 2'd1; div_attr <= ak;
          div_a0 <= 32'(a0);
          msel <= M_GY; mneg <= 1'b0;
          st <= S_GY;
        end
        S_GY: begin  // the divider latches acc in this cycle
          if (flat_attr) begin
            st <= S_GY_W;
          end else begin
            mac_go <= 1'b1;
            st <= S_WAIT; ret <= S_GY_W;
          end
        end
        S_GY_W: if (div_free) begin
          div_go <= 1'b1; div_pending <= 1'b1; div_field <= 2'd3;
          msel <= M_M0;
          st <= S_M0;
        end
        S_M0: begin
          if (flat_attr) begin
            cstep <= 2'd2;
            st    <= S_M0_C;
          end else begin
            mac_go <= 1'b1;
            cstep  <= 2'd0;
            st <= S_WAIT; ret <= S_M0_C;
          end
        end
        S_M0_C: if (!add_go) begin
          // E20 and E01 were biased: add d1, d2 back where the bias was -1; then 2 acc + D
          msel <= (cstep == 2'd2) ? M_DEN : M_D;
          add_go   <= (cstep == 2'd0) ? !tl1 : (cstep == 2'd1) ? !tl2 : 1'b1;
          add_use2 <= (cstep == 2'd1);
          add_neg  <= 1'b0;
          add_dbl  <= (cstep == 2'd2);
          cstep    <= cstep + 2'd1;
          if (cstep == 2'd2) st <= S_M0_D;
        end
        S_M0_D: if (!add_go && div_free) begin
          div_go <= 1'b1; div_pending <= 1'b1; div_field <= 2'd0;
          st <= S_ANEXT;
        end
        S_DRAIN: if (div_free) st <= S_END;
        default: begin  // S_END
          done <= 1'b1;
          st   <= S_IDLE;
        end
      endcase
    end
  end
endmodule
