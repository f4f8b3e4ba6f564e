// spigpu v1 device (docs/protocol.md sections 2-13), one clock domain. The profile parameter picks
// what the device has; CAPS reports exactly that (docs/gateware.md "Profiles"):
//   PROFILE 0 "up5k": iCE40 UP5K, 128 KiB SPRAM as VRAM, 320 x 240 at most, FIFO 64, no texturing,
//                     bilinear, blending or depth buffer (CAPS2, protocol 1.4);
//   PROFILE 1 "ecp5": ECP5-85F, 32 MiB SDR SDRAM as VRAM, 1024 x 768 at most, FIFO 1023, every feature.
// Display timing is in core clocks (LINE_CLOCKS x V_TOTAL lines, V_ACTIVE visible); the board top
// levels set it for 640 x 480 at 60 Hz, the co-simulation uses a short frame.
// VIDEO = 1 adds a board's video output (soc/video_out.v: the displayed buffer every refresh, its own
// memory-arbiter client and line buffer); the co-simulation and the rtl tests keep VIDEO = 0, where
// the video_* outputs are 0 and the arbiter's video client is tied off. LINE_CLOCKS must then be
// 800 x VIDEO_PIX_DIV, so that the scanout's vertical sync is the video's; with VIDEO_PCLK = 1 the pixels
// run on their own clock pclk, the scanout's timing advances once per pixel (video_out's synchronised
// tick) and LINE_CLOCKS is 800.
module spigpu_top #(
  parameter PROFILE     = 0,
  parameter CLK_MHZ     = PROFILE == 0 ? 25 : 50,
  parameter CLK_KHZ     = CLK_MHZ * 1000,   // the core clock the SDRAM's timings are converted with
  parameter LINE_CLOCKS = PROFILE == 0 ? 800 : 1600,
  parameter V_ACTIVE    = 480,
  parameter V_TOTAL     = 525,
  parameter PERF        = 0,      // 1: performance counters for the co-simulation
  parameter VIDEO       = 0,      // 1: video output (board top levels)
  parameter VIDEO_PIX_DIV    = 1, // core clocks per pixel
  parameter VIDEO_SCALE_LOG2 = 1, // framebuffer pixels shown 2^n x 2^n
  parameter VIDEO_LINE_AW    = 8, // line buffer: 2 x 2^n words
  parameter VIDEO_BITS       = 4, // bits per colour channel at the pins
  parameter VIDEO_CENTRE     = 1, // a smaller framebuffer centred (1) or at the top left (0)
  parameter VIDEO_PCLK       = 0  // 1: pixels on pclk, not on clk (docs/gateware.md "Video out")
) (
  input  wire        clk,
  input  wire        rst,
  input  wire        pclk,        // VIDEO_PCLK = 1: the pixel clock (else unused)
  input  wire        spi_sck,
  input  wire        spi_cs_n,
  input  wire        spi_mosi,
  output wire        spi_miso,
  output wire        spi_miso_oe,
  output wire        busy_pin,
  output wire        sd_cke,
  output wire        sd_cs_n,
  output wire        sd_ras_n,
  output wire        sd_cas_n,
  output wire        sd_we_n,
  output wire [1:0]  sd_ba,
  output wire [12:0] sd_a,
  output wire [1:0]  sd_dqm,
  output wire [15:0] sd_dq_o,
  output wire        sd_dq_oe,
  input  wire [15:0] sd_dq_i,
  output wire        vblank,
  output wire        vsync,
  output wire        frame_valid,
  output wire [31:0] frame_word,
  output wire [2:0]  frame_nbytes,
  output wire        frame_start,
  output wire        frame_end,
  output wire [1:0]  frame_format,
  output wire [10:0] frame_width,
  output wire [10:0] frame_height,
  output wire [31:0] perf_cycles,
  output wire [31:0] perf_work_cycles,
  output wire [31:0] perf_cmds,
  output wire [31:0] perf_frames,
  output wire [31:0] perf_core_stalls,
  output wire [31:0] perf_refreshes,
  // render core counters (gw-core's set, docs/gateware.md)
  output wire [31:0] perf_triangles,
  output wire [31:0] perf_pixels,
  output wire [31:0] perf_passed,
  output wire [31:0] perf_textured,
  output wire [31:0] perf_core_busy,
  output wire [31:0] perf_setup,
  output wire [31:0] perf_raster,
  // video output (VIDEO = 1): pixel enable, syncs at pin level (low pulses), data enable, colour
  output wire        video_pix_en,
  output wire        video_hsync,
  output wire        video_vsync,
  output wire        video_de,
  output wire [VIDEO_BITS-1:0] video_r,
  output wire [VIDEO_BITS-1:0] video_g,
  output wire [VIDEO_BITS-1:0] video_b
);
  // CAPS.FEATURES: bit 0 bilinear, 1 blend, 2 dither, 3 strict link, 4 RGB565, 5 RGBA2222,
  // 6 temporal dither (protocol 1.1), 7 texturing (protocol 1.2). up5k: dither, strict link, RGB565,
  // RGBA2222 (no bilinear, blend, temporal dither or texture unit: they do not fit the 5,280 LUTs
  // beside the rest). ecp5: everything.
  localparam [7:0]  FEATURES   = PROFILE == 0 ? 8'h3C : 8'hFF;
  localparam [7:0]  CORE_FEATURES = FEATURES;
  // CAPS2.FEATURES2 bit 0 (protocol 1.4): the depth buffer. up5k has none: it cost 458 packed logic
  // cells and a SB_MAC16 the part has no room for (docs/gateware.md); ecp5 has it.
  localparam        DEPTH      = PROFILE == 0 ? 0 : 1;
  localparam        MAX_WIDTH  = PROFILE == 0 ? 320 : 1024;
  localparam        MAX_HEIGHT = PROFILE == 0 ? 240 : 768;
  localparam        FIFO_DEPTH = PROFILE == 0 ? 64 : 1023;
  localparam        FIFO_AW    = PROFILE == 0 ? 7 : 10;
  localparam        VRAM_KIB   = PROFILE == 0 ? 128 : 32768;
  localparam [15:0] VARIANT    = PROFILE == 0 ? 16'h0001 : 16'h0002;
  localparam        CRC_BYTES  = PROFILE == 0 ? 1 : 4;
  localparam        SCAN_BUF   = PROFILE == 0 ? 2 : 4;

  wire         cmd_valid, cmd_ready, core_idle;
  wire [1:0]   cmd_op, cmd_fb_format;
  wire [31:0]  cmd_tri_mode, cmd_clear_color;
  wire [27:0]  cmd_tex_base, cmd_fb_draw, cmd_fb_z;
  wire [17:0]  cmd_tex_fmt;
  wire [43:0]  cmd_scissor;
  wire [10:0]  cmd_fb_width, cmd_fb_height;
  wire [23:0]  cmd_clear_depth;
  wire [183:0] cmd_v0, cmd_v1, cmd_v2;
  wire [3:0]   vp_addr;
  wire [31:0]  vp_data;
  wire         mem_req_valid, mem_req_ready, mem_req_we, mem_rsp_valid;
  wire [29:0]  mem_req_addr;
  wire [31:0]  mem_req_wdata, mem_rsp_rdata;
  wire [3:0]   mem_req_be;
  wire         v_req_valid, v_req_ready, v_rsp_valid, disp_tick;
  wire [10:0]  disp_hcount, disp_vcount;
  wire [27:0]  disp_frame_addr;
  wire [29:0]  v_req_addr;

  spigpu_soc #(
    .PROFILE(PROFILE), .FEATURES(FEATURES), .DEPTH(DEPTH), .MAX_WIDTH(MAX_WIDTH), .MAX_HEIGHT(MAX_HEIGHT),
    .FIFO_DEPTH(FIFO_DEPTH), .FIFO_AW(FIFO_AW), .VRAM_KIB(VRAM_KIB), .VARIANT(VARIANT), .CLK_MHZ(CLK_MHZ), .CLK_KHZ(CLK_KHZ),
    .LINE_CLOCKS(LINE_CLOCKS), .V_ACTIVE(V_ACTIVE), .V_TOTAL(V_TOTAL), .CRC_BYTES(CRC_BYTES),
    .SCAN_BUF(SCAN_BUF), .PERF(PERF)
  ) u_soc (
    .clk(clk), .rst(rst), .spi_sck(spi_sck), .spi_cs_n(spi_cs_n), .spi_mosi(spi_mosi), .spi_miso(spi_miso),
    .spi_miso_oe(spi_miso_oe), .busy_pin(busy_pin), .sd_cke(sd_cke), .sd_cs_n(sd_cs_n), .sd_ras_n(sd_ras_n),
    .sd_cas_n(sd_cas_n), .sd_we_n(sd_we_n), .sd_ba(sd_ba), .sd_a(sd_a), .sd_dqm(sd_dqm), .sd_dq_o(sd_dq_o),
    .sd_dq_oe(sd_dq_oe), .sd_dq_i(sd_dq_i), .cmd_valid(cmd_valid), .cmd_ready(cmd_ready), .cmd_op(cmd_op),
    .cmd_tri_mode(cmd_tri_mode), .cmd_tex_base(cmd_tex_base), .cmd_tex_fmt(cmd_tex_fmt), .cmd_scissor(cmd_scissor),
    .cmd_fb_draw(cmd_fb_draw), .cmd_fb_z(cmd_fb_z), .cmd_fb_format(cmd_fb_format), .cmd_fb_width(cmd_fb_width),
    .cmd_fb_height(cmd_fb_height), .cmd_clear_color(cmd_clear_color), .cmd_clear_depth(cmd_clear_depth),
    .cmd_v0(cmd_v0), .cmd_v1(cmd_v1), .cmd_v2(cmd_v2), .vp_addr(vp_addr), .vp_data(vp_data),
    .core_idle(core_idle), .mem_req_valid(mem_req_valid),
    .mem_req_ready(mem_req_ready), .mem_req_we(mem_req_we), .mem_req_addr(mem_req_addr),
    .mem_req_wdata(mem_req_wdata), .mem_req_be(mem_req_be), .mem_rsp_valid(mem_rsp_valid),
    .mem_rsp_rdata(mem_rsp_rdata), .vblank(vblank), .vsync(vsync), .frame_valid(frame_valid),
    .frame_word(frame_word), .frame_nbytes(frame_nbytes), .frame_start(frame_start), .frame_end(frame_end),
    .frame_format(frame_format), .frame_width(frame_width), .frame_height(frame_height), .perf_cycles(perf_cycles),
    .perf_work_cycles(perf_work_cycles), .perf_cmds(perf_cmds), .perf_frames(perf_frames),
    .perf_core_stalls(perf_core_stalls), .perf_refreshes(perf_refreshes), .disp_tick(disp_tick), .disp_hcount(disp_hcount),
    .disp_vcount(disp_vcount), .disp_frame_addr(disp_frame_addr), .v_req_valid(v_req_valid), .v_req_ready(v_req_ready), .v_req_addr(v_req_addr),
    .v_rsp_valid(v_rsp_valid));

  generate
    if (VIDEO != 0) begin : g_video
      localparam VAW = PROFILE == 0 ? 15 : 23;
      video_out #(.VAW(VAW), .PIX_DIV(VIDEO_PIX_DIV), .SCALE_LOG2(VIDEO_SCALE_LOG2),
                  .LINE_AW(VIDEO_LINE_AW), .OUT_BITS(VIDEO_BITS), .CENTRE(VIDEO_CENTRE), .PCLK(VIDEO_PCLK),
                  .ICE40(PROFILE == 0 ? 1 : 0)) u_video (
        .clk(clk), .rst(rst), .pclk(pclk), .tick(disp_tick), .hcount(disp_hcount), .vcount(disp_vcount), .frame_start(frame_start),
        .frame_addr(disp_frame_addr),
        .frame_format(frame_format), .frame_width(frame_width), .frame_height(frame_height),
        .req_valid(v_req_valid), .req_ready(v_req_ready), .req_addr(v_req_addr), .rsp_valid(v_rsp_valid),
        .rsp_rdata(mem_rsp_rdata), .pix_en(video_pix_en), .hsync(video_hsync), .vsync(video_vsync), .de(video_de),
        .red(video_r), .green(video_g), .blue(video_b));
    end else begin : g_novideo
      assign v_req_valid = 1'b0;
      assign v_req_addr = 30'd0;
      assign disp_tick = 1'b1;
      assign {video_pix_en, video_hsync, video_vsync, video_de} = 4'd0;
      assign {video_r, video_g, video_b} = {(3 * VIDEO_BITS){1'b0}};
      wire unused_video = &{1'b0, pclk, disp_hcount, disp_vcount, disp_frame_addr, v_req_ready, v_rsp_valid};
    end
  endgenerate

  spigpu_core #(.PROFILE(PROFILE), .FEATURES(CORE_FEATURES), .MAX_WIDTH(MAX_WIDTH), .MAX_HEIGHT(MAX_HEIGHT),
                .VRAM_KIB(VRAM_KIB), .DEPTH(DEPTH), .PERF(PERF)) u_core (
    .clk(clk), .rst(rst), .cmd_valid(cmd_valid), .cmd_ready(cmd_ready), .cmd_op(cmd_op),
    .cmd_tri_mode(cmd_tri_mode), .cmd_tex_base(cmd_tex_base), .cmd_tex_fmt(cmd_tex_fmt), .cmd_scissor(cmd_scissor),
    .cmd_fb_draw(cmd_fb_draw), .cmd_fb_z(cmd_fb_z), .cmd_fb_format(cmd_fb_format), .cmd_fb_width(cmd_fb_width),
    .cmd_fb_height(cmd_fb_height), .cmd_clear_color(cmd_clear_color), .cmd_clear_depth(cmd_clear_depth),
    .cmd_v0(cmd_v0), .cmd_v1(cmd_v1), .cmd_v2(cmd_v2), .vp_addr(vp_addr), .vp_data(vp_data),
    .core_idle(core_idle), .mem_req_valid(mem_req_valid),
    .mem_req_ready(mem_req_ready), .mem_req_we(mem_req_we), .mem_req_addr(mem_req_addr),
    .mem_req_wdata(mem_req_wdata), .mem_req_be(mem_req_be), .mem_rsp_valid(mem_rsp_valid),
    .mem_rsp_rdata(mem_rsp_rdata), .perf_triangles(perf_triangles), .perf_pixels(perf_pixels),
    .perf_passed(perf_passed), .perf_textured(perf_textured), .perf_busy(perf_core_busy), .perf_setup(perf_setup),
    .perf_raster(perf_raster));
endmodule
