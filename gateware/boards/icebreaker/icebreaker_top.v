// iCEBreaker (1BitSquared, iCE40 UP5K-SG48) top level: the up5k profile of spigpu with video out on
// the 12-bit DVI Pmod. Pins: icebreaker.pcf beside this file; clocks and choices: docs/gateware.md
// "Boards".
//
// - One clock domain, 25.125 MHz, from the PLL on the 12 MHz oscillator (12 x 67 / 32): the core
//   and the pixel clock are the same clock. 640 x 480 at 60 Hz asks for 25.175 MHz; 25.125 MHz gives
//   59.85 Hz, which monitors accept, and a second domain (a clock crossing for every pixel) would
//   cost logic cells the UP5K does not have.
// - SPI from the on-board FT2232H channel A: SCK, MOSI and MISO are the configuration flash's lines
//   (iceprog's wiring); chip select is ADBUS3, which reaches the FPGA on the red LED's net through the
//   board's AUX CS jumper, so the flash's own select (ADBUS4) stays high and the flash never answers:
//   the FPGA drives the flash select high as well.
// - Video: the 320 x 240 framebuffer shown 2x (640 x 480 filled), a smaller one at the top left (no
//   centring adders: about 50 logic cells, docs/gateware.md "fit-soc4"); RGB444 out.
// - Reset: until the PLL locks, and while the user button is held.
// - VIDEO = 0 (scripts/gateware.sh --no-video) leaves the video output out, for a headless board
//   read back over SPI (the profile's "scanout": "readback"): the DVI pins then stay low.
module icebreaker_top #(
  parameter VIDEO = 1
) (
  input  wire       clk_12m,
  input  wire       btn_n,
  input  wire       spi_sck,
  input  wire       spi_cs_n,
  input  wire       spi_mosi,
  output wire       spi_miso,
  output wire       flash_cs_n,
  output wire       dvi_clk,
  output wire       dvi_hs,
  output wire       dvi_vs,
  output wire       dvi_de,
  output wire [3:0] dvi_r,
  output wire [3:0] dvi_g,
  output wire [3:0] dvi_b
);
  // 12 MHz x (DIVF + 1) / 2^DIVQ / (DIVR + 1) = 12 x 67 / 32 = 25.125 MHz (icepll -i 12 -o 25.125)
  wire clk, locked;
  SB_PLL40_PAD #(
    .FEEDBACK_PATH("SIMPLE"), .DIVR(4'b0000), .DIVF(7'b1000010), .DIVQ(3'b101), .FILTER_RANGE(3'b001)
  ) u_pll (
    .PACKAGEPIN(clk_12m), .PLLOUTGLOBAL(clk), .LOCK(locked), .RESETB(1'b1), .BYPASS(1'b0)
  );

  // synchronous reset: 16 clocks after lock and button release
  reg [1:0] btn_sync = 2'b00;
  reg [4:0] rst_count = 5'd0;
  always @(posedge clk) begin
    btn_sync <= {btn_sync[0], btn_n};
    if (!locked || !btn_sync[1]) rst_count <= 5'd0;
    else if (!rst_count[4]) rst_count <= rst_count + 5'd1;
  end
  wire rst = !rst_count[4];

  wire miso, miso_oe, pix_en, hs, vs, de;
  wire [3:0] r, g, b;
  /* verilator lint_off PINCONNECTEMPTY */
  spigpu_top #(.PROFILE(0), .CLK_MHZ(25), .LINE_CLOCKS(800), .V_ACTIVE(480), .V_TOTAL(525), .PERF(0),
               .VIDEO(VIDEO), .VIDEO_PIX_DIV(1), .VIDEO_SCALE_LOG2(1), .VIDEO_LINE_AW(8), .VIDEO_BITS(4),
               .VIDEO_CENTRE(0)) u_gpu (
    .clk(clk), .rst(rst), .pclk(1'b0), .spi_sck(spi_sck), .spi_cs_n(spi_cs_n), .spi_mosi(spi_mosi), .spi_miso(miso),
    .spi_miso_oe(miso_oe), .busy_pin(), .sd_cke(), .sd_cs_n(), .sd_ras_n(), .sd_cas_n(), .sd_we_n(), .sd_ba(),
    .sd_a(), .sd_dqm(), .sd_dq_o(), .sd_dq_oe(), .sd_dq_i(16'd0), .vblank(), .vsync(), .frame_valid(),
    .frame_word(), .frame_nbytes(), .frame_start(), .frame_end(), .frame_format(), .frame_width(),
    .frame_height(), .perf_cycles(), .perf_work_cycles(), .perf_cmds(), .perf_frames(), .perf_core_stalls(),
    .perf_refreshes(), .perf_triangles(), .perf_pixels(), .perf_passed(), .perf_textured(), .perf_core_busy(),
    .perf_setup(), .perf_raster(), .video_pix_en(pix_en), .video_hsync(hs), .video_vsync(vs), .video_de(de),
    .video_r(r), .video_g(g), .video_b(b));
  /* verilator lint_on PINCONNECTEMPTY */

  // MISO: driven only while the gpu drives it (the line is the flash's output too)
  SB_IO #(.PIN_TYPE(6'b1010_01)) u_miso (.PACKAGE_PIN(spi_miso), .OUTPUT_CLK(1'b0), .OUTPUT_ENABLE(miso_oe),
                                         .D_OUT_0(miso), .D_OUT_1(1'b0));
  assign flash_cs_n = 1'b1;

  // DVI Pmod (TFP410 class, latching on the rising edge of dvi_clk): data registered in the I/O cells,
  // the clock sent inverted (a DDR cell, 0 then 1) so data settle half a period before its rising edge
  SB_IO #(.PIN_TYPE(6'b0100_01)) u_dvi_clk (.PACKAGE_PIN(dvi_clk), .OUTPUT_CLK(clk), .OUTPUT_ENABLE(1'b1),
                                           .D_OUT_0(1'b0), .D_OUT_1(1'b1));
  SB_IO #(.PIN_TYPE(6'b0101_01)) u_dvi_hs (.PACKAGE_PIN(dvi_hs), .OUTPUT_CLK(clk), .OUTPUT_ENABLE(1'b1), .D_OUT_0(hs), .D_OUT_1(1'b0));
  SB_IO #(.PIN_TYPE(6'b0101_01)) u_dvi_vs (.PACKAGE_PIN(dvi_vs), .OUTPUT_CLK(clk), .OUTPUT_ENABLE(1'b1), .D_OUT_0(vs), .D_OUT_1(1'b0));
  SB_IO #(.PIN_TYPE(6'b0101_01)) u_dvi_de (.PACKAGE_PIN(dvi_de), .OUTPUT_CLK(clk), .OUTPUT_ENABLE(1'b1), .D_OUT_0(de), .D_OUT_1(1'b0));
  genvar i;
  generate
    for (i = 0; i < 4; i = i + 1) begin : g_dvi
      SB_IO #(.PIN_TYPE(6'b0101_01)) u_r (.PACKAGE_PIN(dvi_r[i]), .OUTPUT_CLK(clk), .OUTPUT_ENABLE(1'b1), .D_OUT_0(r[i]), .D_OUT_1(1'b0));
      SB_IO #(.PIN_TYPE(6'b0101_01)) u_g (.PACKAGE_PIN(dvi_g[i]), .OUTPUT_CLK(clk), .OUTPUT_ENABLE(1'b1), .D_OUT_0(g[i]), .D_OUT_1(1'b0));
      SB_IO #(.PIN_TYPE(6'b0101_01)) u_b (.PACKAGE_PIN(dvi_b[i]), .OUTPUT_CLK(clk), .OUTPUT_ENABLE(1'b1), .D_OUT_0(b[i]), .D_OUT_1(1'b0));
    end
  endgenerate
  wire unused_ok = &{1'b0, pix_en};
endmodule
