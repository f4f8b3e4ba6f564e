// Simulation model of the iCE40 look-up table, which the up5k profile instantiates by hand
// (rtl/soc/ice40_load_step.v), for Verilator and yosys's structural check; synthesis maps the
// instances to the device's own cell (synth_ice40's library), so this file is never synthesised.
// The output is LUT_INIT's bit indexed {I3, I2, I1, I0} (iCE40 family handbook).
module SB_LUT4 #(
  parameter [15:0] LUT_INIT = 16'h0000
) (
  output wire O,
  input  wire I0,
  input  wire I1,
  input  wire I2,
  input  wire I3
);
  assign O = LUT_INIT[{I3, I2, I1, I0}];
endmodule
