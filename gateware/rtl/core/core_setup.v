// Triangle setup (docs/protocol.md sections 8 and 9): a sequencer around one accumulator, a
// dual multiply-accumulate and the exact divider.
//   1. edge deltas dx, dy of the edges 1->2, 2->0, 0->1 (kept here; the rasteriser steps with
//      them), the area D = dx20*dy01 - dx01*dy20 (section 8.1); D = 0 draws nothing; D < 0
//      exchanges P1 and P2 and the deltas are taken again;
//   2. bounding box of the sample points inside the vertices, clipped to the clip rectangle,
//      and the linear index y0 * width + x0 of its origin pixel;
//   3. each edge function E_ab(s) = dx*(sy - Ya) - dy*(sx - Xa) at the origin's sample point,
//      with its top-left bias;
//   4. per interpolated attribute (d1 = a1 - a0, d2 = a2 - a0), the exact plane stepper of
//      section 9: the numerator M = 2(d1*E20 + d2*E01) + D changes by
//      Mx = -32(d1*dy20 + d2*dy01) per pixel right and My = 32(d1*dx20 + d2*dx01) per pixel down;
//      each is split by the divider into a quotient and a remainder of 2D; the value at the
//      origin is a0 + floor(M0 / 2D). A step left is the negated step right, renormalised.
// Multiplies are a1*m1 + a2*m2 into the accumulator: in parallel (SERIAL = 0), or bit-serially,
// two cycles per bit of the a operands (SERIAL = 1: small, for the iCE40). A multiply overlaps
// the previous division.
// The vertex inputs are read while the command waits on the port (held stable by the soc).
module core_setup #(
    parameter integer SERIAL = 0,
    parameter integer TEX = 1,       // S, T, Q planes exist (33-bit deltas)
    parameter integer IDX_W = 20
) (
    input  wire         clk,
    input  wire         rst,
    input  wire         start,        // pulse: a triangle waits on the command port
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
    output reg  signed [35:0] e0, e1, e2,   // biased edge values at the origin's sample point
    output reg  [10:0]  box_x0, box_y0, box_x1, box_y1,
    output reg  [IDX_W-1:0] origin_idx,
    output reg  [34:0]  den,          // 2D
    // plane writes: field 0 = value at the origin, 1 = step right, 2 = step left, 3 = step down
    output reg          pw_en,
    output reg  [2:0]   pw_attr,
    output reg  [1:0]   pw_field,
    output reg  [31:0]  pw_q,
    output reg  [34:0]  pw_r
);
  localparam integer AW = (TEX != 0) ? 33 : 25;     // attribute delta bits
  localparam integer ACC_W = (TEX != 0) ? 72 : 64;  // accumulator / numerator bits
  localparam integer MW = 36;                // multiplicand bits

  // ---------------------------------------------------------------- vertices
  reg flip;
  wire signed [15:0] x0 = v0[15:0], y0 = v0[31:16];
  wire signed [15:0] x1 = flip ? v2[15:0] : v1[15:0], y1 = flip ? v2[31:16] : v1[31:16];
  wire signed [15:0] x2 = flip ? v1[15:0] : v2[15:0], y2 = flip ? v1[31:16] : v2[31:16];
  function signed [16:0] sub16(input signed [15:0] b, input signed [15:0] a);
    sub16 = $signed({b[15], b}) - $signed({a[15], a});
  endfunction
  wire signed [16:0] ndx0 = sub16(x2, x1), ndy0 = sub16(y2, y1);
  wire signed [16:0] ndx1 = sub16(x0, x2), ndy1 = sub16(y0, y2);
  wire signed [16:0] ndx2 = sub16(x1, x0), ndy2 = sub16(y1, y0);

  // top or left edge: bias 0, otherwise -1
  wire tl0 = (dy0 == 0 && dx0 > 0) || dy0 < 0;
  wire tl1 = (dy1 == 0 && dx1 > 0) || dy1 < 0;
  wire tl2 = (dy2 == 0 && dx2 > 0) || dy2 < 0;

  // ---------------------------------------------------------------- bounding box
  // vertex order along each axis from the signs of the deltas (x1 - x0 = dx2, x2 - x0 = -dx1)
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
  wire signed [15:0] mnx = pick3(argmin(dx2, dx0, dx1), x0, x1, x2);
  wire signed [15:0] mxx = pick3(argmax(dx2, dx0, dx1), x0, x1, x2);
  wire signed [15:0] mny = pick3(argmin(dy2, dy0, dy1), y0, y1, y2);
  wire signed [15:0] mxy = pick3(argmax(dy2, dy0, dy1), y0, y1, y2);
  // first pixel whose sample 16p + 8 >= min: (min + 7) >> 4; one past the last <= max
  wire signed [12:0] fx0 = 13'(($signed({mnx[15], mnx}) + 17'sd7) >>> 4);
  wire signed [12:0] fy0 = 13'(($signed({mny[15], mny}) + 17'sd7) >>> 4);
  wire signed [12:0] fx1 = 13'((($signed({mxx[15], mxx}) - 17'sd8) >>> 4) + 17'sd1);
  wire signed [12:0] fy1 = 13'((($signed({mxy[15], mxy}) - 17'sd8) >>> 4) + 17'sd1);
  wire signed [12:0] bx0 = (fx0 > $signed({2'b0, clip_x0})) ? fx0 : $signed({2'b0, clip_x0});
  wire signed [12:0] bx1 = (fx1 < $signed({2'b0, clip_x1})) ? fx1 : $signed({2'b0, clip_x1});
  wire signed [12:0] by0 = (fy0 > $signed({2'b0, clip_y0})) ? fy0 : $signed({2'b0, clip_y0});
  wire signed [12:0] by1 = (fy1 < $signed({2'b0, clip_y1})) ? fy1 : $signed({2'b0, clip_y1});
  wire box_empty = (bx0 >= bx1) || (by0 >= by1);

  // ---------------------------------------------------------------- attribute deltas
  function signed [AW-1:0] attr(input [183:0] v, input [2:0] k);
    reg signed [32:0] a;
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
  wire signed [AW-1:0] a0 = attr(v0, ak);
  wire signed [AW-1:0] a1 = attr(flip ? v2 : v1, ak);
  wire signed [AW-1:0] a2 = attr(flip ? v1 : v2, ak);
  wire signed [AW-1:0] d1 = a1 - a0, d2 = a2 - a0;  // |d| < 2^(AW-1)
  wire flat_attr = (d1 == 0) && (d2 == 0);
  // multiplier width of the attribute's deltas: 9 (colour), 25 (Z), 33 (S, T, Q)
  wire [5:0] abits = (ak < 3'd4) ? 6'd9 : (ak == 3'd4) ? 6'd25 : 6'd33;

  // ---------------------------------------------------------------- multiply-accumulate
  // acc <- (clear ? 0 : acc) + a1*m1 +/- a2*m2, with a1, a2 from `asel` and m1, m2 from `msel`
  localparam [2:0] A_AREA = 3'd0, A_ORIGIN = 3'd1, A_EDGE = 3'd2, A_ATTR = 3'd3;
  localparam [3:0] M_AREA = 4'd0, M_WIDTH = 4'd1, M_E0 = 4'd2, M_E1 = 4'd3, M_E2 = 4'd4,
                   M_GX = 4'd5, M_GY = 4'd6, M_M0 = 4'd7;
  reg  [2:0] asel;
  reg  [3:0] msel;
  reg        msub;  // subtract the second product
  reg [ACC_W-1:0] acc;
  wire signed [17:0] sx = $signed({3'b0, box_x0, 4'b1000});  // 16x + 8
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
  reg signed [MW-1:0] mm1, mm2; // m operands
  reg [5:0] mbits;              // bits in the a operands
  always @(*) begin
    case (asel)
      A_AREA:   begin ma1 = 33'(dx1); ma2 = 33'(dx2); mbits = 6'd17; end
      A_ORIGIN: begin ma1 = {21'd0, 1'b0, box_y0}; ma2 = 33'd0; mbits = 6'd12; end
      A_EDGE:   begin ma1 = 33'(ey_a); ma2 = 33'(ex_a); mbits = 6'd18; end
      default:  begin ma1 = 33'(d1); ma2 = 33'(d2); mbits = abits; end
    endcase
    case (msel)
      M_AREA:  begin mm1 = 36'(dy2); mm2 = 36'(dy1); end          // dx20*dy01 - dx01*dy20
      M_WIDTH: begin mm1 = {25'd0, width}; mm2 = 36'd0; end
      M_E0:    begin mm1 = 36'(dx0); mm2 = 36'(dy0); end
      M_E1:    begin mm1 = 36'(dx1); mm2 = 36'(dy1); end
      M_E2:    begin mm1 = 36'(dx2); mm2 = 36'(dy2); end
      M_GX:    begin mm1 = 36'(dy1) <<< 5; mm2 = 36'(dy2) <<< 5; end  // acc negated: -32 Gx
      M_GY:    begin mm1 = 36'(dx1) <<< 5; mm2 = 36'(dx2) <<< 5; end
      default: begin mm1 = e1; mm2 = e2; end                     // biased E20, E01
    endcase
  end
  reg  mneg;    // negate both products (Mx = -32 Gx)
  reg  mac_go;  // pulse: start a multiply-accumulate into acc (from 0)
  wire mac_busy;
  generate
    if (SERIAL != 0) begin : serial_mac
      // Horner's rule, most significant bit first, alternating the two products:
      //   acc = 2 acc +/- a1[k] m1;  acc = acc +/- a2[k] m2   (bit k = mbits-1 weighs negative)
      reg [5:0] k;
      reg       ph, run;
      wire      b1 = ma1[k - 6'd1], b2 = ma2[k - 6'd1];
      wire      msb = (k == mbits);
      wire      neg1 = mneg ^ msb, neg2 = mneg ^ msb ^ msub;
      wire signed [ACC_W-1:0] t1 = b1 ? (neg1 ? -(ACC_W'(mm1)) : ACC_W'(mm1)) : {ACC_W{1'b0}};
      wire signed [ACC_W-1:0] t2 = b2 ? (neg2 ? -(ACC_W'(mm2)) : ACC_W'(mm2)) : {ACC_W{1'b0}};
      assign mac_busy = run;
      always @(posedge clk) begin
        if (rst) begin
          run <= 1'b0;
        end else if (mac_go) begin
          run <= 1'b1;
          k   <= mbits;
          ph  <= 1'b0;
          acc <= {ACC_W{1'b0}};
        end else if (run) begin
          if (!ph) begin
            acc <= (acc << 1) + t1;
            ph  <= 1'b1;
          end else begin
            acc <= acc + t2;
            ph  <= 1'b0;
            k   <= k - 6'd1;
            if (k == 6'd1) run <= 1'b0;
          end
        end else if (acc_add) begin
          acc <= acc_sum;
        end
      end
    end else begin : parallel_mac
      reg run;
      wire signed [68:0] p1 = 69'(ma1) * 69'(mm1);
      wire signed [68:0] p2 = 69'(ma2) * 69'(mm2);
      wire signed [ACC_W-1:0] s12 = ACC_W'(p1) + (msub ? -(ACC_W'(p2)) : ACC_W'(p2));
      assign mac_busy = run;
      always @(posedge clk) begin
        if (rst) begin
          run <= 1'b0;
        end else if (mac_go) begin
          run <= 1'b1;
        end else if (run) begin
          acc <= mneg ? -s12 : s12;
          run <= 1'b0;
        end else if (acc_add) begin
          acc <= acc_sum;
        end
      end
    end
  endgenerate

  // single additions: acc <- (double ? 2 acc : acc) + addend
  reg                acc_add, acc_dbl;
  reg  [ACC_W-1:0]   addend;
  wire [ACC_W-1:0]   acc_sum = (acc_dbl ? acc << 1 : acc) + addend;

  // ---------------------------------------------------------------- divider
  reg          div_go;
  wire         div_done;
  wire [31:0]  div_q;
  wire [34:0]  div_r;
  /* verilator lint_off PINCONNECTEMPTY */
  core_divider #(.NW(ACC_W), .DW(35), .QW(32)) divider (
      .clk(clk), .rst(rst), .start(div_go), .num($signed(acc)), .den(den),
      .busy(), .done(div_done), .quo(div_q), .rem(div_r));
  /* verilator lint_on PINCONNECTEMPTY */
  reg [1:0] div_field;   // which plane field the running division produces
  reg [2:0] div_attr;
  reg       div_pending;
  reg [31:0] div_a0;     // a0 of the attribute being divided (origin value)

  // ---------------------------------------------------------------- sequencer
  localparam [4:0] S_IDLE = 5'd0, S_DELTA = 5'd1, S_AREA = 5'd2, S_AREA_W = 5'd3, S_FLIP = 5'd4,
                   S_BOX = 5'd5, S_ORIGIN = 5'd6, S_ORIGIN_W = 5'd7, S_EDGE = 5'd8, S_EDGE_W = 5'd9,
                   S_EDGE_B = 5'd10, S_ANEXT = 5'd11, S_GX = 5'd12, S_GX_W = 5'd13, S_GY = 5'd14,
                   S_GY_W = 5'd15, S_M0 = 5'd16, S_M0_W = 5'd17, S_M0_C1 = 5'd18, S_M0_C2 = 5'd19,
                   S_M0_D = 5'd20, S_DRAIN = 5'd21, S_END = 5'd22, S_XL = 5'd23;
  reg [4:0]  st, ret;
  reg [1:0]  ek;        // edge being evaluated
  reg [7:0]  todo;
  reg [34:0] xr;        // remainder of the step right, for the step left
  reg [31:0] xq;

  assign busy = (st != S_IDLE);
  wire signed [ACC_W-1:0] acc_s = $signed(acc);

  // start a division of acc, once the previous one has been written
  wire div_free = !div_pending && !div_go;

  always @(posedge clk) begin
    done    <= 1'b0;
    pw_en   <= 1'b0;
    div_go  <= 1'b0;
    mac_go  <= 1'b0;
    acc_add <= 1'b0;
    if (rst) begin
      st          <= S_IDLE;
      flip        <= 1'b0;
      draw        <= 1'b0;
      div_pending <= 1'b0;
    end else begin
      // division results to plane writes
      if (div_done) begin
        div_pending <= 1'b0;
        pw_en    <= 1'b1;
        pw_attr  <= div_attr;
        pw_field <= div_field;
        pw_q     <= (div_field == 2'd0) ? div_a0 + div_q : div_q;
        pw_r     <= div_r;
        if (div_field == 2'd1) begin
          xq <= div_q;
          xr <= div_r;
        end
      end
      case (st)
        S_IDLE: if (start) begin
          flip <= 1'b0;
          st   <= S_DELTA;
          ret  <= S_AREA;
        end
        S_DELTA: begin  // edge deltas of the (possibly exchanged) vertices
          dx0 <= ndx0; dy0 <= ndy0; dx1 <= ndx1; dy1 <= ndy1; dx2 <= ndx2; dy2 <= ndy2;
          st  <= ret;
        end
        S_AREA: begin
          asel <= A_AREA; msel <= M_AREA; msub <= 1'b1; mneg <= 1'b0;
          mac_go <= 1'b1;
          st <= S_AREA_W;
        end
        S_AREA_W: if (!mac_busy && !mac_go) st <= S_FLIP;
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
            box_x0 <= bx0[10:0];
            box_x1 <= bx1[10:0];
            box_y0 <= by0[10:0];
            box_y1 <= by1[10:0];
            st     <= S_ORIGIN;
          end
        end
        S_ORIGIN: begin
          asel <= A_ORIGIN; msel <= M_WIDTH; msub <= 1'b0; mneg <= 1'b0;
          mac_go <= 1'b1;
          st <= S_ORIGIN_W;
        end
        S_ORIGIN_W: if (!mac_busy && !mac_go) begin
          origin_idx <= IDX_W'(acc) + {{(IDX_W-11){1'b0}}, box_x0};
          ek <= 2'd0;
          st <= S_EDGE;
        end
        S_EDGE: begin
          asel <= A_EDGE; msel <= (ek == 2'd0) ? M_E0 : (ek == 2'd1) ? M_E1 : M_E2;
          msub <= 1'b1; mneg <= 1'b0;
          mac_go <= 1'b1;
          st <= S_EDGE_W;
        end
        S_EDGE_W: if (!mac_busy && !mac_go) begin
          // the bias: -1 unless top or left
          case (ek)
            2'd0: e0 <= 36'(acc_s) - (tl0 ? 36'sd0 : 36'sd1);
            2'd1: e1 <= 36'(acc_s) - (tl1 ? 36'sd0 : 36'sd1);
            default: e2 <= 36'(acc_s) - (tl2 ? 36'sd0 : 36'sd1);
          endcase
          ek <= ek + 2'd1;
          if (ek == 2'd2) begin
            draw <= 1'b1;
            todo <= need;
            st   <= S_ANEXT;
          end else begin
            st <= S_EDGE;
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
          if (flat_attr) begin
            // constant: a0 everywhere (M = D at every pixel: quotient 0, remainder D)
            if (div_free) begin
              pw_en <= 1'b1; pw_attr <= ak; pw_field <= 2'd0; pw_q <= 32'(a0); pw_r <= den >> 1;
              st <= S_XL;  // zero steps
              xq <= 32'd0; xr <= 35'd0;
              ret <= S_ANEXT;
            end
          end else begin
            asel <= A_ATTR; msel <= M_GX; msub <= 1'b0; mneg <= 1'b1;
            mac_go <= 1'b1;
            st <= S_GX_W;
          end
        end
        S_GX_W: if (!mac_busy && !mac_go && div_free) begin
          div_go <= 1'b1; div_pending <= 1'b1; div_field <= 2'd1; div_attr <= ak;
          div_a0 <= 32'(a0);
          asel <= A_ATTR; msel <= M_GY; msub <= 1'b0; mneg <= 1'b0;
          st <= S_GY;
        end
        S_GY: begin  // the divider has latched acc
          mac_go <= 1'b1;
          st <= S_GY_W;
        end
        S_GY_W: if (!mac_busy && !mac_go && div_free) begin
          // step right known: write the step left, then divide My
          pw_en <= 1'b1; pw_attr <= ak; pw_field <= 2'd2;
          pw_q  <= (xr == 35'd0) ? -xq : ~xq;
          pw_r  <= (xr == 35'd0) ? 35'd0 : den - xr;
          div_go <= 1'b1; div_pending <= 1'b1; div_field <= 2'd3;
          asel <= A_ATTR; msel <= M_M0; msub <= 1'b0; mneg <= 1'b0;
          st <= S_M0;
        end
        S_M0: begin
          mac_go <= 1'b1;
          st <= S_M0_W;
        end
        S_M0_W: if (!mac_busy && !mac_go) begin
          // E20 and E01 were biased: add d1, d2 back where the bias was -1
          acc_add <= !tl1; acc_dbl <= 1'b0; addend <= ACC_W'(d1);
          st <= S_M0_C1;
        end
        S_M0_C1: begin
          acc_add <= !tl2; acc_dbl <= 1'b0; addend <= ACC_W'(d2);
          st <= S_M0_C2;
        end
        S_M0_C2: begin  // M0 = 2 (d1 E20 + d2 E01) + D
          acc_add <= 1'b1; acc_dbl <= 1'b1; addend <= ACC_W'(den[34:1]);
          st <= S_M0_D;
        end
        S_M0_D: if (!acc_add && div_free) begin
          div_go <= 1'b1; div_pending <= 1'b1; div_field <= 2'd0;
          st <= S_ANEXT;
        end
        S_XL: begin  // constant plane: the three zero steps
          pw_en <= 1'b1; pw_attr <= ak; pw_q <= 32'd0; pw_r <= 35'd0;
          pw_field <= (pw_field == 2'd0) ? 2'd1 : pw_field + 2'd1;
          if (pw_field == 2'd2) st <= ret;
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
