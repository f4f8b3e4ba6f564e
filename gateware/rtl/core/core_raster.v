// Rasteriser (docs/protocol.md section 8): walks the covered pixels of a set-up triangle inside
// its clipped bounding box and tells the attribute steppers how to follow.
//
// The walk is boundary following, not a box scan: each row is entered at the column where the
// previous row ended; from there it moves (without emitting) to the end of the row's covered
// span, then emits the span one pixel per cycle. Rows alternate direction (serpentine), so the
// cost per triangle is its covered pixels plus about one cycle per row plus the horizontal
// length of its boundary, never the empty half of the box. With `ltr` every row is emitted left
// to right (the simulator's pixel order), which the core needs when the buffers a draw reads
// and writes alias.
//
// Coverage of the next pixel is known before moving: one adder per edge computes E + step for
// the direction under consideration, and the move is committed only when wanted. A row's
// covered pixels are contiguous (convexity), and a failing edge tells which side they lie on:
// an edge with E < 0 that grows to the right (ex > 0) puts them to the right.
//
// Outputs form a two-stage pipeline with the steppers: `op` (stepper move), `emit` and the
// pixel position are registered together; the steppers apply `op` in the next enabled cycle.
module core_raster #(
    parameter integer DSP = 0,   // 1: the edge values in three SB_MAC16 accumulators (iCE40)
    parameter integer XW = 11,   // bits of a column and of a row: every column is below
    parameter integer YW = 11    //   FB_FORMAT.WIDTH, every row below HEIGHT (the soc's bounds)
) (
    input  wire               clk,
    input  wire               rst,
    input  wire               start,   // pulse: begin a triangle (setup outputs valid)
    input  wire [2:0]         e_we,              // setup writes the edge values at the origin
    input  wire signed [35:0] e_data,
    output wire signed [35:0] e0, e1, e2,        //   (and reads E20, E01 back for the planes; not with DSP)
    input  wire signed [16:0] dx0, dx1, dx2,     // edge deltas (held by setup while drawing):
    input  wire signed [16:0] dy0, dy1, dy2,     //   E steps by -16 dy right, 16 dx down
    input  wire               flip,              //   ... negated (P1 and P2 exchanged, section 8.1)
    input  wire [10:0]        box_x0, box_xl,    // first and last column (held by setup while active)
    input  wire [10:0]        box_y0, box_y1,    // rows to walk (box_y1 exclusive)
    input  wire [10:0]        x_start,           // first column (of row box_y0)
    input  wire               ltr,     // emit every row left to right
    input  wire               rect,    // every pixel of the box is covered (a clear)
    input  wire               adv,     // the whole raster/stepper pipeline may advance
    input  wire               hold,    // raster itself must not move this cycle (serial mode)
    output wire               active,  // walking a triangle
    output reg  [1:0]         op,      // OP_NONE / OP_RIGHT / OP_LEFT / OP_DOWN
    output wire [1:0]         op_next, // what `op` holds after this cycle's edge
    output reg                emit,    // the pixel reached by `op` is covered: emit it
    output wire [1:0]         px,      // low bits of the pixel position (dither)
    output wire [1:0]         py       // (the pixel index follows op in the core's pixel record)
);
  localparam [1:0] OP_NONE = 2'd0, OP_RIGHT = 2'd1, OP_LEFT = 2'd2, OP_DOWN = 2'd3;
  localparam [2:0] R_IDLE = 3'd0, R_ENTRY = 3'd1, R_SEEK = 3'd2, R_TOEND = 3'd3, R_EMIT = 3'd4,
                   R_DOWN = 3'd5;
  localparam DIR_R = 1'b0, DIR_L = 1'b1;

  reg [2:0] st;
  reg [XW-1:0] x;
  reg [YW-1:0] y;
  // the last column and row: setup holds the box while the walk runs (a setup starts only when the
  // rasteriser is idle), so no copy of it is kept here; all below 2^XW and 2^YW
  wire [XW-1:0] xlo = box_x0[XW-1:0], xhi = box_xl[XW-1:0];
  wire [YW-1:0] yhi = box_y1[YW-1:0] - YW'(1);
  // x != xhi, x != xlo, y == yhi, registered: compared when x or y is loaded or moves (the
  // comparison of the position the move reaches, which does not wait for the step decision), so
  // the decision reads one flip-flop each instead of an 11-bit comparison
  reg        can_r, can_l, last_row;
  reg        mdir;       // direction of the current move / emission
  reg        last_dir;   // emission direction of the previous row
  reg        order;      // ltr latched
  wire       pd_entry = order ? DIR_R : ~last_dir;  // emission direction when entering covered

  assign active = (st != R_IDLE);

  // one adder per edge: E - 16 dy (right), E + 16 dy (left), E + 16 dx (down)
  reg  [1:0] sel;
  wire sub = (sel != OP_LEFT && sel != OP_DOWN);
  wire sb = sub ^ flip;
  wire s0, s1, s2;     // E < 0 at the current pixel
  wire ns0, ns1, ns2;  // E < 0 at the pixel the move `sel` reaches
  wire commit;         // the move `sel` is made this cycle
  reg  area;           // rect latched
  wire ncov;           // the pixel the move `sel` reaches is covered
  wire ncov_r, ncov_l; // the pixel right / left of the current one is (DSP: ncov)
  wire nc_fwd, nc_ent; // ... the one in the direction `mdir` / opposite the entry direction (DSP: ncov)
  function signed [35:0] step(input signed [35:0] e, input signed [16:0] dx, input signed [16:0] dy,
                              input [1:0] sl, input sbit);
    reg [35:0] o;
    begin
      o = {{15{(sl == OP_DOWN) ? dx[16] : dy[16]}}, (sl == OP_DOWN) ? dx : dy, 4'd0};
      step = e + $signed(o ^ {36{sbit}}) + $signed({35'd0, sbit});  // one adder: e +/- o
    end
  endfunction
  genvar k;
  generate
    if (DSP != 0) begin : edge_dsp
      // Only signs are read, and the steps are multiples of 16: E + 16 k < 0 exactly when
      // floor(E / 16) + k < 0, so the accumulators hold E >> 4 (|E| < 2^35: 32 bits) and step by
      // dx, dy themselves. The current sign is kept beside each (loaded or moved with it).
      wire [16:0] dxs[0:2], dys[0:2];
      wire [2:0]  ns, s;
      assign dxs[0] = dx0; assign dxs[1] = dx1; assign dxs[2] = dx2;
      assign dys[0] = dy0; assign dys[1] = dy1; assign dys[2] = dy2;
      for (k = 0; k < 3; k = k + 1) begin : acc
        wire [16:0] o = (sel == OP_DOWN) ? dxs[k] : dys[k];
        wire [31:0] n;
        reg         neg;
        core_dsp_acc edge_acc (
            .clk(clk), .en(e_we[k] || commit), .load(e_we[k]), .sub(sb), .b({{15{o[16]}}, o}),
            .c(e_data[35:4]), .out(n));
        always @(posedge clk) if (e_we[k] || commit) neg <= e_we[k] ? e_data[35] : n[31];
        assign ns[k] = n[31];
        assign s[k]  = neg;
        wire unused_n = &{1'b0, n[30:0]};  // only the sign is read
      end
      assign {ns2, ns1, ns0} = ns;
      assign {s2, s1, s0} = s;
      assign ncov_r = ncov;  // one accumulator per edge: the sum of the move `sel`
      assign ncov_l = ncov;
      assign nc_fwd = ncov;
      assign nc_ent = ncov;
      assign e0 = 36'sd0;
      assign e1 = 36'sd0;
      assign e2 = 36'sd0;
      wire unused_e = &{1'b0, e_data[3:0]};
    end else begin : edge_fabric
      reg  signed [35:0] r0, r1, r2;
      // One adder per edge and move (right, left, down), all from registers: the coverage of
      // the pixel to either side is known while the decision is still choosing `sel`, so the
      // decision reads it instead of waiting for an adder behind its own choice (the walk's
      // cone, docs/gateware.md "Pipelining the ecp5 cones"); `sel` only picks the sum to keep.
      wire signed [35:0] n0r = step(r0, dx0, dy0, OP_RIGHT, !flip), n0l = step(r0, dx0, dy0, OP_LEFT, flip);
      wire signed [35:0] n1r = step(r1, dx1, dy1, OP_RIGHT, !flip), n1l = step(r1, dx1, dy1, OP_LEFT, flip);
      wire signed [35:0] n2r = step(r2, dx2, dy2, OP_RIGHT, !flip), n2l = step(r2, dx2, dy2, OP_LEFT, flip);
      wire signed [35:0] n0d = step(r0, dx0, dy0, OP_DOWN, flip);
      wire signed [35:0] n1d = step(r1, dx1, dy1, OP_DOWN, flip);
      wire signed [35:0] n2d = step(r2, dx2, dy2, OP_DOWN, flip);
      wire signed [35:0] n0 = (sel == OP_DOWN) ? n0d : (sel == OP_LEFT) ? n0l : n0r;
      wire signed [35:0] n1 = (sel == OP_DOWN) ? n1d : (sel == OP_LEFT) ? n1l : n1r;
      wire signed [35:0] n2 = (sel == OP_DOWN) ? n2d : (sel == OP_LEFT) ? n2l : n2r;
      wire unused_sb = &{1'b0, sb};
      // edge values: setup's writes (the rasteriser is idle then) or a committed move
      always @(posedge clk) begin
        if (e_we[0] || commit) r0 <= e_we[0] ? e_data : n0;
        if (e_we[1] || commit) r1 <= e_we[1] ? e_data : n1;
        if (e_we[2] || commit) r2 <= e_we[2] ? e_data : n2;
      end
      assign {ns0, ns1, ns2} = {n0[35], n1[35], n2[35]};
      assign ncov_r = area || (!n0r[35] && !n1r[35] && !n2r[35]);
      assign ncov_l = area || (!n0l[35] && !n1l[35] && !n2l[35]);
      assign nc_fwd = (mdir == DIR_R) ? ncov_r : ncov_l;
      assign nc_ent = (pd_entry == DIR_R) ? ncov_l : ncov_r;
      wire unused_ncov = &{1'b0, ncov};
      assign {s0, s1, s2} = {r0[35], r1[35], r2[35]};
      assign e0 = r0;
      assign e1 = r1;
      assign e2 = r2;
    end
  endgenerate
  assign ncov = area || (!ns0 && !ns1 && !ns2);
  wire cov = area || (!s0 && !s1 && !s2);
  // sides on which covered pixels of this row can lie, from the failing edges
  // (ex = -16 dy, or 16 dy when exchanged: a failing edge with ex > 0 grows to the right)
  // The sides are fixed for the draw (setup holds dy and flip): latched at the start as "edge k,
  // failing, rules out the right (nr) / the left (nl)", so no 17-bit comparison of dy lies on
  // the walk's paths. dy > 0 as sign and non-zero bits (no carry chain).
  function grows_r(input signed [16:0] dy, input f);  // ex > 0
    grows_r = f ? (!dy[16] && |dy[15:0]) : dy[16];
  endfunction
  function grows_l(input signed [16:0] dy, input f);  // ex < 0
    grows_l = f ? dy[16] : (!dy[16] && |dy[15:0]);
  endfunction
  reg  [2:0] nr, nl;
  always @(posedge clk)
    if (start) begin
      nr <= ~{grows_r(dy2, flip), grows_r(dy1, flip), grows_r(dy0, flip)};
      nl <= ~{grows_l(dy2, flip), grows_l(dy1, flip), grows_l(dy0, flip)};
    end
  wire right_ok = !(s0 && nr[0]) && !(s1 && nr[1]) && !(s2 && nr[2]);
  wire left_ok  = !(s0 && nl[0]) && !(s1 && nl[1]) && !(s2 && nl[2]);

  // ---- decision for this cycle ----
  reg       go;         // commit the move `sel`
  reg       emit_n;
  reg [2:0] st_n;
  reg       mdir_n, last_dir_n;
  always @(*) begin
    sel        = OP_NONE;
    go         = 1'b0;
    emit_n     = 1'b0;
    st_n       = st;
    mdir_n     = mdir;
    last_dir_n = last_dir;
    case (st)
      R_ENTRY: begin
        if (cov) begin
          // walk to the end of the span behind the emission direction first
          sel = (pd_entry == DIR_R) ? OP_LEFT : OP_RIGHT;
          if (((pd_entry == DIR_R) ? can_l : can_r) && nc_ent) begin
            go     = 1'b1;
            st_n   = R_TOEND;
            mdir_n = ~pd_entry;
          end else begin
            emit_n = 1'b1;
            st_n   = R_EMIT;
            mdir_n = pd_entry;
          end
        end else if (right_ok && can_r) begin
          sel    = OP_RIGHT;
          go     = 1'b1;
          mdir_n = DIR_R;
          emit_n = ncov_r;
          st_n   = ncov_r ? R_EMIT : R_SEEK;
        end else if (left_ok && can_l) begin
          sel    = OP_LEFT;
          go     = 1'b1;
          mdir_n = DIR_L;
          // arriving at the right end: emit from here, or (left-to-right order) walk on to the left end
          emit_n = ncov_l && !order;
          st_n   = !ncov_l ? R_SEEK : order ? R_TOEND : R_EMIT;
        end else if (last_row) begin
          st_n = R_IDLE;  // empty row, last row
        end else begin
          sel  = OP_DOWN;  // empty row
          go   = 1'b1;
          st_n = R_ENTRY;
        end
      end
      R_SEEK: begin
        sel = (mdir == DIR_R) ? OP_RIGHT : OP_LEFT;
        if ((mdir == DIR_R) ? (right_ok && can_r) : (left_ok && can_l)) begin
          go = 1'b1;
          if (nc_fwd) begin
            emit_n = !(order && mdir == DIR_L);
            st_n   = (order && mdir == DIR_L) ? R_TOEND : R_EMIT;
          end
        end else if (last_row) begin
          st_n = R_IDLE;
        end else begin
          sel  = OP_DOWN;  // nothing covered on this row
          go   = 1'b1;
          st_n = R_ENTRY;
        end
      end
      R_TOEND: begin
        sel = (mdir == DIR_R) ? OP_RIGHT : OP_LEFT;
        if (((mdir == DIR_R) ? can_r : can_l) && nc_fwd) begin
          go = 1'b1;
        end else begin
          emit_n = 1'b1;
          st_n   = R_EMIT;
          mdir_n = ~mdir;
        end
      end
      R_EMIT: begin
        sel = (mdir == DIR_R) ? OP_RIGHT : OP_LEFT;
        if (((mdir == DIR_R) ? can_r : can_l) && nc_fwd) begin
          go     = 1'b1;
          emit_n = 1'b1;
        end else begin
          last_dir_n = mdir;
          st_n       = last_row ? R_IDLE : R_DOWN;
        end
      end
      R_DOWN: begin
        sel  = OP_DOWN;
        go   = 1'b1;
        st_n = R_ENTRY;
      end
      default: ;
    endcase
  end

  // one adder each: the position a move of `sel` reaches (or the start), x +/- 1, y + 1, and its
  // bound flags; the decision only enables the registers
  wire [XW-1:0] x_mv = (start ? x_start[XW-1:0] : x) + (start ? XW'(0) : (sel == OP_LEFT) ? {XW{1'b1}} : XW'(1));
  wire [YW-1:0] y_mv = start ? box_y0[YW-1:0] : y + YW'(1);
  wire        hmove = commit && (sel == OP_RIGHT || sel == OP_LEFT);
  wire        vmove = commit && (sel == OP_DOWN);
  always @(posedge clk) begin
    if (start || hmove) begin
      x     <= x_mv;
      can_r <= (x_mv != xhi);
      can_l <= (x_mv != xlo);
    end
    if (start || vmove) begin
      y        <= y_mv;
      last_row <= (y_mv == yhi);
    end
  end

  assign op_next = (rst || start) ? OP_NONE : !adv ? op : (hold || st == R_IDLE || !go) ? OP_NONE : sel;

  always @(posedge clk) begin
    if (rst) begin
      st   <= R_IDLE;
      op   <= OP_NONE;
      emit <= 1'b0;
    end else if (start) begin
      st       <= R_ENTRY;
      last_dir <= DIR_L;
      mdir     <= DIR_R;
      order    <= ltr;
      area     <= rect;
      op       <= OP_NONE;
      emit     <= 1'b0;
    end else if (adv) begin
      if (hold || st == R_IDLE) begin
        op   <= OP_NONE;
        emit <= 1'b0;
      end else begin
        st       <= st_n;
        mdir     <= mdir_n;
        last_dir <= last_dir_n;
        op   <= go ? sel : OP_NONE;
        emit <= emit_n;
      end
    end
  end

  // the pixel reached by `op` is where the walk now is: x and y move together with op and emit
  // (after a start they differ from that pixel's only while emit is 0, when nothing reads them)
  assign px   = x[1:0];
  assign py   = y[1:0];

  assign commit = !rst && !start && adv && !hold && st != R_IDLE && go;
  wire unused_box = &{1'b0, box_x0, box_xl, box_y0, box_y1, x_start};  // bits above XW / YW
endmodule
