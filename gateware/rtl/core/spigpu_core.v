// spigpu render core: triangle setup -> rasteriser -> attribute steppers -> depth stage ->
// texture unit -> colour stage -> one memory request stream; plus CLEAR / CLEAR_Z.
// docs/protocol.md sections 8-12 are the specification; the C++ simulator (backends/sim) is the
// bit-exact reference. Interface to the soc: docs/gateware.md ("soc <-> core").
//
// Commands execute in order. A triangle is set up while the command waits on the port (the soc
// holds cmd_* stable while cmd_valid && !cmd_ready); the core then copies the render state it
// needs, accepts the command and rasterises while the soc moves on. Memory order between
// commands is kept by draining the pixel pipeline before a draw's first request and before a
// clear; the next triangle's setup overlaps that drain.
module spigpu_core #(
    parameter integer PROFILE    = 1,       // 0 up5k (small: serial setup, steps in block RAM, one
                                            // read in flight per stage), 1 ecp5 (parallel, deeper)
    parameter [7:0]   FEATURES   = 8'hFF,   // CAPS.FEATURES; bit 6: temporal dither, bit 7: texturing
    parameter integer MAX_WIDTH  = 1024,    // CAPS.MAX_WIDTH / MAX_HEIGHT
    parameter integer MAX_HEIGHT = 1024,
    parameter integer VRAM_KIB   = 32768,   // CAPS.VRAM_KIB
    parameter integer DEPTH      = 1,       // CAPS2.FEATURES2 bit 0: 0 = no depth buffer (the soc
                                            // refuses Z_TEST/Z_WRITE/CLEAR_Z; the depth stage folds away)
    parameter integer PERF       = 1        // 1: the perf_* counters count (co-simulation); 0: they
                                            // read 0 and cost nothing (boards)
) (
    input  wire         clk,
    input  wire         rst,
    // command port
    input  wire         cmd_valid,
    output wire         cmd_ready,
    input  wire [1:0]   cmd_op,           // 0 TRIANGLE, 1 CLEAR, 2 CLEAR_Z
    input  wire [31:0]  cmd_tri_mode,
    input  wire [27:0]  cmd_tex_base,
    input  wire [17:0]  cmd_tex_fmt,
    input  wire [43:0]  cmd_scissor,      // {Y1, X1, Y0, X0}
    input  wire [27:0]  cmd_fb_draw,
    input  wire [27:0]  cmd_fb_z,
    input  wire [1:0]   cmd_fb_format,
    input  wire [10:0]  cmd_fb_width,
    input  wire [10:0]  cmd_fb_height,
    input  wire [31:0]  cmd_clear_color,
    input  wire [23:0]  cmd_clear_depth,
    input  wire [183:0] cmd_v0,
    input  wire [183:0] cmd_v1,
    input  wire [183:0] cmd_v2,
    output wire [3:0]   vp_addr,          // PROFILE 0: the vertices through the soc's read port
    input  wire [31:0]  vp_data,          // ({vertex, word} in, the word a clock later), not cmd_v*;
                                          // {3, 0} CLEAR_COLOR, {3, 1} CLEAR_DEPTH (not cmd_clear_*)
    output reg          core_idle,
    // memory port
    output wire         mem_req_valid,
    input  wire         mem_req_ready,
    output wire         mem_req_we,
    output wire [29:0]  mem_req_addr,
    output wire [31:0]  mem_req_wdata,
    output wire [3:0]   mem_req_be,
    input  wire         mem_rsp_valid,
    input  wire [31:0]  mem_rsp_rdata,
    // counters
    output reg  [31:0]  perf_triangles,   // triangles rasterised (non-empty after setup)
    output reg  [31:0]  perf_pixels,      // covered pixels emitted by the rasteriser
    output reg  [31:0]  perf_passed,      // pixels that passed the depth stage
    output reg  [31:0]  perf_textured,    // pixels through the texture unit
    output reg  [31:0]  perf_busy,        // cycles not idle
    output reg  [31:0]  perf_setup,       // cycles in triangle setup
    output reg  [31:0]  perf_raster       // cycles the rasteriser walked
);
  localparam F_BILINEAR = 0, F_TEXTURE = 7;
  localparam integer TEX    = FEATURES[F_TEXTURE] ? 1 : 0;
  localparam integer SMALL  = (PROFILE == 0) ? 1 : 0;
  localparam integer IDX_W  = $clog2(MAX_WIDTH * MAX_HEIGHT);     // pixel index bits
  localparam integer ADDR_W = $clog2(VRAM_KIB) + 10;              // byte address bits of VRAM
  localparam integer Q_AW   = (SMALL != 0) ? 0 : 2;                      // log2 reads in flight per stage
  localparam integer PW     = IDX_W + 60 + ((TEX != 0) ? 96 : 0);        // pixel record
  localparam integer CW     = IDX_W + 36;                         // colour stage record
  localparam [1:0] OP_TRI = 2'd0, OP_CLEAR = 2'd1, OP_CLEAR_Z = 2'd2;
  // up5k: the rasteriser's column and row bits. The soc's FB_FORMAT holds a width and height of
  // at most MAX_WIDTH x MAX_HEIGHT or its reset value 640 x 480 (command_exec's WB, HB bits), and
  // every column and row drawn is below them (fit9, docs/gateware.md); ecp5 keeps 11 bits.
  localparam integer RAS_XW = (SMALL != 0) ? $clog2(((MAX_WIDTH > 640) ? MAX_WIDTH : 640) + 1) : 11;
  localparam integer RAS_YW = (SMALL != 0) ? $clog2(((MAX_HEIGHT > 480) ? MAX_HEIGHT : 480) + 1) : 11;
  // up5k: the colour buffer's base as its block bits below 2^ADDR_W and one bit for "any above"
  // (all core_color's byte_addr reads of it), so the draw's copy keeps 14 flip-flops, not 28
  localparam integer BLK_W = ADDR_W - 4;
  function [27:0] fold_base(input [27:0] b16);
    fold_base = 28'({|(b16 >> BLK_W), b16[BLK_W-1:0]});
  endfunction

  // ---------------------------------------------------------------- command decode
  wire [10:0] sc_x0 = cmd_scissor[10:0], sc_y0 = cmd_scissor[21:11];
  wire [10:0] sc_x1 = cmd_scissor[32:22], sc_y1 = cmd_scissor[43:33];
  wire [10:0] clip_x1_n = (sc_x1 < cmd_fb_width) ? sc_x1 : cmd_fb_width;
  wire [10:0] clip_y1_n = (sc_y1 < cmd_fb_height) ? sc_y1 : cmd_fb_height;
  wire [10:0] clip_x1, clip_y1;
  wire        clip_empty;
  generate
    if (SMALL != 0) begin : clip_held
      // up5k: the clip rectangle's end in flip-flops, a clock behind SCISSOR and FB_FORMAT. Only
      // the setup reads it, from su_go on: a command is offered (cmd_valid) at the earliest a
      // clock after the SCISSOR or FB_FORMAT before it executes, and su_go is a clock after that,
      // so the held value is the new one by then. The emptiness test is read in the first clock
      // a command is offered, so it stays a function of the executor's registers, but as four
      // comparisons side by side, not two behind the two minimums: min(a, b) <= c exactly when
      // a <= c or b <= c. Each comparison's carry chain starts at flip-flops and ends in the
      // accept / su_go choice (docs/gateware.md up5k-clip: main's SCISSOR -> clip_y1 carry ->
      // clip_empty carry -> accept path, 39.6-40.0 ns on the iCEBreaker).
      reg [10:0] x1_q, y1_q;
      always @(posedge clk) begin
        x1_q <= clip_x1_n;
        y1_q <= clip_y1_n;
      end
      assign clip_x1 = x1_q;
      assign clip_y1 = y1_q;
      assign clip_empty = (sc_x1 <= sc_x0) || (cmd_fb_width <= sc_x0) ||
                          (sc_y1 <= sc_y0) || (cmd_fb_height <= sc_y0);
    end else begin : clip_comb
      // ecp5: the clear engine copies the rectangle in the clock the command is first offered
      assign clip_x1 = clip_x1_n;
      assign clip_y1 = clip_y1_n;
      assign clip_empty = (clip_x1 <= sc_x0) || (clip_y1 <= sc_y0);
    end
  endgenerate

  wire       m_gouraud = cmd_tri_mode[0];
  wire       m_tex     = cmd_tri_mode[1] && FEATURES[F_TEXTURE];
  wire       m_ztest   = cmd_tri_mode[2] && DEPTH != 0;
  wire [2:0] m_zfunc   = cmd_tri_mode[5:3];
  wire       m_zwrite  = cmd_tri_mode[6] && DEPTH != 0;
  wire [3:0] m_keep    = cmd_tri_mode[13:10];
  wire [3:0] stored    = (cmd_fb_format == 2'd1) ? 4'b0111 : 4'b1111;
  wire       all_masked  = (m_keep & stored) == stored;
  wire       some_masked = (m_keep & stored) != 4'd0;
  wire       writes_nothing = (m_ztest && m_zfunc == 3'd0) || (all_masked && !m_zwrite);
  wire       colour_on = !all_masked;
  wire       tex_on = m_tex && colour_on;
  wire [7:0] need = {{3{tex_on}}, m_ztest || m_zwrite, {4{m_gouraud && colour_on}}};

  wire serial_n;
  core_alias #(.ADDR_W(ADDR_W)) alias_check (
      .clk(clk), .fb_draw16(cmd_fb_draw), .fb_z16(cmd_fb_z), .tex16(cmd_tex_base),
      .width(cmd_fb_width), .height(cmd_fb_height), .fmt(cmd_fb_format), .tex_fmt(cmd_tex_fmt[17:16]),
      .tex_wl(cmd_tex_fmt[3:0]), .tex_hl(cmd_tex_fmt[7:4]), .colour_on(colour_on),
      .depth_on(m_ztest || m_zwrite), .z_write(m_zwrite), .textured(tex_on), .serial(serial_n));

  // ---------------------------------------------------------------- setup
  wire        su_busy, su_done, su_draw;
  wire [2:0]  su_e_we;
  wire signed [35:0] su_e_data, ras_e0, ras_e1, ras_e2;
  wire signed [16:0] su_dx0, su_dx1, su_dx2, su_dy0, su_dy1, su_dy2;
  wire [10:0] su_bx0, su_by0, su_bxl, su_by1, su_xs;
  wire        su_flip;
  wire [IDX_W-1:0] su_idx;
  wire [34:0] su_den;
  wire        pw_en;
  wire [2:0]  pw_attr;
  wire [1:0]  pw_field;
  wire [31:0] pw_q;
  wire [34:0] pw_r;
  reg         su_go;
  wire        su_rect = (cmd_op != OP_TRI);  // small profile: clears are drawn as rectangles
  generate
    if (SMALL != 0) begin : setup_tm
      // a sequencer whose operands are block RAM words (no operand buses); the rasteriser's
      // edge values are not read back
      wire [23:0] q24;
      wire unused_e = &{1'b0, ras_e1, ras_e2, need[7:5], cmd_v0, cmd_v1, cmd_v2, cmd_clear_color, cmd_clear_depth};
      core_setup_tm #(.IDX_W(IDX_W), .DEPTH(DEPTH)) setup (
          .clk(clk), .rst(rst), .start(su_go), .rect(su_rect), .busy(su_busy), .done(su_done),
          .draw(su_draw), .vp_addr(vp_addr), .vp_data(vp_data),
          .vp_idle((cmd_op == OP_TRI) ? 4'b0010 : {3'b110, cmd_op == OP_CLEAR_Z}),
          .clip_x0(sc_x0), .clip_y0(sc_y0), .clip_x1(clip_x1), .clip_y1(clip_y1), .width(cmd_fb_width),
          .need(need[4:0]),
          .dx0(su_dx0), .dx1(su_dx1), .dx2(su_dx2), .dy0(su_dy0), .dy1(su_dy1), .dy2(su_dy2),
          .flip(su_flip), .e_we(su_e_we), .e_data(su_e_data),
          .box_x0(su_bx0), .box_y0(su_by0), .box_xl(su_bxl), .box_y1(su_by1), .x_start(su_xs),
          .origin_idx(su_idx),
          .den(su_den), .pw_en(pw_en), .pw_attr(pw_attr), .pw_field(pw_field), .pw_q(q24), .pw_r(pw_r));
      assign pw_q = {8'd0, q24};
    end else begin : setup_par
      assign vp_addr = 4'd0;
      wire unused_vp = &{1'b0, vp_data};
      core_setup #(.TEX(TEX), .IDX_W(IDX_W), .SKIP(1), .XREJECT(1), .NDIV(3)) setup (
          .clk(clk), .rst(rst), .start(su_go), .rect(su_rect), .busy(su_busy), .done(su_done), .draw(su_draw),
          .v0(cmd_v0), .v1(cmd_v1), .v2(cmd_v2),
          .clip_x0(sc_x0), .clip_y0(sc_y0), .clip_x1(clip_x1), .clip_y1(clip_y1), .width(cmd_fb_width),
          .need(need),
          .dx0(su_dx0), .dx1(su_dx1), .dx2(su_dx2), .dy0(su_dy0), .dy1(su_dy1), .dy2(su_dy2),
          .flip(su_flip), .e_we(su_e_we), .e_data(su_e_data), .e1(ras_e1), .e2(ras_e2),
          .box_x0(su_bx0), .box_y0(su_by0), .box_xl(su_bxl), .box_y1(su_by1), .x_start(su_xs),
          .origin_idx(su_idx),
          .den(su_den), .pw_en(pw_en), .pw_attr(pw_attr), .pw_field(pw_field), .pw_q(pw_q), .pw_r(pw_r));
    end
  endgenerate

  // ---------------------------------------------------------------- render state of the draw
  reg        r_gouraud, r_tex, r_ztest, r_zwrite, r_dither, r_decal, r_serial, r_need_dst;
  reg [2:0]  r_zfunc;
  reg [1:0]  r_blend, r_fmt;
  reg [3:0]  r_keep;
  reg [27:0] r_fb_draw, r_fb_z, r_tex_base;
  reg [17:0] r_tex_fmt;
  reg [31:0] r_flat;
  reg        r_temporal;
  reg [3:0]  r_phase;
  reg [10:0] r_width;
  reg [7:0]  r_need;
  reg        r_rect, r_zsel;   // r_zsel: Z is CLEAR_DEPTH, held in r_flat (a clear drawn as a rectangle)
  // clear state
  reg [27:0] k_base;
  reg [1:0]  k_bpp;
  reg [31:0] k_pattern;
  reg [10:0] k_w, k_x0, k_y0, k_x1, k_y1;

  // ---------------------------------------------------------------- rasteriser + steppers
  wire        ras_active;
  wire [1:0]  ras_op, ras_op_next;
  wire        ras_emit;
  wire [1:0]  ras_x, ras_y;
  reg         ras_go;
  wire        adv, hold;
  wire        draw_go;   // the draw starts: render state copied, command accepted (sequencer below)
  core_raster #(.DSP(SMALL), .XW(RAS_XW), .YW(RAS_YW)) raster (
      .clk(clk), .rst(rst), .start(ras_go),
      .e_we(su_e_we), .e_data(su_e_data), .e0(ras_e0), .e1(ras_e1), .e2(ras_e2),
      .dx0(su_dx0), .dx1(su_dx1), .dx2(su_dx2), .dy0(su_dy0), .dy1(su_dy1), .dy2(su_dy2),
      .flip(su_flip), .box_x0(su_bx0), .box_y0(su_by0), .box_xl(su_bxl), .box_y1(su_by1), .x_start(su_xs),
      .ltr(r_serial), .rect(r_rect), .adv(adv), .hold(hold), .active(ras_active), .op(ras_op),
      .op_next(ras_op_next), .emit(ras_emit), .px(ras_x), .py(ras_y));

  wire [7:0]  a_r, a_g, a_b, a_a;
  wire [23:0] a_z;
  wire [95:0] a_stq;
  wire        pipe_ok;   // the emitted pixel record may change this cycle
  genvar gi;
  generate
    if (SMALL != 0) begin : tm_steppers
      // one shared datapath, a cycle per interpolated attribute per move
      wire [31:0] tm_rgba;
      core_interp_tm #(.RW(35), .QW((DEPTH != 0) ? 24 : 8)) interp (
          .clk(clk), .rst(rst), .we(pw_en), .attr(pw_attr), .field(pw_field), .wq(pw_q[23:0]),
          .wr(pw_r), .den(su_den), .mask(r_need[4:0]),
          // a flat draw's colour and a clear's value straight into the output registers when
          // the draw starts (v0's COLOR, CLEAR_COLOR or CLEAR_DEPTH on the idle read port)
          .ld_rgba(draw_go && (cmd_op != OP_TRI || !m_gouraud)), .ld_z(draw_go && cmd_op != OP_TRI),
          .ld_data(vp_data), .op(ras_op), .op_next(ras_op_next),
          .pipe_ok(pipe_ok), .adv(adv), .rgba(tm_rgba), .z(a_z));
      assign {a_r, a_g, a_b, a_a} = tm_rgba;
    end else begin : steppers
      for (gi = 0; gi < 4; gi = gi + 1) begin : colour
        wire [7:0] qv;
        core_stepper #(.QW(8), .RW(35), .EBR(0)) st (
            .clk(clk), .we(pw_en && pw_attr == gi), .field(pw_field), .wq(pw_q[7:0]), .wr(pw_r),
            .den(su_den), .en(adv), .op(ras_op), .op_next(ras_op_next), .q(qv));
      end
      assign a_r = colour[0].qv;
      assign a_g = colour[1].qv;
      assign a_b = colour[2].qv;
      assign a_a = colour[3].qv;
      core_stepper #(.QW(24), .RW(35), .EBR(0)) z_stepper (
          .clk(clk), .we(pw_en && pw_attr == 3'd4), .field(pw_field), .wq(pw_q[23:0]), .wr(pw_r),
          .den(su_den), .en(adv), .op(ras_op), .op_next(ras_op_next), .q(a_z));
      assign adv = pipe_ok;
    end
    if (TEX != 0) begin : tex_steppers
      for (gi = 5; gi < 8; gi = gi + 1) begin : stq
        wire [31:0] qv;
        core_stepper #(.QW(32), .RW(35), .EBR(0)) st (
            .clk(clk), .we(pw_en && pw_attr == gi), .field(pw_field), .wq(pw_q), .wr(pw_r),
            .den(su_den), .en(adv), .op(ras_op), .op_next(ras_op_next), .q(qv));
      end
      assign a_stq = {stq[7].qv, stq[6].qv, stq[5].qv};
    end else begin : no_tex_steppers
      assign a_stq = 96'd0;
    end
  endgenerate

  // emitted pixel record, aligned with the steppers' values: set when the rasteriser advances,
  // cleared when the depth stage takes it. Its pixel index takes the move `op` when the steppers
  // do (y * width + x from the origin on), so the rasteriser keeps no index of its own.
  reg        emit2;
  reg [1:0]  x2, y2;
  reg [IDX_W-1:0] idx2;
  localparam [1:0] OP_RIGHT = 2'd1, OP_LEFT = 2'd2, OP_DOWN = 2'd3;
  wire [IDX_W-1:0] idx2_n = idx2 + ((ras_op == OP_DOWN) ? IDX_W'(r_width) :
                                    (ras_op == OP_LEFT) ? {IDX_W{1'b1}} : IDX_W'(ras_op == OP_RIGHT));
  always @(posedge clk) begin
    if (ras_go) idx2 <= su_idx;
    else if (adv) idx2 <= idx2_n;
    if (rst) emit2 <= 1'b0;
    else if (ras_go) emit2 <= 1'b0;
    else if (adv) begin
      emit2 <= ras_emit;
      x2    <= ras_x;
      y2    <= ras_y;
    end else if (d_in_ready) begin
      emit2 <= 1'b0;
    end
  end
  // up5k: the stepper's output registers hold a flat colour and a clear's depth too (loaded when
  // the draw starts), so the record needs no choice; ecp5 keeps them in r_flat
  wire [31:0] src_rgba = (SMALL != 0 || r_gouraud) ? {a_r, a_g, a_b, a_a} : r_flat;
  // without a depth buffer the record's depth is 0: nothing reads it, and the steppers' depth
  // register then goes (fit9, docs/gateware.md)
  wire [23:0] src_z = (DEPTH == 0) ? 24'd0 : (SMALL == 0 && r_zsel) ? r_flat[23:0] : a_z;
  wire [PW-1:0] pix;
  generate
    if (TEX != 0) begin : pix_tex
      assign pix = {a_stq, src_rgba, y2, x2, src_z, idx2};
    end else begin : pix_plain
      assign pix = {src_rgba, y2, x2, src_z, idx2};
    end
  endgenerate

  // ---------------------------------------------------------------- depth stage
  wire         d_in_ready, d_out_valid, d_out_ready, d_idle, d_passed;
  wire [PW-1:0] d_out;
  wire         zr_valid, zr_ready, zr_rsp, zw_valid, zw_ready;
  wire [29:0]  zr_addr, zw_addr;
  wire [23:0]  zw_data;
  // Without a depth buffer the stage never reads or writes (Z_TEST and Z_WRITE are 0): its
  // requests are constants here, so the memory port's choices lose their depth inputs (its
  // address and data multiplexers took them as their default, keeping the depth address adder,
  // FB_Z's copy and the steppers' depth register alive; fit9, docs/gateware.md)
  wire         zr_valid_d, zw_valid_d;
  wire [29:0]  zr_addr_d, zw_addr_d;
  wire [23:0]  zw_data_d;
  assign zr_valid = (DEPTH != 0) && zr_valid_d;
  assign zw_valid = (DEPTH != 0) && zw_valid_d;
  assign zr_addr  = (DEPTH != 0) ? zr_addr_d : 30'd0;
  assign zw_addr  = (DEPTH != 0) ? zw_addr_d : 30'd0;
  assign zw_data  = (DEPTH != 0) ? zw_data_d : 24'd0;
  core_depth #(.PW(PW), .ZLSB(IDX_W), .IDX_W(IDX_W), .AW(Q_AW), .ADDR_W(ADDR_W), .OUT_REG(1 - SMALL)) depth (
      .clk(clk), .rst(rst), .z_test(r_ztest), .z_func(r_zfunc), .z_write(r_zwrite), .fb_z16(r_fb_z),
      .in_valid(emit2), .in_ready(d_in_ready), .in_pix(pix),
      .out_valid(d_out_valid), .out_ready(d_out_ready), .out_pix(d_out),
      .rd_valid(zr_valid_d), .rd_ready(zr_ready), .rd_addr(zr_addr_d), .rsp_valid(zr_rsp), .rsp_data(mem_rsp_rdata[23:0]),
      .wr_valid(zw_valid_d), .wr_ready(zw_ready), .wr_addr(zw_addr_d), .wr_data(zw_data_d), .idle(d_idle),
      .passed(d_passed));

  // ---------------------------------------------------------------- texture unit
  // The texel cache is kept across consecutive non-serial textured draws with the same texture and
  // buffers while the core stays busy; otherwise memory may have changed under it (a clear, another
  // draw, MEM_DATA writes while the core was idle) and it is forgotten when the draw starts.
  reg          tc_keep, tc_inval;
  reg  [103:0] tc_sig;
  wire [103:0] tc_sig_n = {cmd_tex_base, cmd_tex_fmt, cmd_fb_draw, cmd_fb_z, cmd_fb_format};
  wire         tc_ok_n = tex_on && !serial_n;
  wire          c_in_valid, c_in_ready;
  wire [CW-1:0] c_in;
  wire          tr_valid, tr_ready, tr_rsp;
  wire [29:0]   tr_addr;
  wire          t_idle, t_count;
  reg           colour_on_r;
  wire [CW-1:0] d_colour = {d_out[IDX_W+27:IDX_W+24], d_out[IDX_W-1:0], d_out[IDX_W+59:IDX_W+28]};
  generate
    if (TEX != 0) begin : texturing
      wire          t_in_ready, t_out_valid;
      wire [CW-1:0] t_out;
      core_texture #(.AW(Q_AW), .CACHE(1 - SMALL), .IDX_W(IDX_W), .ADDR_W(ADDR_W)) texture (
          .clk(clk), .rst(rst), .tex16(r_tex_base), .wl(r_tex_fmt[3:0]), .hl(r_tex_fmt[7:4]),
          .wrap_s(r_tex_fmt[9:8]), .wrap_t(r_tex_fmt[11:10]),
          .bilinear(r_tex_fmt[12] && FEATURES[F_BILINEAR]), .tfmt(r_tex_fmt[17:16]), .decal(r_decal),
          .inval(tc_inval), .cache_en(!r_serial),
          .in_valid(d_out_valid && r_tex), .in_ready(t_in_ready), .in_pix(d_out),
          .out_valid(t_out_valid), .out_ready(c_in_ready), .out_pix(t_out),
          .rd_valid(tr_valid), .rd_ready(tr_ready), .rd_addr(tr_addr), .rsp_valid(tr_rsp),
          .rsp_data(mem_rsp_rdata), .idle(t_idle), .textured(t_count));
      assign c_in_valid  = r_tex ? t_out_valid : (d_out_valid && colour_on_r);
      assign d_out_ready = r_tex ? t_in_ready : (colour_on_r ? c_in_ready : 1'b1);
      assign c_in        = r_tex ? t_out : d_colour;
    end else begin : no_texturing
      assign c_in_valid  = d_out_valid && colour_on_r;
      assign d_out_ready = colour_on_r ? c_in_ready : 1'b1;
      assign c_in        = d_colour;
      assign tr_valid    = 1'b0;
      assign tr_addr     = 30'd0;
      assign t_idle      = 1'b1;
      assign t_count     = 1'b0;
    end
  endgenerate

  // ---------------------------------------------------------------- colour stage
  wire        cr_valid, cr_ready, cr_rsp, cw_valid, cw_ready, c_idle;
  wire [29:0] cr_addr, cw_addr;
  wire [31:0] cw_data;
  wire [3:0]  cw_be;
  core_color #(.AW(Q_AW), .IDX_W(IDX_W), .ADDR_W(ADDR_W), .FEATURES(FEATURES), .PIPE(1 - SMALL)) colour (
      .clk(clk), .rst(rst), .fmt(r_fmt), .fb_draw16(r_fb_draw), .blend(r_blend), .dither(r_dither),
      .temporal(r_temporal), .phase(r_phase),
      .keep(r_keep), .need_dst(r_need_dst),
      .in_valid(c_in_valid), .in_ready(c_in_ready), .in_pix(c_in),
      .rd_valid(cr_valid), .rd_ready(cr_ready), .rd_addr(cr_addr), .rsp_valid(cr_rsp), .rsp_data(mem_rsp_rdata),
      .wr_valid(cw_valid), .wr_ready(cw_ready), .wr_addr(cw_addr), .wr_data(cw_data), .wr_be(cw_be),
      .idle(c_idle));

  // ---------------------------------------------------------------- clears
  // ecp5: a word per cycle; up5k: drawn as rectangles through the rasteriser and pixel stages
  wire        k_busy, k_valid, k_ready;
  wire [29:0] k_addr;
  wire [31:0] k_data;
  wire [3:0]  k_be;
  reg         k_go;
  generate
    if (SMALL == 0) begin : clear_engine
      core_clear #(.ADDR_W(ADDR_W)) clear (
          .clk(clk), .rst(rst), .start(k_go), .base16(k_base), .bpp_log2(k_bpp), .pattern(k_pattern),
          .width(k_w), .x0(k_x0), .y0(k_y0), .x1(k_x1), .y1(k_y1), .busy(k_busy),
          .wr_valid(k_valid), .wr_ready(k_ready), .wr_addr(k_addr), .wr_data(k_data), .wr_be(k_be));
    end else begin : no_clear_engine
      assign k_busy  = 1'b0;
      assign k_valid = 1'b0;
      assign k_addr  = 30'd0;
      assign k_data  = 32'd0;
      assign k_be    = 4'd0;
    end
  endgenerate

  // ---------------------------------------------------------------- memory port
  wire m_idle, m_pending;
  wire pipe_idle = !ras_active && ras_op == 2'd0 && !ras_emit && !emit2;
  wire stages_idle = d_idle && t_idle && c_idle;
  wire drained = pipe_idle && stages_idle && m_idle && !k_busy;
  wire idle_now;  // the pipeline-empty test; the port core_idle is it a clock late
  core_memport #(.TAGS_AW((SMALL != 0) ? 1 : 3), .COMBINE(1 - SMALL), .SKID(SMALL), .READS_FIRST(1 - SMALL)) memport (
      .clk(clk), .rst(rst), .flush(!ras_active || r_serial),
      .clr_valid(k_valid), .clr_ready(k_ready), .clr_addr(k_addr), .clr_data(k_data), .clr_be(k_be),
      .cw_valid(cw_valid), .cw_ready(cw_ready), .cw_addr(cw_addr), .cw_data(cw_data), .cw_be(cw_be),
      .cr_valid(cr_valid), .cr_ready(cr_ready), .cr_addr(cr_addr), .cr_rsp(cr_rsp),
      .tr_valid(tr_valid), .tr_ready(tr_ready), .tr_addr(tr_addr), .tr_rsp(tr_rsp),
      .zw_valid(zw_valid), .zw_ready(zw_ready), .zw_addr(zw_addr), .zw_data(zw_data),
      .zr_valid(zr_valid), .zr_ready(zr_ready), .zr_addr(zr_addr), .zr_rsp(zr_rsp),
      .mem_req_valid(mem_req_valid), .mem_req_ready(mem_req_ready), .mem_req_we(mem_req_we),
      .mem_req_addr(mem_req_addr), .mem_req_wdata(mem_req_wdata), .mem_req_be(mem_req_be),
      .mem_rsp_valid(mem_rsp_valid), .idle(m_idle), .pending_write(m_pending));

  // the raster pipeline advances unless an emitted pixel waits; in serial mode the rasteriser
  // moves only when every earlier pixel has left the core
  assign pipe_ok = !emit2 || d_in_ready;
  assign hold = r_serial && (ras_emit || emit2 || !stages_idle || !m_idle);

  // ---------------------------------------------------------------- command sequencer
  localparam [1:0] C_IDLE = 2'd0, C_SETUP = 2'd1, C_DRAIN = 2'd2;
  reg [1:0] cst;
  reg       accept;
  assign draw_go = (cst == C_DRAIN) && drained;
  assign cmd_ready = accept;

  // clear values, truncated to the format (section 12)
  wire [31:0] cc = cmd_clear_color;
  wire [15:0] c565 = {cc[31:27], cc[23:18], cc[15:11]};
  wire [7:0]  c2222 = {cc[31:30], cc[23:22], cc[15:14], cc[7:6]};
  wire [31:0] cpat = (cmd_fb_format == 2'd1) ? {2{c565}} : (cmd_fb_format == 2'd2) ? {4{c2222}} : cc;

  always @(posedge clk) begin
    accept   <= 1'b0;
    su_go    <= 1'b0;
    ras_go   <= 1'b0;
    k_go     <= 1'b0;
    tc_inval <= 1'b0;
    if (rst || idle_now) tc_keep <= 1'b0;
    if (rst) begin
      cst <= C_IDLE;
      colour_on_r <= 1'b1;
      r_serial <= 1'b0;
      r_rect <= 1'b0;
      r_zsel <= 1'b0;
      r_need <= 8'd0;
    end else begin
      case (cst)
        C_IDLE: if (cmd_valid && !accept) begin
          if (cmd_op == OP_TRI) begin
            if (writes_nothing || clip_empty) begin
              accept <= 1'b1;  // draws nothing, touches no memory
            end else if (pipe_idle && !su_busy) begin
              su_go <= 1'b1;
              cst   <= C_SETUP;
            end
          end else begin
            // CLEAR / CLEAR_Z after every earlier pixel is written
            if (clip_empty || cmd_op == 2'd3) begin
              accept <= 1'b1;
            end else if (SMALL != 0) begin
              if (pipe_idle && !su_busy) begin  // the clip rectangle, set up like a triangle
                su_go <= 1'b1;
                cst   <= C_SETUP;
              end
            end else if (drained && !su_busy) begin
              accept    <= 1'b1;
              k_go      <= 1'b1;
              tc_keep   <= 1'b0;
              k_base    <= (cmd_op == OP_CLEAR) ? cmd_fb_draw : cmd_fb_z;
              k_bpp     <= (cmd_op == OP_CLEAR_Z || cmd_fb_format == 2'd0) ? 2'd2 :
                           (cmd_fb_format == 2'd1) ? 2'd1 : 2'd0;
              k_pattern <= (cmd_op == OP_CLEAR) ? cpat : {8'd0, cmd_clear_depth};
              k_w       <= cmd_fb_width;
              k_x0      <= sc_x0;
              k_y0      <= sc_y0;
              k_x1      <= clip_x1;
              k_y1      <= clip_y1;
            end
          end
        end
        C_SETUP: if (su_done) cst <= su_draw ? C_DRAIN : C_IDLE;
                 else if (!su_busy && !su_go) cst <= C_SETUP;
        default: if (drained) begin  // C_DRAIN
          accept      <= 1'b1;
          ras_go      <= 1'b1;
          cst         <= C_IDLE;
          r_fmt       <= cmd_fb_format;
          r_fb_draw   <= (SMALL != 0) ? fold_base(cmd_fb_draw) : cmd_fb_draw;
          r_fb_z      <= cmd_fb_z;
          r_tex_base  <= cmd_tex_base;
          r_tex_fmt   <= cmd_tex_fmt;
          r_width     <= cmd_fb_width;
          r_rect      <= (cmd_op != OP_TRI);
          r_zsel      <= (cmd_op != OP_TRI);
          tc_keep <= (cmd_op == OP_TRI) && tc_ok_n;
          tc_sig  <= tc_sig_n;
          tc_inval <= !(tc_keep && (cmd_op == OP_TRI) && tc_ok_n && tc_sig == tc_sig_n);
          if (cmd_op == OP_TRI) begin
            r_gouraud   <= m_gouraud;
            r_tex       <= tex_on;
            r_ztest     <= m_ztest;
            r_zfunc     <= m_zfunc;
            r_zwrite    <= m_zwrite;
            r_blend     <= cmd_tri_mode[8:7];
            r_dither    <= cmd_tri_mode[9];
            r_temporal  <= cmd_tri_mode[15];
            r_phase     <= cmd_tri_mode[19:16];
            r_keep      <= m_keep;
            r_decal     <= cmd_tri_mode[14];
            // v0's COLOR: the setup leaves the read port on it when idle (up5k)
            r_flat      <= (SMALL != 0) ? vp_data : cmd_v0[87:56];
            r_serial    <= serial_n;
            r_need      <= need;
            r_need_dst  <= (cmd_tri_mode[8:7] != 2'd0) || (some_masked && !all_masked && cmd_fb_format != 2'd0);
            colour_on_r <= colour_on;
          end else begin
            // a clear drawn as a rectangle: CLEAR_COLOR truncated (no dither, blend or mask), or
            // CLEAR_DEPTH written
            r_gouraud   <= 1'b0;
            r_tex       <= 1'b0;
            r_ztest     <= 1'b0;
            r_zwrite    <= (cmd_op == OP_CLEAR_Z) && DEPTH != 0;
            r_blend     <= 2'd0;
            r_dither    <= 1'b0;
            r_temporal  <= 1'b0;
            r_keep      <= 4'd0;
            // CLEAR_Z writes no colour, so r_flat carries its depth (one register, not two)
            // (up5k: the value through the read port, which the idle setup leaves on it)
            r_flat      <= (SMALL != 0) ? vp_data : (cmd_op == OP_CLEAR_Z) ? {8'd0, cmd_clear_depth} : cmd_clear_color;
            r_serial    <= 1'b0;
            r_need      <= 8'd0;
            r_need_dst  <= 1'b0;
            colour_on_r <= (cmd_op == OP_CLEAR);
          end
        end
      endcase
      if (cst == C_SETUP && su_done && !su_draw) accept <= 1'b1;
    end
  end

  assign idle_now = (cst == C_IDLE) && !cmd_valid && !accept && !su_busy && drained && !k_go && !ras_go;

  // The soc sees the pipeline-empty test a clock late (issue 19, 25.125 MHz on the UP5K): the
  // test (the rasteriser's emit and state, the memory port, setup) reached the soc's command FIFO
  // pop through command_exec in one clock. Registered it can be late, never early: the core leaves
  // idle only on a command the soc presents (cmd_valid, in the test), so the clock after that the
  // flip-flop already says busy, and in the clock itself the soc's users that act on it see no
  // core command at the FIFO's head (command_exec waits on it only for FENCE, FB_DISPLAY and the
  // MEM_* registers; the RESET drain and STATUS.BUSY also look at cmd_valid / the FIFO's level).
  // Becoming idle is a clock late: a command waiting on it starts a clock later.
  always @(posedge clk) core_idle <= !rst && idle_now;

  // ---------------------------------------------------------------- counters
  generate
    if (PERF != 0) begin : counters
      always @(posedge clk) begin
        if (rst) begin
          perf_triangles <= 32'd0;
          perf_pixels    <= 32'd0;
          perf_passed    <= 32'd0;
          perf_textured  <= 32'd0;
          perf_busy      <= 32'd0;
          perf_setup     <= 32'd0;
          perf_raster    <= 32'd0;
        end else begin
          if (su_done && su_draw && cmd_op == OP_TRI) perf_triangles <= perf_triangles + 32'd1;
          if (emit2 && d_in_ready && !r_rect) perf_pixels <= perf_pixels + 32'd1;
          if (d_passed && !r_rect) perf_passed <= perf_passed + 32'd1;
          if (t_count) perf_textured <= perf_textured + 32'd1;
          if (!idle_now) perf_busy <= perf_busy + 32'd1;
          if (su_busy) perf_setup <= perf_setup + 32'd1;
          if (ras_active) perf_raster <= perf_raster + 32'd1;
        end
      end
    end else begin : no_counters
      always @(*) begin
        perf_triangles = 32'd0;
        perf_pixels    = 32'd0;
        perf_passed    = 32'd0;
        perf_textured  = 32'd0;
        perf_busy      = 32'd0;
        perf_setup     = 32'd0;
        perf_raster    = 32'd0;
      end
    end
  endgenerate
  // what a profile does not use (the generate blocks that read it are absent) or nothing reads
  wire unused_ok = &{1'b0, ras_e0, pw_q[31:24], r_tex, r_decal, r_tex_base, r_tex_fmt, r_need, k_base,
                     k_bpp, k_pattern, k_w, k_x0, k_y0, k_x1, k_y1, a_stq, d_passed, d_out, tr_ready,
                     tr_rsp, t_count, cmd_tri_mode[31:20], k_ready, m_pending, tc_inval, r_flat, r_zsel,
                     draw_go};
endmodule
