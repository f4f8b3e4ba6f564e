// Co-simulation top level: the device (spigpu_top) as a board sees it, cut at the SPI pins, plus the
// behavioural SDRAM chip for the ecp5 profile. Verilated once per profile (backends/rtl); the harness
// drives clk, rst and the SPI pins and reads MISO, BUSY, the scanned-out frames and the counters.
// Display timing is short (LINE_CLOCKS x V_TOTAL core clocks per refresh) so that swaps wait little.
module spigpu_sim #(
  parameter PROFILE     = 0,
  parameter CLK_MHZ     = PROFILE == 0 ? 25 : 50,
  parameter LINE_CLOCKS = 64,
  parameter V_ACTIVE    = 8,
  parameter V_TOTAL     = 10
) (
  input  wire        clk,
  input  wire        rst,
  input  wire        spi_sck,
  input  wire        spi_cs_n,
  input  wire        spi_mosi,
  output wire        spi_miso,
  output wire        spi_miso_oe,
  output wire        busy_pin,
  output wire        vblank,
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
  output wire [31:0] perf_triangles,
  output wire [31:0] perf_pixels,
  output wire [31:0] perf_passed,
  output wire [31:0] perf_textured,
  output wire [31:0] perf_core_busy,
  output wire [31:0] perf_setup,
  output wire [31:0] perf_raster,
  output wire [31:0] sdram_violations
);
  wire        sd_cke, sd_cs_n, sd_ras_n, sd_cas_n, sd_we_n, sd_dq_oe;
  wire [1:0]  sd_ba, sd_dqm;
  wire [12:0] sd_a;
  wire [15:0] sd_dq_o, sd_dq_i;
  wire        vsync;
  // the board video output is not part of the co-simulation (VIDEO = 0: these read 0)
  wire        video_pix_en, video_hsync, video_vsync, video_de;
  wire [3:0]  video_r, video_g, video_b;
  wire        unused_video = &{1'b0, video_pix_en, video_hsync, video_vsync, video_de, video_r, video_g, video_b};

  spigpu_top #(.PROFILE(PROFILE), .CLK_MHZ(CLK_MHZ), .LINE_CLOCKS(LINE_CLOCKS), .V_ACTIVE(V_ACTIVE),
               .V_TOTAL(V_TOTAL), .PERF(1)) dut (
    .clk(clk), .rst(rst), .pclk(1'b0), .spi_sck(spi_sck), .spi_cs_n(spi_cs_n), .spi_mosi(spi_mosi), .spi_miso(spi_miso),
    .spi_miso_oe(spi_miso_oe), .busy_pin(busy_pin), .sd_cke(sd_cke), .sd_cs_n(sd_cs_n), .sd_ras_n(sd_ras_n),
    .sd_cas_n(sd_cas_n), .sd_we_n(sd_we_n), .sd_ba(sd_ba), .sd_a(sd_a), .sd_dqm(sd_dqm), .sd_dq_o(sd_dq_o),
    .sd_dq_oe(sd_dq_oe), .sd_dq_i(sd_dq_i), .vblank(vblank), .vsync(vsync), .frame_valid(frame_valid),
    .frame_word(frame_word), .frame_nbytes(frame_nbytes), .frame_start(frame_start), .frame_end(frame_end),
    .frame_format(frame_format), .frame_width(frame_width), .frame_height(frame_height), .perf_cycles(perf_cycles),
    .perf_work_cycles(perf_work_cycles), .perf_cmds(perf_cmds), .perf_frames(perf_frames),
    .perf_core_stalls(perf_core_stalls), .perf_refreshes(perf_refreshes), .perf_triangles(perf_triangles),
    .perf_pixels(perf_pixels), .perf_passed(perf_passed), .perf_textured(perf_textured),
    .perf_core_busy(perf_core_busy), .perf_setup(perf_setup), .perf_raster(perf_raster),
    .video_pix_en(video_pix_en), .video_hsync(video_hsync), .video_vsync(video_vsync), .video_de(video_de),
    .video_r(video_r), .video_g(video_g), .video_b(video_b));

  generate
    if (PROFILE == 1) begin : g_sdram
      wire [15:0] chip_dq;
      wire        chip_oe;
      wire [31:0] reads, writes, activates;
      sdram_model #(.CLK_MHZ(CLK_MHZ)) chip (
        .clk(clk), .cke(sd_cke), .cs_n(sd_cs_n), .ras_n(sd_ras_n), .cas_n(sd_cas_n), .we_n(sd_we_n), .ba(sd_ba),
        .a(sd_a), .dqm(sd_dqm), .dq_in(sd_dq_o), .dq_in_oe(sd_dq_oe), .dq_out(chip_dq), .dq_out_oe(chip_oe),
        .violations(sdram_violations), .reads(reads), .writes(writes), .activates(activates));
      assign sd_dq_i = chip_oe ? chip_dq : 16'hFFFF;
      wire unused_counts = &{1'b0, reads, writes, activates};
    end else begin : g_none
      assign sd_dq_i = 16'hFFFF;
      assign sdram_violations = 32'd0;
      wire unused_sd = &{1'b0, sd_cke, sd_cs_n, sd_ras_n, sd_cas_n, sd_we_n, sd_ba, sd_a, sd_dqm, sd_dq_o, sd_dq_oe};
    end
  endgenerate
  wire unused_vsync = &{1'b0, vsync};
endmodule
