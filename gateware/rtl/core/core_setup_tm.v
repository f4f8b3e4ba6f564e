// Triangle setup of the small profile (iCE40): the same integers as core_setup (docs/protocol.md
// sections 8 and 9, exchange by negation, see core_setup), computed by a sequencer around one
// 62-bit accumulator whose operands come from block RAM, running a program that is block RAM
// too (core_setup_prog, written by gen_setup_prog.py, which lists the steps).
//
// Why: on the UP5K the logic of a setup with its operands on wires was multiplexers (a 36-bit
// operand bus of 14 sources, the multiplier's operand and bit selects, the attribute and vertex
// selects, about 600 LUT4 of 1,900). Here every operand is a word of a small RAM: the vertex
// fields are written once through one 25-bit field multiplexer, differences, products and edge
// values are computed from RAM reads and written back, so choosing an operand is choosing an
// address. The results the rasteriser holds (dx, dy, 2|D|, edge values) are loaded from the
// accumulator as side effects of writing their RAM words.
//
// Datapath: acc <- (clr ? 0 : dbl ? 2 acc : acc) + (use ? m : 0) ^ neg + cin, with m the word
// read from the operand RAM. Accumulator operations ("uops") are issued with a read address and
// act two cycles later, when the RAM has answered; a uop may instead write acc to a RAM word,
// or start the divider with acc as numerator. A uop that writes a word is issued at least two
// cycles before one that reads it (the sequencer waits for an empty pipeline where needed).
// Multiplies a1*m1 +/- a2*m2 are Horner's rule, most significant bit first, two cycles per
// bit: m1 and m2 alternate on the operand RAM's read port while a copy of the RAM (the a
// operands' low 25 bits, read a cycle ahead of m: below) gives the bit of a1 or a2; the value
// at the origin adds a third product, A0 * |D| (three cycles per bit), so that its quotient is
// a0 plus the plane's and no adder or register holds a0 after the division. The one divider
// takes a plane's three numerators in turn; a multiply overlaps the previous division. The
// origin index y0 * width + x_start is a DSP multiply.
//
// Instruction (32 bits): [4:0] addr (read address of a uop, or the word a uop or the field
// multiplexer writes, or m1 of a multiply), [7:5] accumulator op, [8] w (the uop writes acc to
// addr), [9] wf (the field multiplexer writes addr), [11:10] wait (0 none, 1 pipeline empty, 2
// multiply fetched, 3 pipeline empty and the divider free), [13:12] cond (uops: 0 always, 1-3
// only when edge 0-2's bias is -1; act div: the plane field), [17:14] act, [24:18] tgt (branch
// target; m2 of a multiply; the field select of wf), [26:25] multiply pair, [28:27] its sign.
module core_setup_tm #(
    parameter integer IDX_W = 17,
    parameter integer DEPTH = 1   // 0: no depth buffer (CAPS2): no Z plane, colour numerators only
) (
    input  wire         clk,
    input  wire         rst,
    input  wire         start,        // pulse: a triangle (or a clear) waits on the command port
    input  wire         rect,         // a clear: the clip rectangle only
    output wire         busy,
    output reg          done,         // pulse: results valid; `draw` says whether to rasterise
    output reg          draw,
    output wire [3:0]   vp_addr,      // the soc's vertex read port: {vertex, word}; words are
    input  wire [31:0]  vp_data,      // 0 {Y, X}, 1 Z, 2 COLOR (RGBA, R in [31:24]); a clock later
    input  wire [3:0]   vp_idle,      // the port's address while idle (the value the core copies)
    input  wire [10:0]  clip_x0,
    input  wire [10:0]  clip_y0,
    input  wire [10:0]  clip_x1,      // exclusive, already min(SCISSOR.X1, WIDTH)
    input  wire [10:0]  clip_y1,
    input  wire [10:0]  width,        // FB_FORMAT.WIDTH
    input  wire [4:0]   need,         // planes to set up: R G B A Z (bit 0 = R)
    output reg  signed [16:0] dx0, dx1, dx2, dy0, dy1, dy2,
    output reg          flip,
    output reg  [2:0]   e_we,         // the rasteriser loads e_data into its edge registers
    output wire signed [35:0] e_data,
    output reg  [10:0]  box_x0, box_y0, box_xl, box_y1, x_start,
    output reg  [IDX_W-1:0] origin_idx,
    output wire [34:0]  den,          // |2D| (held inverted, den_n below)
    output reg          pw_en,
    output reg  [2:0]   pw_attr,
    output reg  [1:0]   pw_field,
    output wire [23:0]  pw_q,
    output wire [34:0]  pw_r
);
  // Without S, T, Q: |M0| < 2^60 (see core_setup), and a0 2D < 2^58 is added to it (below),
  // so 62 bits; RAM words are 36 bits (the biased edge values), a operands at most 25 (Z).
  // Without a depth buffer the widest value is a colour numerator, |M0| < 2^44 (the divider
  // below), so 46 bits. The accumulator only adds, subtracts and shifts left (a multiply is
  // MSB-first), so a wider intermediate sum wraps and still ends exact; its sign and zero tests
  // are of D and the edges (below 2^36).
  localparam integer ACC_W = (DEPTH != 0) ? 62 : 46;
  localparam integer MW = 36;
  localparam integer AW = 25;

  // ---------------------------------------------------------------- operand RAM words
  // (gen_setup_prog.py): vertex i X at 2i, Y at 2i + 1; DX0-2, DY0-2; |D|; the sample point
  // minus an edge's start vertex (EY, EX); the biased edge values E0-2; the attribute's A0-2 and
  // D1 = A1 - A0, D2 = A2 - A0. Reads of 26-28 are the top vertex's Y and X, the bottom one's Y.
  localparam [4:0] R_DX0 = 5'd6, R_DX1 = 5'd7, R_DX2 = 5'd8, R_DY0 = 5'd9, R_DY1 = 5'd10,
                   R_DY2 = 5'd11, R_ABSD = 5'd12, R_EY = 5'd14, R_E0 = 5'd18,
                   R_E1 = 5'd19, R_E2 = 5'd20, R_D1 = 5'd21, R_YTOP = 5'd26,
                   R_XTOP = 5'd27, R_YBOT = 5'd28;
  function [4:0] r_x(input [1:0] i);
    r_x = {2'b0, i, 1'b0};
  endfunction
  function [4:0] r_y(input [1:0] i);
    r_y = {2'b0, i, 1'b1};
  endfunction

  (* ram_style = "block", no_rw_check *) reg [MW-1:0] mem_m[0:31];
  (* ram_style = "block", no_rw_check *) reg [AW-1:0] mem_a[0:31];
  reg  [MW-1:0] rd;     // mem_m[raddr of the previous cycle]
  reg  [AW-1:0] rda;    // mem_a[the a operand's address of the previous cycle]

  // ---------------------------------------------------------------- field multiplexer
  // fsel = {kind, vertex}: kind 0 X, 1 Y, 2 the attribute ak, 3 the sample point (vertex 0:
  // 16 y0 + 8, 1: 16 x_start + 8). The vertex fields come through the soc's read port: an
  // instruction that writes one waits a clock for it (fw_ok). Idle, the port reads what the
  // core copies when it accepts the command (vp_idle: v0's COLOR, CLEAR_COLOR or CLEAR_DEPTH).
  wire [31:0] I;        // the instruction (registered block RAM read of pc_next)
  wire [3:0] fsel = I[21:18];
  reg  [2:0] ak;
  reg  [6:0] pc;
  reg        fw_ok;     // vp_data is the word the instruction's field select names
  // ak = 4 is Z. Without a depth buffer no Z plane is set up (need[4] = 0, so A_NEXTA chooses 4
  // only when no attribute is left, and branches away in the same instruction): the attribute
  // field, the vertex word and the multiply's bit count are a colour's (fit9, docs/gateware.md)
  wire       ak_z = (DEPTH != 0) && ak[2];
  assign vp_addr = (pc == 7'd0) ? vp_idle : {fsel[1:0], !fsel[3] ? 2'd0 : ak_z ? 2'd1 : 2'd2};
  reg  [AW-1:0] fld;
  always @(*) begin
    case (fsel[3:2])
      2'd0: fld = AW'($signed(vp_data[15:0]));
      2'd1: fld = AW'($signed(vp_data[31:16]));
      2'd2: if (ak_z) fld = AW'(vp_data[23:0]);
            else case (ak[1:0])
              2'd0: fld = AW'(vp_data[31:24]);
              2'd1: fld = AW'(vp_data[23:16]);
              2'd2: fld = AW'(vp_data[15:8]);
              default: fld = AW'(vp_data[7:0]);
            endcase
      default: fld = AW'({fsel[0] ? x_start : box_y0, 4'b1000});
    endcase
  end

  // ---------------------------------------------------------------- program
  wire [4:0] i_addr = I[4:0];
  wire [2:0] i_op   = I[7:5];
  wire       i_w    = I[8];
  wire       i_wf   = I[9];
  wire [1:0] i_wait = I[11:10];
  wire [1:0] i_cond = I[13:12];
  wire [3:0] i_act  = I[17:14];
  wire [6:0] i_tgt  = I[24:18];
  wire [1:0] i_pair = I[26:25];
  wire [1:0] i_neg  = I[28:27];
  wire unused_i = &{1'b0, I[31:29]};
  localparam [3:0] A_JMP = 4'd1, A_BRZERO = 4'd2, A_BRNNEG = 4'd3, A_FLIP = 4'd4, A_FY0 = 4'd5,
                   A_XT = 4'd6, A_BOX = 4'd7, A_ORG = 4'd8, A_BRRECT = 4'd9, A_TODO = 4'd10,
                   A_NEXTA = 4'd11, A_DIV = 4'd12, A_DONE = 4'd13, A_NODRAW = 4'd14;
  localparam [1:0] P_DX = 2'd1, P_E = 2'd2;
  wire [6:0] pc_next;
  core_setup_prog prog (.clk(clk), .addr(pc_next), .word(I));
  assign busy = (pc != 7'd0);

  // ---------------------------------------------------------------- uop pipeline
  // op = {clr, dbl, use, neg, cin}
  function [4:0] op_bits(input [2:0] o);
    case (o)
      3'd1: op_bits = 5'b10100;   // load
      3'd2: op_bits = 5'b00100;   // add
      3'd3: op_bits = 5'b00111;   // sub
      3'd4: op_bits = 5'b10111;   // load negated
      3'd5: op_bits = 5'b00010;   // minus one
      3'd6: op_bits = 5'b01000;   // double
      3'd7: op_bits = 5'b01100;   // double and add
      default: op_bits = 5'b00000;
    endcase
  endfunction
  reg  [4:0] ra;                  // read address of the uop issued last cycle
  reg        v1_, w1, dv1;        // stage 1: valid, write acc to wa1, start the divider
  reg  [4:0] op1, wa1;
  reg        v2_, w2, dv2;        // stage 2: acts this cycle, with rd
  reg  [4:0] wa2;

  // multiply: fetch (fr, fph, fk) runs a cycle ahead of execution (xr); phase 2 is the third
  // product of the value at the origin, A0 * |D| (A0 is the word after D2). fk is the bit of a
  // fetched (mbits, the top one, down to 0).
  reg        fr, xr, three;
  reg  [1:0] fph;
  reg  [4:0] fk, mbits;
  reg  [4:0] m1a, m2a, a1a;
  reg        mneg, msub;
  wire       quiet = !fr && !xr && !v1_ && !v2_;

  // The a operand's word is read a cycle ahead of the fetch that takes its bit (in the issue
  // cycle the pair's first word, then the word of the next phase), so that the bit is picked
  // from the RAM's output into ctl's register in the fetch cycle: the accumulator's control
  // is flip-flops only (fmax-setup, docs/gateware.md; it was xk -> the bit select -> ctl ->
  // b_in -> the carry chain, 48 ns). Safe because a multiply issues only on an empty pipeline
  // (wait "quiet", gen_setup_prog.py) and nothing writes the RAM while it fetches.
  wire       f_last = (fph == {three, !three});
  wire [1:0] fph_n = f_last ? 2'd0 : fph + 2'd1;
  wire [4:0] pair_a = (i_pair == P_DX) ? R_DX1 : (i_pair == P_E) ? R_EY : R_D1;
  wire [4:0] raddr = !fr ? ra : (fph == 2'd0) ? m1a : fph[0] ? m2a : R_ABSD;
  wire [4:0] aaddr = fr ? a1a + {3'd0, fph_n} : pair_a;  // a2 (a3) is the word after a1 (a2)
  reg  [ACC_W-1:0] acc;
  wire signed [ACC_W-1:0] acc_s = $signed(acc);
  assign e_data = acc_s[35:0];
  reg        adv;                 // the instruction completes this cycle
  wire       wr_en = w2 || (adv && i_wf);
  wire [4:0] waddr = w2 ? wa2 : i_addr;
  wire [MW-1:0] wdata = w2 ? acc[MW-1:0] : MW'($signed(fld));
  always @(posedge clk) begin
    if (wr_en) begin
      mem_m[waddr] <= wdata;
      mem_a[waddr] <= wdata[AW-1:0];
    end
    rd  <= mem_m[raddr];
    rda <= mem_a[aaddr];
  end

  // ---------------------------------------------------------------- accumulator
  // ctl = {clr, dbl, use, neg, cin} of the cycle, decided a cycle ahead from the fetch (a
  // multiply's bit) or from stage 1's uop
  reg  [4:0] ctl;
  wire       f_msb = (fk == mbits);
  wire       f_neg = mneg ^ f_msb ^ (fph[0] & msub);
  always @(posedge clk)
    ctl <= rst ? 5'd0 : fr ? {f_msb && fph == 2'd0, fph == 2'd0, rda[fk], f_neg, f_neg} :
                        v1_ ? op1 : 5'd0;
  wire [ACC_W-1:0] a_in = ctl[4] ? {ACC_W{1'b0}} : ctl[3] ? acc << 1 : acc;
  wire [ACC_W-1:0] b_in = (ctl[2] ? ACC_W'($signed(rd)) : {ACC_W{1'b0}}) ^ {ACC_W{ctl[1]}};
  always @(posedge clk) acc <= a_in + b_in + {{(ACC_W-1){1'b0}}, ctl[0]};

  // ---------------------------------------------------------------- box (from RAM reads)
  // From signs and the dy == 0 flags only (no comparators): no edge is (0, 0) once D != 0, so
  // where dy = 0 the sign of dx says dx > 0 or dx < 0.
  reg  [2:0] dyz;  // dy_k == 0
  wire [2:0] sy_ = {dy2[16], dy1[16], dy0[16]}, sx_ = {dx2[16], dx1[16], dx0[16]};
  // index of the smallest / largest of (p0, p1, p2) from the signs and zeros of d10, d21, d02
  // (dy2, dy0, dy1)
  wire [1:0] top = (!sy_[2] && (sy_[1] || dyz[1])) ? 2'd0 : (sy_[2] && !sy_[0]) ? 2'd1 : 2'd2;
  wire [1:0] bot = ((sy_[2] || dyz[2]) && !sy_[1]) ? 2'd0 :
                   (!sy_[2] && !dyz[2] && (sy_[0] || dyz[0])) ? 2'd1 : 2'd2;
  // top-left rule on the edge as drawn (reversed when exchanged): bias 0, otherwise -1
  wire [2:0] tlv = flip ? (dyz & sx_) | (~dyz & ~sy_) : (dyz & ~sx_) | (~dyz & sy_);
  wire tl0 = tlv[0], tl1 = tlv[1], tl2 = tlv[2];
  reg        box2;  // rd is the bottom vertex's Y
  wire signed [15:0] rc = $signed(rd[15:0]);
  // samples 16p + 8 inside [min, max]: p from (min + 7) >> 4 to (max + 8) >> 4, exclusive
  // as (rc >> 4) + the carry out of rc's low four bits (+ 8: rc[3]; + 7: rc[3:0] >= 9), an
  // incrementer instead of a 17-bit adder whose low bits are dropped
  wire        fy_c = rc[3] && (box2 || rc[2:0] != 3'd0);
  wire signed [12:0] fy = $signed({rc[15], rc[15:4]}) + $signed({12'd0, fy_c});
  // Each clamped value goes straight into its output register when its vertex field is read
  // (A_FY0: the first row, rd the top vertex's Y; A_XT: the first column, rd its X; A_BOX: the
  // row end, rd the bottom vertex's Y), so no register holds the unclamped ones. by0 is in
  // [0, 2048]: 2048 lies below every clip rectangle (y0_in_clip is then 0).
  wire signed [12:0] xt = 13'(rc >>> 4);
  wire signed [12:0] cx0 = $signed({2'b0, clip_x0});
  wire signed [12:0] cy0 = $signed({2'b0, clip_y0}), cy1 = $signed({2'b0, clip_y1});
  // Idle (pc = 0), the clamps give the clip rectangle itself, which a clear (rect) loads at its
  // start through the same registers' inputs: box_y0, x_start and box_y1 have one source each,
  // not a second one for clears (fit9, docs/gateware.md)
  wire        idle = (pc == 7'd0);
  // The comparisons with fy and with rc are sign tests of sums with their complements (x - y - 1
  // = x + ~y), ~fy and ~rc shared by all of them: written as x < y each one inverted its other
  // operand (the clip rectangle, box_y0, box_xl: flip-flops, or clip_y1) into its carry chain
  // through LUTs of its own, a logic cell per bit and comparison (fit10, docs/gateware.md).
  // 14 and 18-bit sums: no overflow. Where a clamp's test becomes >= instead of >, the two
  // values it chooses between are equal.
  wire signed [12:0] nfy = ~fy;
  wire signed [15:0] nrc = ~rc;
  wire signed [12:0] nxt = 13'(nrc >>> 4);  // ~xt
  wire signed [13:0] s_fy0 = $signed({cy0[12], cy0}) + $signed({nfy[12], nfy});  // cy0 - fy - 1
  wire signed [13:0] s_fy1 = $signed({cy1[12], cy1}) + $signed({nfy[12], nfy});  // cy1 - fy - 1
  wire signed [13:0] s_x0 = $signed({cx0[12], cx0}) + $signed({nxt[12], nxt});   // cx0 - xt - 1
  wire signed [13:0] s_xl = $signed({3'b0, box_xl}) + $signed({nxt[12], nxt});   // xl - xt - 1
  wire        fy_ge_cy0 = s_fy0[13];   // fy >= cy0
  wire        fy_in_clip = !s_fy1[13]; // fy < cy1
  wire        xt_lt_cx0 = !s_x0[13];   // xt < cx0
  wire        xt_ge_xl = s_xl[13];     // xt >= box_xl
  wire        unused_s = &{1'b0, xt[12:11], s_fy0[12:0], s_fy1[12:0], s_x0[12:0], s_xl[12:0]};
  wire signed [12:0] by0 = (fy_ge_cy0 && !idle) ? fy : cy0;
  wire signed [12:0] by1 = (fy_in_clip && !idle) ? fy : cy1;
  wire        unused_by0 = &{1'b0, by0[12:11]};  // by0 >= 0; by0 = 2048 fails y0_in_clip
  wire        unused_by1 = &{1'b0, by1[12:11]};  // stored only when box_y0 < by1 <= cy1 < 2048
  // A_BOX: some row to walk, box_y0 < min(fy, cy1). The clip half is latched at A_FY0, two
  // instructions before A_BOX, as the top's fy < cy1 (box_y0 = max(fy, cy0) < cy1 exactly then,
  // cy0 < cy1 being a setup's condition; by0 = 2048 fails it too), by1's own comparator: no
  // comparator of box_y0 with cy1 (fit10, docs/gateware.md), and the branch does not wait for
  // the scissor's clamp and the fy clamp in series.
  // The fy half without fy's adder (A_BOX reads with box2 set, fy = (y + 8) >> 4):
  // box_y0 < floor((y + 8) / 16) <=> 16 (box_y0 + 1) <= y + 8 <=> y >= 16 box_y0 + 8, one
  // comparison of rd's Y with a concatenation, so the branch into the program ROM's address
  // has one carry chain instead of two (fmax-setup, docs/gateware.md); since fit10 the chain
  // takes ~rc, one LUT after the RAM's output (shared with the X clamp's comparisons).
  reg         y0_in_clip;
  // rc >= 16 box_y0 + 8 <=> 16 box_y0 + 8 + ~rc < 0
  wire signed [17:0] s_rows = $signed({3'b0, box_y0, 4'b1000}) + $signed({nrc[15], nrc[15], nrc});
  wire        rows = y0_in_clip && s_rows[17];
  wire        unused_rows = &{1'b0, s_rows[16:0]};
  // box_xl (the last column, clip_x1 - 1, loaded at the start) is the clamp's upper bound too
  wire [10:0] xs = (xt_lt_cx0 || idle) ? clip_x0 : xt_ge_xl ? box_xl : xt[10:0];
  wire [4:0] r_sel = (i_addr == R_YTOP) ? r_y(top) : (i_addr == R_XTOP) ? r_x(top) :
                     (i_addr == R_YBOT) ? r_y(bot) : i_addr;

  // ---------------------------------------------------------------- divider and plane writes
  // den is held inverted: its readers (the divider's trial - den, the steppers' t - den) are
  // subtractors, whose carry chains take it inverted. Held as it is, every bit cost an inverter
  // LUT beside a flip-flop without one (two logic cells); inverted, the inverter is the
  // flip-flop's own LUT, and the readers' inversion of ~den_n cancels (fit10, docs/gateware.md).
  reg  [34:0] den_n;
  assign den = ~den_n;
  reg         dv_pend, dv_rdy, xl_next;
  reg  [1:0]  dv_field;
  reg  [2:0]  dv_attr;
  wire        dv_done, dv_neg;
  wire [31:0] dv_q;
  wire [34:0] dv_r;
  // The steps right and left need r and den - 1 - r (the other one for a negative numerator,
  // core_divider): the divider complements its remainder in place, through its own subtractor,
  // in the clock before the write that needs the other one (dv_rdy with a negative numerator:
  // before the first write; xl_next: between the step right and the step left), so pw_r is the
  // remainder register itself, without an adder and a multiplexer for rem_c (fit10,
  // docs/gateware.md)
  wire        dv_comp = (dv_rdy && dv_neg) || xl_next;
  /* verilator lint_off PINCONNECTEMPTY */
  // colour numerators: |d| < 2^8, |e| < 2^33, |D| < 2^33, a0 < 2^8, so |M0| = |2(d1 e1 + d2 e2 + a0
  // |D|) + ...| < 2^44 and the steps |32(d1 dy + d2 dy)| < 2^31: 45 numerator bits, 46 cycles a
  // division instead of 62 (Z's need all 62). Without a depth buffer every numerator is a
  // colour's: the divider is 46 bits wide and always takes 46 cycles.
  core_divider #(.NW(ACC_W), .DW(35), .QW(32), .SKIP(0), .NARROW((DEPTH != 0) ? 45 : 0), .COMP(1)) divider (
      .clk(clk), .rst(rst), .start(dv2), .num(acc_s), .narrow(dv_attr != 3'd4), .den(den), .comp(dv_comp),
      .busy(), .done(dv_done), .quo(dv_q), .rem(dv_r), .rem_c(), .neg(dv_neg));
  /* verilator lint_on PINCONNECTEMPTY */
  wire unused_q = &{1'b0, dv_q[31:24]};
  assign pw_q = (pw_field == 2'd2) ? ~dv_q[23:0] : dv_q[23:0];
  assign pw_r = dv_r;

  // ---------------------------------------------------------------- sequencer
  reg  [4:0] todo;
  always @(*) begin
    case (i_wait)
      2'd0: adv = 1'b1;
      2'd1: adv = quiet;
      2'd2: adv = !fr;
      default: adv = quiet && !dv_pend;
    endcase
    if (i_wf && fsel[3:2] != 2'd3 && !fw_ok) adv = 1'b0;  // the port answers a clock later
    if (pc == 7'd0) adv = start;
  end
  reg taken;
  always @(*) begin
    case (i_act)
      A_JMP, A_DONE, A_NODRAW: taken = 1'b1;
      A_BRZERO: taken = (acc[35:0] == 36'd0);  // D: |D| < 2^34, so its low 36 bits say D == 0
      A_BRNNEG: taken = !acc[ACC_W-1];
      A_BOX:    taken = !rows;
      A_BRRECT: taken = rect;
      A_NEXTA:  taken = (todo == 5'd0);
      default:  taken = (pc == 7'd0) && rect;
    endcase
  end
  assign pc_next = rst ? 7'd0 : !adv ? pc : taken ? i_tgt : pc + 7'd1;
  wire cond_ok = (i_cond == 2'd0) || (i_cond == 2'd1 && !tl0) || (i_cond == 2'd2 && !tl1) ||
                 (i_cond == 2'd3 && !tl2);

  always @(posedge clk) begin
    done <= 1'b0;
    pw_en <= 1'b0;
    xl_next <= 1'b0;
    pc <= pc_next;
    fw_ok <= !adv && pc != 7'd0;
    // pipeline
    v1_ <= 1'b0; w1 <= 1'b0; dv1 <= 1'b0;
    v2_ <= v1_; w2 <= w1; dv2 <= dv1; wa2 <= wa1;
    xr <= fr;
    if (fr) begin
      fph <= fph_n;
      if (f_last) begin
        fk <= fk - 5'd1;
        if (fk == 5'd0) fr <= 1'b0;
      end
    end
    // results the rasteriser holds, loaded with their RAM words
    if (w2) begin
      case (wa2)
        R_DX0: dx0 <= acc[16:0];
        R_DY0: begin dy0 <= acc[16:0]; dyz[0] <= (acc[16:0] == 17'd0); end
        R_DX1: dx1 <= acc[16:0];
        R_DY1: begin dy1 <= acc[16:0]; dyz[1] <= (acc[16:0] == 17'd0); end
        R_DX2: dx2 <= acc[16:0];
        R_DY2: begin dy2 <= acc[16:0]; dyz[2] <= (acc[16:0] == 17'd0); end
        R_ABSD: den_n <= ~{acc[33:0], 1'b0};
        default: ;
      endcase
    end
    if (rst) begin
      flip    <= 1'b0;
      draw    <= 1'b0;
      dv_pend <= 1'b0;
      dv_rdy  <= 1'b0;
      fr      <= 1'b0;
      xr      <= 1'b0;
      v2_     <= 1'b0;
      w2      <= 1'b0;
      dv2     <= 1'b0;
    end else begin
      // division results become plane writes: the step right is followed by the step left
      if (dv_done) dv_rdy <= 1'b1;
      if (xl_next) begin
        pw_en    <= 1'b1;
        pw_field <= 2'd2;
        dv_pend  <= 1'b0;
      end else if (dv_rdy) begin
        pw_en    <= 1'b1;
        pw_attr  <= dv_attr;
        pw_field <= dv_field;
        xl_next  <= (dv_field == 2'd1);
        dv_rdy   <= 1'b0;
        if (dv_field != 2'd1) dv_pend <= 1'b0;
      end
      if (pc == 7'd0 && start) begin
        box_x0 <= clip_x0;
        box_xl <= clip_x1 - 11'd1;  // clip_x1 > clip_x0 >= 0: a setup starts only then
        flip   <= 1'b0;
        if (rect) begin  // a clear: the clip rectangle (the clamps' values while idle)
          box_y0  <= by0[10:0];
          box_y1  <= by1[10:0];
          x_start <= xs;
          draw    <= 1'b1;
        end
      end
      if (adv && pc != 7'd0) begin
        ra <= r_sel;
        if ((i_op != 3'd0 || i_w) && cond_ok) begin
          v1_ <= 1'b1;
          op1 <= op_bits(i_op);
          w1  <= i_w;
          wa1 <= i_addr;
        end
        if (i_pair != 2'd0) begin  // a1*m1 +/- a2*m2, a from the pair, m1 = addr, m2 = tgt
          a1a   <= pair_a;
          m1a   <= i_addr;
          m2a   <= i_tgt[4:0];
          msub  <= (i_pair != 2'd3);
          mneg  <= (i_neg == 2'd1) ? flip : (i_neg == 2'd2) ? !flip : 1'b0;
          three <= (i_neg == 2'd3);
          mbits <= (i_pair == P_DX) ? 5'd16 : (i_pair == P_E) ? 5'd17 : ak_z ? 5'd24 : 5'd8;
          fr    <= 1'b1;
          fph   <= 2'd0;
          fk    <= (i_pair == P_DX) ? 5'd16 : (i_pair == P_E) ? 5'd17 : ak_z ? 5'd24 : 5'd8;
        end
        case (i_act)
          A_FLIP: flip <= 1'b1;
          A_FY0: begin
            box_y0     <= by0[10:0];
            y0_in_clip <= fy_in_clip;
            box2       <= 1'b1;
          end
          A_XT: x_start <= xs;
          A_BOX: begin
            box2 <= 1'b0;
            if (rows) begin
              box_y1 <= by1[10:0];
              draw   <= 1'b1;
            end
          end
          A_ORG: origin_idx <= IDX_W'(box_y0) * IDX_W'(width) + IDX_W'(x_start);
          A_TODO: todo <= need;
          A_NEXTA: begin
            ak   <= todo[0] ? 3'd0 : todo[1] ? 3'd1 : todo[2] ? 3'd2 : todo[3] ? 3'd3 : 3'd4;
            todo <= todo & (todo - 5'd1);
          end
          A_DIV: begin  // the numerator in acc to the divider, through the pipeline
            v1_      <= 1'b1;
            op1      <= 5'd0;
            dv1      <= 1'b1;
            dv_pend  <= 1'b1;
            dv_attr  <= ak;
            dv_field <= i_cond;
          end
          A_DONE: done <= 1'b1;
          A_NODRAW: begin
            draw <= 1'b0;
            done <= 1'b1;
          end
          default: ;
        endcase
      end
    end
  end

  always @(*) begin
    e_we = 3'b000;
    if (w2 && wa2 == R_E0) e_we = 3'b001;
    if (w2 && wa2 == R_E1) e_we = 3'b010;
    if (w2 && wa2 == R_E2) e_we = 3'b100;
  end
endmodule
