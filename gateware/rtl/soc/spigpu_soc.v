// Everything of the spigpu device except the render core: SPI slave, link integrity, register file,
// command FIFO, executor with primitive assembly, memory-access unit, memory arbiter, video memory
// (SPRAM or SDRAM controller) and scanout. spigpu_top connects it to the render core.
module spigpu_soc #(
  parameter        PROFILE     = 0,          // 0 up5k, 1 ecp5
  parameter [7:0]  FEATURES    = 8'h38,
  parameter        DEPTH       = 1,          // CAPS2.FEATURES2 bit 0: the depth buffer (protocol 1.4)
  parameter        MAX_WIDTH   = 320,
  parameter        MAX_HEIGHT  = 240,
  parameter        FIFO_DEPTH  = 64,
  parameter        FIFO_AW     = 7,
  parameter        VRAM_KIB    = 128,
  parameter [15:0] VARIANT     = 16'h0001,
  parameter        CLK_MHZ     = 25,
  parameter        CLK_KHZ     = CLK_MHZ * 1000,  // the SDRAM's timings are converted with it
  parameter        LINE_CLOCKS = 800,        // display timing in core clocks
  parameter        V_ACTIVE    = 480,
  parameter        V_TOTAL     = 525,
  parameter        CRC_BYTES   = 1,
  parameter        SCAN_BUF    = 2,          // scanout read-ahead words
  parameter        PERF        = 0           // 1: the perf_* counters exist (co-simulation), 0: they read 0
) (
  input  wire         clk,
  input  wire         rst,
  // SPI
  input  wire         spi_sck,
  input  wire         spi_cs_n,
  input  wire         spi_mosi,
  output wire         spi_miso,
  output wire         spi_miso_oe,
  output wire         busy_pin,
  // SDRAM (ecp5; constant for up5k)
  output wire         sd_cke,
  output wire         sd_cs_n,
  output wire         sd_ras_n,
  output wire         sd_cas_n,
  output wire         sd_we_n,
  output wire [1:0]   sd_ba,
  output wire [12:0]  sd_a,
  output wire [1:0]   sd_dqm,
  output wire [15:0]  sd_dq_o,
  output wire         sd_dq_oe,
  input  wire [15:0]  sd_dq_i,
  // render core
  output wire         cmd_valid,
  input  wire         cmd_ready,
  output wire [1:0]   cmd_op,
  output wire [31:0]  cmd_tri_mode,
  output wire [27:0]  cmd_tex_base,
  output wire [17:0]  cmd_tex_fmt,
  output wire [43:0]  cmd_scissor,
  output wire [27:0]  cmd_fb_draw,
  output wire [27:0]  cmd_fb_z,
  output wire [1:0]   cmd_fb_format,
  output wire [10:0]  cmd_fb_width,
  output wire [10:0]  cmd_fb_height,
  output wire [31:0]  cmd_clear_color,
  output wire [23:0]  cmd_clear_depth,
  output wire [183:0] cmd_v0,
  output wire [183:0] cmd_v1,
  output wire [183:0] cmd_v2,
  input  wire [3:0]   vp_addr,        // the vertex read port (up5k; docs/gateware.md "soc <-> core")
  output wire [31:0]  vp_data,
  input  wire         core_idle,      // the core's pipeline-empty test a clock late (never early)
  input  wire         mem_req_valid,
  output wire         mem_req_ready,
  input  wire         mem_req_we,
  input  wire [29:0]  mem_req_addr,
  input  wire [31:0]  mem_req_wdata,
  input  wire [3:0]   mem_req_be,
  output wire         mem_rsp_valid,
  output wire [31:0]  mem_rsp_rdata,
  // display
  output wire         vblank,
  output wire         vsync,
  output wire         frame_valid,
  output wire [31:0]  frame_word,
  output wire [2:0]   frame_nbytes,
  output wire         frame_start,
  output wire         frame_end,
  output wire [1:0]   frame_format,
  output wire [10:0]  frame_width,
  output wire [10:0]  frame_height,
  // a board's video output (video_out): the scanout's display timing, the latched frame's address
  // and a memory-arbiter client (tie v_req_valid to 0 where there is none, as the co-simulation does)
  input  wire         disp_tick,      // the display timing advances (1 unless the pixels have their own clock)
  output wire [10:0]  disp_hcount,
  output wire [10:0]  disp_vcount,
  output wire [27:0]  disp_frame_addr,
  input  wire         v_req_valid,
  output wire         v_req_ready,
  input  wire [29:0]  v_req_addr,
  output wire         v_rsp_valid,
  // counters for the co-simulation and the timing model (PERF = 1)
  output wire [31:0]  perf_cycles,        // clocks since power-on
  output wire [31:0]  perf_work_cycles,   // clocks with work (a released command, the core, MEM_*)
  output wire [31:0]  perf_cmds,          // FIFO entries executed
  output wire [31:0]  perf_frames,        // SPI frames completed
  output wire [31:0]  perf_core_stalls,   // clocks a core memory request waited
  output wire [31:0]  perf_refreshes      // SDRAM auto refreshes
);
`include "spigpu_regs.vh"
  localparam [9:0]  FIFO_D10 = FIFO_DEPTH;
  localparam [10:0] MAXW11 = MAX_WIDTH, MAXH11 = MAX_HEIGHT;
  localparam [23:0] VRAM24 = VRAM_KIB;
  localparam [63:0] CAPS = {FEATURES, FIFO_D10, MAXH11, MAXW11, VRAM24};
  localparam [63:0] CAPS2 = {63'd0, DEPTH != 0};                  // FEATURES2 [7:0]: bit 0 depth buffer
  localparam [63:0] ID_RESET = reg_reset(`SPIGPU_REG_ID);   // magic and protocol version from the table
  localparam [63:0] ID = {ID_RESET[63:16], VARIANT};
  localparam        VAW = PROFILE == 0 ? 15 : 23;      // back-end word address bits
  // the largest frame's bytes: FB_FORMAT holds at most MAX_WIDTH x MAX_HEIGHT, or its 640 x 480 reset value
  localparam integer SCAN_BYTES_W = $clog2((MAX_WIDTH > 640 ? MAX_WIDTH : 640) * (MAX_HEIGHT > 480 ? MAX_HEIGHT : 480) * 4 + 1);

  // --- SPI slave ---
  wire        rd_strobe, rd_from_ram;
  wire [6:0]  rd_idx;
  wire [63:0] rd_live, rd_ram;
  wire [5:0]  status_flags;
  wire        byte_valid, byte_first;
  wire [7:0]  byte_data;
  wire        f_valid, f_rw, f_abort;
  wire [6:0]  f_idx;
  wire [63:0] f_data;
  spi_slave u_spi (
    .clk(clk), .rst(rst), .spi_sck(spi_sck), .spi_cs_n(spi_cs_n), .spi_mosi(spi_mosi), .spi_miso(spi_miso),
    .spi_miso_oe(spi_miso_oe), .status_flags(status_flags), .rd_strobe(rd_strobe), .rd_idx(rd_idx),
    .rd_live(rd_live), .rd_from_ram(rd_from_ram), .rd_ram(rd_ram), .byte_valid(byte_valid), .byte_first(byte_first),
    .byte_data(byte_data), .frame_valid(f_valid), .frame_rw(f_rw), .frame_idx(f_idx), .frame_data(f_data),
    .frame_abort(f_abort));

  // --- register file, link integrity, command FIFO ---
  wire        soft_reset;
  wire        rst_any = rst || soft_reset;
  wire        fifo_push, fifo_push_held, fifo_full, fifo_nearly_full, fifo_held, fifo_out_valid, fifo_pop;
  wire        fifo_read_any;   // an entry waits in the FIFO's output (HEAD: in either of its two registers)
  wire [70:0] fifo_entry, fifo_out;
  wire [10:0] fifo_level;
  wire        link_strict, link_discarding, link_release, link_discard, err_link_crc, drop_overflow;
  wire        check_strobe, ctrl_strobe, ctrl_strict;
  wire [31:0] check_crc;
  wire [63:0] link_status;
  wire        sh_wr_req, sh_wr_ack;
  wire [4:0]  sh_wr_idx;
  wire [63:0] sh_wr_data;
  wire [6:0]  ex_err;
  wire        core_drain, core_range_err;
  wire        swap_pending_w, mem_ready, mem_read_strobe;
  wire [15:0] frame_count;
  wire [47:0] frame_crc;
  wire [28:0] mem_addr;
  wire [63:0] prefetch;
  wire        mem_err, scan_err;
  wire        mem_ex_idle;
  wire [6:0]  errors;
  // core_idle is a clock late and in the clock a command is first offered still says idle: the
  // FIFO's level counts that command (STATUS.BUSY), and the RESET drain looks at cmd_valid too
  // (a RESET in that clock must wait for the command the core may already have begun)
  wire        device_busy = fifo_level != 11'd0 || !core_idle || !mem_ex_idle;

  wire [4:0]  sh_rd_idx;
  wire [63:0] sh_rd_data;
  wire        sh_rd_valid;
  register_file #(.CAPS(CAPS), .CAPS2(CAPS2), .ID(ID), .FEATURES(FEATURES), .EX_READ(PROFILE == 0 ? 1 : 0)) u_regs (
    .clk(clk), .rst(rst), .frame_valid(f_valid), .frame_rw(f_rw), .frame_idx(f_idx), .frame_data(f_data),
    .frame_abort(f_abort), .rd_strobe(rd_strobe), .rd_idx(rd_idx), .rd_live(rd_live), .rd_from_ram(rd_from_ram),
    .rd_ram(rd_ram), .status_flags(status_flags), .fifo_push(fifo_push), .fifo_push_held(fifo_push_held),
    .fifo_entry(fifo_entry), .fifo_full(fifo_full), .fifo_nearly_full(fifo_nearly_full), .fifo_level(fifo_level),
    .fifo_held(fifo_held), .link_strict(link_strict), .link_discarding(link_discarding), .link_status(link_status),
    .err_link_crc(err_link_crc), .drop_overflow(drop_overflow), .link_check_strobe(check_strobe),
    .link_check_crc(check_crc), .link_ctrl_strobe(ctrl_strobe), .link_ctrl_strict(ctrl_strict),
    .soft_reset(soft_reset), .ex_wr_req(sh_wr_req), .ex_wr_idx(sh_wr_idx), .ex_wr_data(sh_wr_data),
    .ex_wr_ack(sh_wr_ack), .ex_rd_idx(sh_rd_idx), .ex_rd_data(sh_rd_data), .ex_rd_valid(sh_rd_valid),
    .err_set(ex_err | {mem_err || scan_err, 6'd0}), .core_range_err(core_range_err),
    .core_idle(core_idle && !cmd_valid), .core_drain(core_drain), .busy(device_busy), .vblank(vblank),
    .swap_pending(swap_pending_w), .frame_count(frame_count), .frame_crc(frame_crc), .mem_ready(mem_ready),
    .mem_addr(mem_addr), .prefetch(prefetch), .mem_read_strobe(mem_read_strobe), .errors(errors));

  link_integrity #(.DSP(PROFILE == 0 ? 1 : 0)) u_link (
    .clk(clk), .rst(rst_any), .byte_valid(byte_valid), .byte_first(byte_first), .byte_data(byte_data),
    .frame_valid(f_valid), .frame_idx(f_idx), .frame_abort(f_abort), .drop_overflow(drop_overflow),
    .check_strobe(check_strobe), .check_crc(check_crc), .ctrl_strobe(ctrl_strobe), .ctrl_strict(ctrl_strict),
    .strict(link_strict), .discarding(link_discarding), .release_held(link_release), .discard_held(link_discard),
    .err_link_crc(err_link_crc), .link_status(link_status));

  command_fifo #(.DEPTH(FIFO_DEPTH), .AW(FIFO_AW), .HEAD(PROFILE == 1 ? 1 : 0)) u_fifo (
    .clk(clk), .rst(rst_any), .push(fifo_push), .push_held(fifo_push_held), .push_entry(fifo_entry),
    .release_held(link_release), .discard_held(link_discard), .full(fifo_full), .nearly_full(fifo_nearly_full),
    .level(fifo_level), .held(fifo_held), .out_valid(fifo_out_valid), .out_entry(fifo_out), .read_any(fifo_read_any),
    .pop(fifo_pop));
  assign busy_pin = fifo_nearly_full;

  // --- executor ---
  wire        mem_set_addr, mem_addr_head, mem_write, mem_op_ack, executed, core_stall;
  wire [63:0] mem_op_data;
  wire        swap_req, swap_ready, waiting_vsync;
  wire [27:0] swap_addr;
  command_exec #(.FEATURES(FEATURES), .MAX_WIDTH(MAX_WIDTH), .MAX_HEIGHT(MAX_HEIGHT), .VRAM_KIB(VRAM_KIB), .DEPTH(DEPTH),
                 .VPORT(PROFILE == 0 ? 1 : 0), .IDX5(PROFILE == 0 ? 1 : 0)) u_exec (
    .clk(clk), .rst(rst_any), .in_valid(fifo_out_valid), .in_entry(fifo_out), .in_pop(fifo_pop),
    .sh_wr_req(sh_wr_req), .sh_wr_idx(sh_wr_idx), .sh_wr_data(sh_wr_data), .sh_wr_ack(sh_wr_ack),
    .sh_rd_idx(sh_rd_idx), .sh_rd_data(sh_rd_data), .sh_rd_valid(sh_rd_valid),
    .err_set(ex_err), .core_drain(core_drain), .cmd_valid(cmd_valid), .cmd_ready(cmd_ready), .cmd_op(cmd_op),
    .cmd_tri_mode(cmd_tri_mode), .cmd_tex_base(cmd_tex_base), .cmd_tex_fmt(cmd_tex_fmt), .cmd_scissor(cmd_scissor),
    .cmd_fb_draw(cmd_fb_draw), .cmd_fb_z(cmd_fb_z), .cmd_fb_format(cmd_fb_format), .cmd_fb_width(cmd_fb_width),
    .cmd_fb_height(cmd_fb_height), .cmd_clear_color(cmd_clear_color), .cmd_clear_depth(cmd_clear_depth),
    .cmd_v0(cmd_v0), .cmd_v1(cmd_v1), .cmd_v2(cmd_v2), .vp_addr(vp_addr), .vp_data(vp_data),
    .core_idle(core_idle), .mem_set_addr(mem_set_addr), .mem_addr_head(mem_addr_head),
    .mem_write(mem_write), .mem_op_data(mem_op_data), .mem_op_ack(mem_op_ack), .mem_idle(mem_ex_idle),
    .swap_req(swap_req), .swap_addr(swap_addr), .swap_ready(swap_ready), .waiting_vsync(waiting_vsync),
    .executed(executed));

  // --- memory-access unit, scanout, arbiter ---
  wire        m_req_valid, m_req_ready, m_req_we, m_rsp_valid;
  wire [29:0] m_req_addr;
  wire [31:0] m_req_wdata;
  wire        s_req_valid, s_req_ready, s_rsp_valid;
  wire [29:0] s_req_addr;
  wire [31:0] rsp_rdata;
  wire        prot_active;
  wire [VAW:0] prot_lo, prot_hi;
  mem_access #(.UNITS_L2(VAW - 1), .ICE40(PROFILE == 0 ? 1 : 0)) u_mem (
    .clk(clk), .rst(rst), .soft_reset(soft_reset), .set_addr(mem_set_addr), .set_addr_head(mem_addr_head), .write(mem_write),
    .op_data(mem_op_data), .op_ack(mem_op_ack), .ex_idle(mem_ex_idle), .read_strobe(mem_read_strobe), .addr(mem_addr),
    .prefetch(prefetch), .mem_ready(mem_ready), .err_range(mem_err), .req_valid(m_req_valid),
    .req_ready(m_req_ready), .req_we(m_req_we), .req_addr(m_req_addr), .req_wdata(m_req_wdata),
    .rsp_valid(m_rsp_valid), .rsp_rdata(rsp_rdata));

  scanout #(.VAW(VAW), .LINE_CLOCKS(LINE_CLOCKS), .V_ACTIVE(V_ACTIVE), .V_TOTAL(V_TOTAL),
            // the UP5K's SB_MAC16s hold setup, the swap length, the rasteriser's three edges and
            // LINK_STATUS's counters (u_link); the one the depth buffer's overlap check took is free
            // without it (DEPTH = 0) and holds FRAME_COUNT and the frame's read address (the counter
            // with a load costs the most cells of the scanout's; docs/gateware.md fit-soc5)
            .CRC_BYTES(CRC_BYTES), .BUF_WORDS(SCAN_BUF), .BYTES_W(SCAN_BYTES_W),
            .DSP(PROFILE == 0 && DEPTH == 0 ? 1 : 0), .CRC_ROM(PROFILE == 0 ? 1 : 0),
            .ICE40(PROFILE == 0 ? 1 : 0)) u_scan (
    .clk(clk), .rst(rst), .soft_reset(soft_reset), .tick(disp_tick), .swap_req(swap_req), .swap_addr(swap_addr),
    .swap_format(cmd_fb_format), .swap_width(cmd_fb_width), .swap_height(cmd_fb_height), .swap_ready(swap_ready),
    .swap_pending(swap_pending_w), .err_range(scan_err), .vblank(vblank), .vsync(vsync),
    .req_valid(s_req_valid), .req_ready(s_req_ready), .req_addr(s_req_addr), .rsp_valid(s_rsp_valid),
    .hcount(disp_hcount), .vcount(disp_vcount), .frame_addr(disp_frame_addr),
    .rsp_rdata(rsp_rdata), .prot_active(prot_active), .prot_lo(prot_lo), .prot_hi(prot_hi),
    .frame_count(frame_count), .frame_crc(frame_crc), .frame_valid(frame_valid), .frame_word(frame_word),
    .frame_nbytes(frame_nbytes), .frame_start(frame_start), .frame_end(frame_end), .frame_format(frame_format),
    .frame_width(frame_width), .frame_height(frame_height));

  wire           b_req_valid, b_req_ready, b_req_we, b_rsp_valid;
  wire [VAW-1:0] b_req_addr;
  wire [31:0]    b_req_wdata, b_rsp_rdata;
  wire [3:0]     b_req_be;
  mem_arbiter #(.AW(VAW), .TAG_AW(PROFILE == 0 ? 1 : 3)) u_arb (
    .clk(clk), .rst(rst), .v_req_valid(v_req_valid), .v_req_ready(v_req_ready), .v_req_addr(v_req_addr),
    .v_rsp_valid(v_rsp_valid), .m_req_valid(m_req_valid), .m_req_ready(m_req_ready), .m_req_we(m_req_we),
    .m_req_addr(m_req_addr), .m_req_wdata(m_req_wdata), .m_rsp_valid(m_rsp_valid), .s_req_valid(s_req_valid),
    .s_req_ready(s_req_ready), .s_req_addr(s_req_addr), .s_rsp_valid(s_rsp_valid), .c_req_valid(mem_req_valid),
    .c_req_ready(mem_req_ready), .c_req_we(mem_req_we), .c_req_addr(mem_req_addr), .c_req_wdata(mem_req_wdata),
    .c_req_be(mem_req_be), .c_rsp_valid(mem_rsp_valid), .rsp_rdata(rsp_rdata), .c_range_err(core_range_err),
    .prot_active(prot_active), .prot_lo(prot_lo), .prot_hi(prot_hi), .b_req_valid(b_req_valid),
    .b_req_ready(b_req_ready), .b_req_we(b_req_we), .b_req_addr(b_req_addr), .b_req_wdata(b_req_wdata),
    .b_req_be(b_req_be), .b_rsp_valid(b_rsp_valid), .b_rsp_rdata(b_rsp_rdata), .core_stall(core_stall));
  assign mem_rsp_rdata = rsp_rdata;

  wire refresh_pulse;
  generate
    if (PROFILE == 0) begin : g_spram
      vram_spram u_vram (
        .clk(clk), .req_valid(b_req_valid), .req_ready(b_req_ready), .req_we(b_req_we), .req_addr(b_req_addr),
        .req_wdata(b_req_wdata), .req_be(b_req_be), .rsp_valid(b_rsp_valid), .rsp_rdata(b_rsp_rdata));
      assign {sd_cke, sd_cs_n, sd_ras_n, sd_cas_n, sd_we_n} = 5'b01111;
      assign sd_ba = 2'd0;
      assign sd_a = 13'd0;
      assign sd_dqm = 2'b11;
      assign sd_dq_o = 16'd0;
      assign sd_dq_oe = 1'b0;
      assign refresh_pulse = 1'b0;
      wire unused_sd = &{1'b0, sd_dq_i};
    end else begin : g_sdram
      wire sd_init_done;
      sdram_ctrl #(.CLK_MHZ(CLK_MHZ), .CLK_KHZ(CLK_KHZ)) u_vram (
        .clk(clk), .rst(rst), .req_valid(b_req_valid), .req_ready(b_req_ready), .req_we(b_req_we),
        .req_addr(b_req_addr), .req_wdata(b_req_wdata), .req_be(b_req_be), .rsp_valid(b_rsp_valid),
        .rsp_rdata(b_rsp_rdata), .sd_cke(sd_cke), .sd_cs_n(sd_cs_n), .sd_ras_n(sd_ras_n), .sd_cas_n(sd_cas_n),
        .sd_we_n(sd_we_n), .sd_ba(sd_ba), .sd_a(sd_a), .sd_dqm(sd_dqm), .sd_dq_o(sd_dq_o), .sd_dq_oe(sd_dq_oe),
        .sd_dq_i(sd_dq_i), .init_done(sd_init_done), .refresh(refresh_pulse));
      wire unused_init = &{1'b0, sd_init_done};
    end
  endgenerate

  // --- counters (co-simulation only: 192 flip-flops and adders a board does not need) ---
  generate
    if (PERF != 0) begin : g_perf
      reg [31:0] cycles, work, cmds, frames, stalls, refreshes;
      always @(posedge clk) begin
        if (rst) begin
          {cycles, work, cmds, frames, stalls, refreshes} <= 192'd0;
        end else begin
          cycles <= cycles + 32'd1;
          if ((fifo_read_any && !waiting_vsync) || !core_idle || !mem_ex_idle) work <= work + 32'd1;
          if (executed) cmds <= cmds + 32'd1;
          if (f_valid) frames <= frames + 32'd1;
          if (core_stall) stalls <= stalls + 32'd1;
          if (refresh_pulse) refreshes <= refreshes + 32'd1;
        end
      end
      assign {perf_cycles, perf_work_cycles, perf_cmds, perf_frames, perf_core_stalls, perf_refreshes} =
             {cycles, work, cmds, frames, stalls, refreshes};
    end else begin : g_noperf
      assign {perf_cycles, perf_work_cycles, perf_cmds, perf_frames, perf_core_stalls, perf_refreshes} = 192'd0;
      wire unused_perf = &{1'b0, executed, core_stall, refresh_pulse, waiting_vsync, fifo_read_any};
    end
  endgenerate

  wire unused_ok = &{1'b0, errors};
endmodule
