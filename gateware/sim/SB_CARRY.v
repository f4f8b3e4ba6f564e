// Simulation model of the iCE40 carry cell, which the up5k profile instantiates by hand
// (rtl/soc/ice40_load_step.v), for Verilator and yosys's structural check; synthesis maps the
// instances to the device's own cell (synth_ice40's library), so this file is never synthesised.
// CO is the majority of I0, I1 and CI (iCE40 family handbook).
module SB_CARRY (
  output wire CO,
  input  wire I0,
  input  wire I1,
  input  wire CI
);
  assign CO = (I0 && I1) || (CI && (I0 || I1));
endmodule
