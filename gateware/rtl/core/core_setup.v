// Triangle setup (docs/protocol.md sections 8 and 9), a sequencer around one multiplier and one
// exact divider:
//   1. area D = (X1-X0)(Y2-Y0) - (X2-X0)(Y1-Y0); D = 0 draws nothing; D < 0 exchanges P1 and P2;
//   2. bounding box of the sample points inside the vertices, clipped to the clip rectangle;
//   3. the three edge functions E12, E20, E01 at the box origin's sample point with their
//      top-left biases, and their per-pixel steps;
//   4. per interpolated attribute, the exact plane stepper of section 9: with
//      Gx = d1*dy20 + d2*dy01 and Gy = d1*dx20 + d2*dx01 (d = a - a0, dyab = Yb - Ya),
//      M(x, y) = 2(d1*E20 + d2*E01) + D is M0 = D + 2(Gy*oy - Gx*ox) at the origin (ox, oy: the
//      origin's sample point minus P0) and changes by Mx = -32 Gx per pixel right, My = 32 Gy per
//      pixel down; the value there is a0 + floor(M / 2D). Each M is split by the divider into
//      (quotient, remainder) of 2D; a step left is the negated step right, renormalised.
// The vertex inputs are read while `start` is held (the command port keeps them stable until
// the core accepts the command); results are held until the next start.
module core_setup (
    input  wire         clk,
    input  wire         rst,
    input  wire         start,        // level: a triangle waits on the command port
    output reg          busy,
    output reg          done,         // pulse: results valid; `draw` says whether to rasterise
    input  wire [183:0] v0,
    input  wire [183:0] v1,
    input  wire [183:0] v2,
    input  wire [10:0]  clip_x0,
    input  wire [10:0]  clip_y0,
    input  wire [10:0]  clip_x1,      // exclusive, already min(SCISSOR.X1, WIDTH)
    input  wire [10:0]  clip_y1,
    input  wire [7:0]   need,         // attributes to set up: R G B A Z S T Q (bit 0 = R)
    output reg          draw,
    // edges E12, E20, E01: value (biased) at the origin pixel, step right, step down
    output reg  signed [35:0] e0, e1, e2,
    output reg  signed [21:0] ex0, ex1, ex2,
    output reg  signed [21:0] ey0, ey1, ey2,
    output reg  [10:0]  box_x0, box_y0, box_x1, box_y1,  // inclusive-exclusive
    output reg  [34:0]  den,          // 2D
    // one plane per pulse of plane_we (attribute plane_id)
    output reg          plane_we,
    output reg  [2:0]   plane_id,
    output reg  [31:0]  pq0, pqx, pqxl, pqy,
    output reg  [34:0]  pr0, prx, prxl, pry
);
  // ---- vertices after the exchange of section 8.1 ----
  reg flip;
  wire [183:0] w0 = v0;
  wire [183:0] w1 = flip ? v2 : v1;
  wire [183:0] w2 = flip ? v1 : v2;
  wire signed [15:0] x0 = w0[15:0], y0 = w0[31:16];
  wire signed [15:0] x1 = w1[15:0], y1 = w1[31:16];
  wire signed [15:0] x2 = w2[15:0], y2 = w2[31:16];

  // kick order, for the area
  wire signed [16:0] kdx01 = $signed({v1[15], v1[15:0]}) - $signed({v0[15], v0[15:0]});
  wire signed [16:0] kdy01 = $signed({v1[31], v1[31:16]}) - $signed({v0[31], v0[31:16]});
  wire signed [16:0] kdx02 = $signed({v2[15], v2[15:0]}) - $signed({v0[15], v0[15:0]});
  wire signed [16:0] kdy02 = $signed({v2[31], v2[31:16]}) - $signed({v0[31], v0[31:16]});

  function signed [16:0] diff16(input signed [15:0] b, input signed [15:0] a);
    diff16 = $signed({b[15], b}) - $signed({a[15], a});
  endfunction
  // edge k: a -> b = (1 -> 2), (2 -> 0), (0 -> 1)
  wire signed [16:0] dx12 = diff16(x2, x1), dy12 = diff16(y2, y1);
  wire signed [16:0] dx20 = diff16(x0, x2), dy20 = diff16(y0, y2);
  wire signed [16:0] dx01 = diff16(x1, x0), dy01 = diff16(y1, y0);

  function bias_zero(input signed [15:0] xa, input signed [15:0] ya, input signed [15:0] xb,
                     input signed [15:0] yb);
    bias_zero = (ya == yb && xb > xa) || (yb < ya);  // top or left edge
  endfunction

  // ---- bounding box (combinational on the exchanged vertices) ----
  function signed [15:0] min3(input signed [15:0] a, input signed [15:0] b, input signed [15:0] c);
    min3 = (a < b) ? ((a < c) ? a : c) : ((b < c) ? b : c);
  endfunction
  function signed [15:0] max3(input signed [15:0] a, input signed [15:0] b, input signed [15:0] c);
    max3 = (a > b) ? ((a > c) ? a : c) : ((b > c) ? b : c);
  endfunction
  wire signed [15:0] mnx = min3(x0, x1, x2), mxx = max3(x0, x1, x2);
  wire signed [15:0] mny = min3(y0, y1, y2), mxy = max3(y0, y1, y2);
  // first pixel whose sample 16p + 8 >= min: ceil((min - 8) / 16) = (min + 7) >> 4
  wire signed [16:0] fx0 = ($signed({mnx[15], mnx}) + 17'sd7) >>> 4;
  wire signed [16:0] fy0 = ($signed({mny[15], mny}) + 17'sd7) >>> 4;
  // one past the last pixel whose sample <= max: floor((max - 8) / 16) + 1
  wire signed [16:0] fx1 = (($signed({mxx[15], mxx}) - 17'sd8) >>> 4) + 17'sd1;
  wire signed [16:0] fy1 = (($signed({mxy[15], mxy}) - 17'sd8) >>> 4) + 17'sd1;
  wire signed [16:0] cx0 = $signed({6'b0, clip_x0}), cx1 = $signed({6'b0, clip_x1});
  wire signed [16:0] cy0 = $signed({6'b0, clip_y0}), cy1 = $signed({6'b0, clip_y1});
  wire signed [16:0] bx0 = fx0 > cx0 ? fx0 : cx0;
  wire signed [16:0] bx1 = fx1 < cx1 ? fx1 : cx1;
  wire signed [16:0] by0 = fy0 > cy0 ? fy0 : cy0;
  wire signed [16:0] by1 = fy1 < cy1 ? fy1 : cy1;
  wire box_empty = (bx0 >= bx1) || (by0 >= by1);

  // ---- the multiplier: P = A * B, registered ----
  reg  signed [50:0] mul_a;
  reg  signed [17:0] mul_b;
  reg  signed [68:0] mul_p;
  always @(posedge clk) mul_p <= mul_a * mul_b;

  // ---- the divider ----
  reg                div_start;
  reg  signed [71:0] div_num;
  wire               div_done;
  wire [31:0]        div_q;
  wire [34:0]        div_r;
  /* verilator lint_off PINCONNECTEMPTY */
  core_divider #(.NW(72), .DW(35), .QW(32)) divider (
      .clk(clk), .rst(rst), .start(div_start), .num(div_num), .den(den),
      .busy(), .done(div_done), .quo(div_q), .rem(div_r));
  /* verilator lint_on PINCONNECTEMPTY */

  // ---- attribute values of the exchanged vertices (33-bit signed) ----
  function signed [32:0] attr(input [183:0] v, input [2:0] k);
    case (k)
      3'd0: attr = {25'b0, v[87:80]};
      3'd1: attr = {25'b0, v[79:72]};
      3'd2: attr = {25'b0, v[71:64]};
      3'd3: attr = {25'b0, v[63:56]};
      3'd4: attr = {9'b0, v[55:32]};
      3'd5: attr = {v[151], v[151:120]};
      3'd6: attr = {v[183], v[183:152]};
      default: attr = {1'b0, v[119:88]};
    endcase
  endfunction
  reg  [2:0] ak;  // attribute being set up
  wire signed [32:0] a0 = attr(w0, ak), a1 = attr(w1, ak), a2 = attr(w2, ak);
  wire signed [33:0] d1w = $signed({a1[32], a1}) - $signed({a0[32], a0});
  wire signed [33:0] d2w = $signed({a2[32], a2}) - $signed({a0[32], a0});
  // |d| < 2^32: 33 bits hold it
  wire signed [32:0] d1 = d1w[32:0], d2 = d2w[32:0];
  wire flat_attr = (d1 == 0) && (d2 == 0);

  // ---- sequencer ----
  localparam [3:0] S_IDLE = 4'd0, S_AREA = 4'd1, S_BOX = 4'd2, S_EDGE = 4'd3, S_ANEXT = 4'd4,
                   S_AMUL = 4'd5, S_DIVX = 4'd6, S_DIVY = 4'd7, S_DIV0 = 4'd8, S_AOUT = 4'd9,
                   S_END = 4'd10;
  reg [3:0]  st;
  reg [3:0]  step;
  reg signed [69:0] acc;
  reg signed [34:0] dsign;     // D with its sign
  reg signed [50:0] gx, gy;
  reg signed [17:0] ox, oy;    // origin sample point minus P0 (1/16 pixel)
  reg        [7:0]  todo;      // attributes left
  reg               div_wait;

  wire signed [17:0] sx = $signed({3'b0, box_x0, 4'b1000});  // 16 * x + 8
  wire signed [17:0] sy = $signed({3'b0, box_y0, 4'b1000});

  always @(posedge clk) begin
    done      <= 1'b0;
    plane_we  <= 1'b0;
    div_start <= 1'b0;
    if (rst) begin
      st   <= S_IDLE;
      busy <= 1'b0;
      draw <= 1'b0;
      flip <= 1'b0;
    end else begin
      case (st)
        S_IDLE: if (start && !busy) begin
          busy  <= 1'b1;
          flip  <= 1'b0;
          step  <= 4'd0;
          todo  <= need;
          mul_a <= 51'(kdx01);
          mul_b <= 18'(kdy02);
          st    <= S_AREA;
        end
        S_AREA: begin
          step <= step + 1'b1;
          case (step)
            4'd0: begin mul_a <= 51'(kdx02); mul_b <= 18'(kdy01); end
            4'd1: acc <= 70'(mul_p);
            default: begin
              dsign <= 35'(acc - 70'(mul_p));
              st    <= S_BOX;
              step  <= 4'd0;
            end
          endcase
        end
        S_BOX: begin
          if (step == 4'd0) begin
            if (dsign == 0) begin
              draw <= 1'b0;
              st   <= S_END;
            end else begin
              flip <= dsign < 0;
              den  <= (dsign < 0) ? 35'(-(dsign <<< 1)) : 35'(dsign <<< 1);
              step <= 4'd1;
            end
          end else begin
            // flip has settled: the box and the first edge product use the exchanged vertices
            if (box_empty) begin
              draw <= 1'b0;
              st   <= S_END;
            end else begin
              box_x0 <= bx0[10:0];
              box_x1 <= bx1[10:0];
              box_y0 <= by0[10:0];
              box_y1 <= by1[10:0];
              ex0 <= -($signed({{5{dy12[16]}}, dy12}) <<< 4);
              ex1 <= -($signed({{5{dy20[16]}}, dy20}) <<< 4);
              ex2 <= -($signed({{5{dy01[16]}}, dy01}) <<< 4);
              ey0 <= $signed({{5{dx12[16]}}, dx12}) <<< 4;
              ey1 <= $signed({{5{dx20[16]}}, dx20}) <<< 4;
              ey2 <= $signed({{5{dx01[16]}}, dx01}) <<< 4;
              st   <= S_EDGE;
              step <= 4'd0;
            end
          end
        end
        S_EDGE: begin
          // E_ab(s) = dx_ab * (sy - Ya) - dy_ab * (sx - Xa), products issued in pairs
          step <= step + 1'b1;
          case (step)
            4'd0: begin mul_a <= 51'(dx12); mul_b <= sy - 18'(y1); end
            4'd1: begin mul_a <= 51'(dy12); mul_b <= sx - 18'(x1); end
            4'd2: begin acc <= 70'(mul_p); mul_a <= 51'(dx20); mul_b <= sy - 18'(y2); end
            4'd3: begin
              e0 <= 36'(acc - 70'(mul_p)) - (bias_zero(x1, y1, x2, y2) ? 36'sd0 : 36'sd1);
              mul_a <= 51'(dy20); mul_b <= sx - 18'(x2);
            end
            4'd4: begin acc <= 70'(mul_p); mul_a <= 51'(dx01); mul_b <= sy - 18'(y0); end
            4'd5: begin
              e1 <= 36'(acc - 70'(mul_p)) - (bias_zero(x2, y2, x0, y0) ? 36'sd0 : 36'sd1);
              mul_a <= 51'(dy01); mul_b <= sx - 18'(x0);
            end
            4'd6: acc <= 70'(mul_p);
            default: begin
              e2 <= 36'(acc - 70'(mul_p)) - (bias_zero(x0, y0, x1, y1) ? 36'sd0 : 36'sd1);
              ox <= sx - 18'(x0);
              oy <= sy - 18'(y0);
              draw <= 1'b1;
              st   <= S_ANEXT;
            end
          endcase
        end
        S_ANEXT: begin
          // next attribute to set up, lowest index first
          if (todo == 8'd0) begin
            st <= S_END;
          end else begin
            ak   <= todo[0] ? 3'd0 : todo[1] ? 3'd1 : todo[2] ? 3'd2 : todo[3] ? 3'd3 :
                    todo[4] ? 3'd4 : todo[5] ? 3'd5 : todo[6] ? 3'd6 : 3'd7;
            todo <= todo & (todo - 8'd1);
            step <= 4'd0;
            st   <= S_AMUL;
          end
        end
        S_AMUL: begin
          step <= step + 1'b1;
          case (step)
            4'd0: begin
              if (flat_attr) begin
                // constant: a0 everywhere (M = D at every pixel: quotient 0, remainder D)
                pq0 <= a0[31:0]; pr0 <= den >> 1;
                pqx <= 32'd0; prx <= 35'd0; pqxl <= 32'd0; prxl <= 35'd0;
                pqy <= 32'd0; pry <= 35'd0;
                st  <= S_AOUT;
              end else begin
                mul_a <= 51'(d1); mul_b <= 18'(dy20);
              end
            end
            4'd1: begin mul_a <= 51'(d2); mul_b <= 18'(dy01); end
            4'd2: begin acc <= 70'(mul_p); mul_a <= 51'(d1); mul_b <= 18'(dx20); end
            4'd3: begin gx <= 51'(acc + 70'(mul_p)); mul_a <= 51'(d2); mul_b <= 18'(dx01); end
            4'd4: begin acc <= 70'(mul_p); mul_a <= gx; mul_b <= ox; end
            4'd5: begin gy <= 51'(acc + 70'(mul_p)); end
            4'd6: begin acc <= 70'(mul_p); mul_a <= gy; mul_b <= oy; end  // acc = Gx*ox
            4'd7: begin end
            default: begin
              // M0 = D + 2 (Gy*oy - Gx*ox); divisions follow: Mx, My, M0
              acc       <= 70'(mul_p) - acc;
              div_num   <= -(72'(gx) <<< 5);
              div_start <= 1'b1;
              st        <= S_DIVX;
            end
          endcase
        end
        S_DIVX: if (div_done) begin
          pqx <= div_q;
          prx <= div_r;
          // a step left is -(qx*2D + rx): (-qx - 1, 2D - rx), or (-qx, 0) when rx = 0
          pqxl <= (div_r == 0) ? -div_q : ~div_q;
          prxl <= (div_r == 0) ? 35'd0 : den - div_r;
          div_num   <= 72'(gy) <<< 5;
          div_start <= 1'b1;
          st        <= S_DIVY;
        end
        S_DIVY: if (div_done) begin
          pqy <= div_q;
          pry <= div_r;
          div_num   <= (72'(acc) <<< 1) + 72'(den[34:1]);
          div_start <= 1'b1;
          st        <= S_DIV0;
        end
        S_DIV0: if (div_done) begin
          pq0 <= a0[31:0] + div_q;
          pr0 <= div_r;
          st  <= S_AOUT;
        end
        S_AOUT: begin
          plane_we <= 1'b1;
          plane_id <= ak;
          st       <= S_ANEXT;
        end
        default: begin  // S_END
          done <= 1'b1;
          busy <= 1'b0;
          st   <= S_IDLE;
        end
      endcase
    end
  end
endmodule
