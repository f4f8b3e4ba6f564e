// ULX3S (Radiona, ECP5 LFE5U-85F-6BG381C) top level: the ecp5 profile of spigpu with its 32 MiB SDR
// SDRAM and DVI out on the GPDI connector. Pins: ulx3s.lpf beside this file; choices: docs/gateware.md
// "Boards".
//
// - Clocks from one PLL on the 25 MHz oscillator, VCO 625 MHz: 125 MHz (/5) for the TMDS serialisers
//   (10 bits a pixel, two a clock through DDR output cells), the 25 MHz pixel clock (/25: 640 x 480 at
//   59.5 Hz, the 25.0 MHz VESA / CEA sinks take; 25.175 / 25.2 MHz would need a PFD below the EHXPLLL's
//   3.125 MHz from a 25 MHz input) and the core at 52.08 MHz (/12), independent of the pixels: video_out
//   runs its display side in the pixel clock and its fill in the core clock (PCLK = 1, docs/gateware.md
//   "Clocking"). The VCO must be a multiple of 125 MHz in 400-800 MHz (500, 625 or 750): of their
//   integer divisions, 52.08 MHz is the fastest that stays below the netlist's clock estimate (53.4
//   MHz) and reaches the RGB565 fill goal (>= 51.6 MHz); 750 / 14 = 53.57 and 500 / 9 = 55.6 exceed it.
// - TMDS symbols are encoded in the pixel domain (two stages: a symbol leaves one clock after its
//   pixel) and change every 40 ns; the 125 MHz domain (the same VCO's, five clocks a pixel) loads them
//   2-3 of its clocks after a pixel toggle it synchronises, so always mid-symbol.
// - SPI from an FT232H wired to the J1 GPIO header (docs/boards.md "ULX3S"), BUSY wired.
// - The SDRAM clock is the core clock inverted (a DDR output cell, 0 then 1): commands and data change
//   on the rising edge and are sampled by the chip half a period later.
// - Reset: until the PLL locks, and while the power button (BTN_PWRn) is held; at least 16 core clocks
//   (video_out's pixel tick needs 12 to drain, its pixel-domain reset follows it into the pixel clock).
module ulx3s_top (
  input  wire        clk_25mhz,
  input  wire        btn_pwr_n,
  input  wire        spi_sck,
  input  wire        spi_cs_n,
  input  wire        spi_mosi,
  output wire        spi_miso,
  output wire        spi_busy,
  output wire        sdram_clk,
  output wire        sdram_cke,
  output wire        sdram_csn,
  output wire        sdram_rasn,
  output wire        sdram_casn,
  output wire        sdram_wen,
  output wire [1:0]  sdram_ba,
  output wire [12:0] sdram_a,
  output wire [1:0]  sdram_dqm,
  inout  wire [15:0] sdram_d,
  output wire [3:0]  gpdi_dp
);
  // 25 MHz x 5 (feedback from CLKOP: PFD 25 MHz) = 125 MHz; VCO = 125 x 5 = 625 MHz; CLKOS 625 / 25 =
  // 25 MHz pixels; CLKOS2 625 / 12 = 52.083 MHz core (dividers 1-128, PFD 3.125-400 MHz)
  wire clk_tmds, pclk, clk, locked;
  (* FREQUENCY_PIN_CLKI = "25", FREQUENCY_PIN_CLKOP = "125", FREQUENCY_PIN_CLKOS = "25",
     FREQUENCY_PIN_CLKOS2 = "52.083333", ICP_CURRENT = "12", LPF_RESISTOR = "8", MFG_ENABLE_FILTEROPAMP = "1",
     MFG_GMCREF_SEL = "2" *)
  /* verilator lint_off PINCONNECTEMPTY */
  EHXPLLL #(
    .PLLRST_ENA("DISABLED"), .INTFB_WAKE("DISABLED"), .STDBY_ENABLE("DISABLED"), .DPHASE_SOURCE("DISABLED"),
    .OUTDIVIDER_MUXA("DIVA"), .OUTDIVIDER_MUXB("DIVB"), .OUTDIVIDER_MUXC("DIVC"), .OUTDIVIDER_MUXD("DIVD"),
    .CLKI_DIV(1), .CLKFB_DIV(5), .CLKOP_ENABLE("ENABLED"), .CLKOP_DIV(5), .CLKOP_CPHASE(4), .CLKOP_FPHASE(0),
    .CLKOS_ENABLE("ENABLED"), .CLKOS_DIV(25), .CLKOS_CPHASE(24), .CLKOS_FPHASE(0),
    .CLKOS2_ENABLE("ENABLED"), .CLKOS2_DIV(12), .CLKOS2_CPHASE(11), .CLKOS2_FPHASE(0), .FEEDBK_PATH("CLKOP")
  ) u_pll (
    .RST(1'b0), .STDBY(1'b0), .CLKI(clk_25mhz), .CLKOP(clk_tmds), .CLKOS(pclk), .CLKOS2(clk), .CLKOS3(),
    .CLKFB(clk_tmds), .CLKINTFB(), .PHASESEL0(1'b0), .PHASESEL1(1'b0), .PHASEDIR(1'b1), .PHASESTEP(1'b1),
    .PHASELOADREG(1'b1), .PLLWAKESYNC(1'b0), .ENCLKOP(1'b0), .ENCLKOS(1'b0), .ENCLKOS2(1'b0), .ENCLKOS3(1'b0),
    .LOCK(locked), .INTLOCK(), .REFCLK()
  );
  /* verilator lint_on PINCONNECTEMPTY */

  reg [1:0] btn_sync = 2'b00;
  reg [4:0] rst_count = 5'd0;
  always @(posedge clk) begin
    btn_sync <= {btn_sync[0], btn_pwr_n};
    if (!locked || !btn_sync[1]) rst_count <= 5'd0;
    else if (!rst_count[4]) rst_count <= rst_count + 5'd1;
  end
  wire rst = !rst_count[4];

  wire        miso, miso_oe, sd_dq_oe, pix_en, hs, vs, de;
  wire [15:0] sd_dq_o;
  wire [7:0]  r, g, b;
  /* verilator lint_off PINCONNECTEMPTY */
  // the scanout's line is 800 pixels (its timing advances by the pixel tick); the SDRAM's timings from
  // the core clock in kHz (52,084: rounded up, so every spacing in clocks is at least the chip's)
  spigpu_top #(.PROFILE(1), .CLK_MHZ(52), .CLK_KHZ(52084), .LINE_CLOCKS(800), .V_ACTIVE(480), .V_TOTAL(525),
               .PERF(0), .VIDEO(1), .VIDEO_PIX_DIV(1), .VIDEO_SCALE_LOG2(0), .VIDEO_LINE_AW(10), .VIDEO_BITS(8),
               .VIDEO_PCLK(1)) u_gpu (
    .clk(clk), .rst(rst), .pclk(pclk), .spi_sck(spi_sck), .spi_cs_n(spi_cs_n), .spi_mosi(spi_mosi), .spi_miso(miso),
    .spi_miso_oe(miso_oe), .busy_pin(spi_busy), .sd_cke(sdram_cke), .sd_cs_n(sdram_csn), .sd_ras_n(sdram_rasn),
    .sd_cas_n(sdram_casn), .sd_we_n(sdram_wen), .sd_ba(sdram_ba), .sd_a(sdram_a), .sd_dqm(sdram_dqm),
    .sd_dq_o(sd_dq_o), .sd_dq_oe(sd_dq_oe), .sd_dq_i(sdram_d), .vblank(), .vsync(), .frame_valid(),
    .frame_word(), .frame_nbytes(), .frame_start(), .frame_end(), .frame_format(), .frame_width(),
    .frame_height(), .perf_cycles(), .perf_work_cycles(), .perf_cmds(), .perf_frames(), .perf_core_stalls(),
    .perf_refreshes(), .perf_triangles(), .perf_pixels(), .perf_passed(), .perf_textured(), .perf_core_busy(),
    .perf_setup(), .perf_raster(), .video_pix_en(pix_en), .video_hsync(hs), .video_vsync(vs), .video_de(de),
    .video_r(r), .video_g(g), .video_b(b));
  /* verilator lint_on PINCONNECTEMPTY */
  assign spi_miso = miso_oe ? miso : 1'bz;
  assign sdram_d = sd_dq_oe ? sd_dq_o : 16'bz;
  ODDRX1F u_sdram_clk (.SCLK(clk), .RST(1'b0), .D0(1'b0), .D1(1'b1), .Q(sdram_clk));

  // TMDS, in the pixel clock (pix_en is 1): blue carries the syncs (C0 = HSYNC, C1 = VSYNC), green and
  // red carry 0
  wire [9:0] sym_b, sym_g, sym_r;
  tmds_encoder u_enc_b (.clk(pclk), .en(pix_en), .de(de), .d(b), .c({vs, hs}), .q(sym_b));
  tmds_encoder u_enc_g (.clk(pclk), .en(pix_en), .de(de), .d(g), .c(2'b00), .q(sym_g));
  tmds_encoder u_enc_r (.clk(pclk), .en(pix_en), .de(de), .d(r), .c(2'b00), .q(sym_r));
  // the encoders' symbols change at every pixel clock: the toggle with them
  reg pix_toggle = 1'b0;
  always @(posedge pclk) pix_toggle <= !pix_toggle;

  // 125 MHz: a new symbol 2-3 clocks after each pixel toggle, then two bits a clock, LSB first
  reg [2:0] toggle_sync = 3'd0;
  reg [9:0] sr_b, sr_g, sr_r, sr_c;
  always @(posedge clk_tmds) begin
    toggle_sync <= {toggle_sync[1:0], pix_toggle};
    if (toggle_sync[2] != toggle_sync[1]) begin
      sr_b <= sym_b;
      sr_g <= sym_g;
      sr_r <= sym_r;
      sr_c <= 10'b0000011111;
    end else begin
      sr_b <= {2'b00, sr_b[9:2]};
      sr_g <= {2'b00, sr_g[9:2]};
      sr_r <= {2'b00, sr_r[9:2]};
      sr_c <= {2'b00, sr_c[9:2]};
    end
  end
  ODDRX1F u_ddr_b (.SCLK(clk_tmds), .RST(1'b0), .D0(sr_b[0]), .D1(sr_b[1]), .Q(gpdi_dp[0]));
  ODDRX1F u_ddr_g (.SCLK(clk_tmds), .RST(1'b0), .D0(sr_g[0]), .D1(sr_g[1]), .Q(gpdi_dp[1]));
  ODDRX1F u_ddr_r (.SCLK(clk_tmds), .RST(1'b0), .D0(sr_r[0]), .D1(sr_r[1]), .Q(gpdi_dp[2]));
  ODDRX1F u_ddr_c (.SCLK(clk_tmds), .RST(1'b0), .D0(sr_c[0]), .D1(sr_c[1]), .Q(gpdi_dp[3]));
endmodule
