// Port-only stand-ins for the vendor primitives the board top levels instantiate, so that Verilator
// can lint the top levels (ctest rtl.lint.boards); yosys uses its own cell libraries instead.
/* verilator lint_off DECLFILENAME */
/* verilator lint_off UNUSEDSIGNAL */
/* verilator lint_off UNUSEDPARAM */
module SB_PLL40_PAD #(parameter FEEDBACK_PATH = "SIMPLE", parameter [3:0] DIVR = 0, parameter [6:0] DIVF = 0,
                      parameter [2:0] DIVQ = 0, parameter [2:0] FILTER_RANGE = 0) (
  input wire PACKAGEPIN, output wire PLLOUTGLOBAL, output wire LOCK, input wire RESETB, input wire BYPASS);
  assign PLLOUTGLOBAL = PACKAGEPIN;
  assign LOCK = RESETB && !BYPASS;
endmodule

module SB_IO #(parameter [5:0] PIN_TYPE = 0) (
  output wire PACKAGE_PIN, input wire OUTPUT_CLK, input wire OUTPUT_ENABLE, input wire D_OUT_0, input wire D_OUT_1);
  assign PACKAGE_PIN = D_OUT_0;
endmodule

module EHXPLLL #(parameter PLLRST_ENA = "", INTFB_WAKE = "", STDBY_ENABLE = "", DPHASE_SOURCE = "",
                 OUTDIVIDER_MUXA = "", OUTDIVIDER_MUXB = "", OUTDIVIDER_MUXC = "", OUTDIVIDER_MUXD = "",
                 integer CLKI_DIV = 1, CLKFB_DIV = 1, CLKOP_DIV = 1, CLKOP_CPHASE = 0, CLKOP_FPHASE = 0,
                 CLKOS_DIV = 1, CLKOS_CPHASE = 0, CLKOS_FPHASE = 0, CLKOS2_DIV = 1, CLKOS2_CPHASE = 0, CLKOS2_FPHASE = 0,
                 CLKOP_ENABLE = "", CLKOS_ENABLE = "", CLKOS2_ENABLE = "", FEEDBK_PATH = "") (
  input wire RST, STDBY, CLKI, CLKFB, PHASESEL0, PHASESEL1, PHASEDIR, PHASESTEP, PHASELOADREG, PLLWAKESYNC,
  input wire ENCLKOP, ENCLKOS, ENCLKOS2, ENCLKOS3,
  output wire CLKOP, CLKOS, CLKOS2, CLKOS3, CLKINTFB, LOCK, INTLOCK, REFCLK);
  assign {CLKOP, CLKOS, CLKOS2, CLKOS3, CLKINTFB, REFCLK} = {6{CLKI}};
  assign {LOCK, INTLOCK} = {2{!RST}};
endmodule

module ODDRX1F (input wire SCLK, input wire RST, input wire D0, input wire D1, output wire Q);
  assign Q = D0;
endmodule
/* verilator lint_on UNUSEDPARAM */
/* verilator lint_on UNUSEDSIGNAL */
/* verilator lint_on DECLFILENAME */
