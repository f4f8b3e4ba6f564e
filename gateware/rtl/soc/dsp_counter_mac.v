// dsp_counter's SB_MAC16 (gateware/rtl/soc/dsp_counter.v), kept as its own module through synthesis:
// yosys 0.23's DSP packer (ice40_dsp) otherwise takes the instantiated accumulator for a multiplier
// to merge registers into and fails an assertion on it. Kept as its own module it still matches the
// pass, which rewrites it as an unclocked 16 x 16 multiply (A x B = 1 x 1): for yosys (SYNTHESIS) the
// cell is SB_MAC16_KEPT, a black box the pass does not know, renamed SB_MAC16 after synthesis
// (boards/build.py, synth.py: `chtype -map SB_MAC16_KEPT SB_MAC16`); simulators see SB_MAC16.
`ifdef SYNTHESIS
`define DSP_COUNTER_MAC_CELL SB_MAC16_KEPT
`else
`define DSP_COUNTER_MAC_CELL SB_MAC16
`endif
(* keep_hierarchy *)
module dsp_counter_mac #(
  parameter WIDE = 0
) (
  input  wire        clk,
  input  wire [15:0] d_top,
  input  wire [15:0] d_bot,
  input  wire        load_top,
  input  wire        load_bot,
  input  wire        hold_top,
  input  wire        hold_bot,
  output wire [31:0] o
);
  wire co, accum_co, signext;
  `DSP_COUNTER_MAC_CELL #(
    .TOPOUTPUT_SELECT(2'd1), .TOPADDSUB_UPPERINPUT(1'b0), .TOPADDSUB_LOWERINPUT(2'd0),
    .TOPADDSUB_CARRYSELECT(WIDE != 0 ? 2'd3 : 2'd0),
    .BOTOUTPUT_SELECT(2'd1), .BOTADDSUB_UPPERINPUT(1'b0), .BOTADDSUB_LOWERINPUT(2'd0),
    .BOTADDSUB_CARRYSELECT(2'd0), .MODE_8x8(1'b1)
  ) u_mac (
    .CLK(clk), .CE(1'b1), .C(d_top), .A(WIDE != 0 ? 16'd0 : 16'd1), .B(16'd1), .D(d_bot),
    .AHOLD(1'b1), .BHOLD(1'b1), .CHOLD(1'b1), .DHOLD(1'b1), .IRSTTOP(1'b0), .IRSTBOT(1'b0),
    .ORSTTOP(1'b0), .ORSTBOT(1'b0), .OLOADTOP(load_top), .OLOADBOT(load_bot), .ADDSUBTOP(1'b0),
    .ADDSUBBOT(1'b0), .OHOLDTOP(hold_top), .OHOLDBOT(hold_bot), .CI(1'b0), .ACCUMCI(1'b0),
    .SIGNEXTIN(1'b0), .O(o), .CO(co), .ACCUMCO(accum_co), .SIGNEXTOUT(signext));
  wire unused = &{1'b0, co, accum_co, signext};
endmodule

`ifdef SYNTHESIS
// yosys 0.23's ice40_dsp pass rewrites every SB_MAC16 it meets as a multiplier (an instantiated
// accumulator becomes an unclocked 16 x 16 multiply); under this name it is a black box the pass
// does not know, renamed SB_MAC16 after synthesis (`chtype -map SB_MAC16_KEPT SB_MAC16`: build.py,
// synth.py)
(* blackbox *)
module SB_MAC16_KEPT #(
  parameter [0:0] NEG_TRIGGER = 1'b0, parameter [0:0] C_REG = 1'b0, parameter [0:0] A_REG = 1'b0,
  parameter [0:0] B_REG = 1'b0, parameter [0:0] D_REG = 1'b0, parameter [0:0] TOP_8x8_MULT_REG = 1'b0,
  parameter [0:0] BOT_8x8_MULT_REG = 1'b0, parameter [0:0] PIPELINE_16x16_MULT_REG1 = 1'b0,
  parameter [0:0] PIPELINE_16x16_MULT_REG2 = 1'b0, parameter [1:0] TOPOUTPUT_SELECT = 2'b00,
  parameter [1:0] TOPADDSUB_LOWERINPUT = 2'b00, parameter [0:0] TOPADDSUB_UPPERINPUT = 1'b0,
  parameter [1:0] TOPADDSUB_CARRYSELECT = 2'b00, parameter [1:0] BOTOUTPUT_SELECT = 2'b00,
  parameter [1:0] BOTADDSUB_LOWERINPUT = 2'b00, parameter [0:0] BOTADDSUB_UPPERINPUT = 1'b0,
  parameter [1:0] BOTADDSUB_CARRYSELECT = 2'b00, parameter [0:0] MODE_8x8 = 1'b0,
  parameter [0:0] A_SIGNED = 1'b0, parameter [0:0] B_SIGNED = 1'b0
) (
  input wire CLK, input wire CE, input wire [15:0] C, input wire [15:0] A, input wire [15:0] B,
  input wire [15:0] D, input wire AHOLD, input wire BHOLD, input wire CHOLD, input wire DHOLD,
  input wire IRSTTOP, input wire IRSTBOT, input wire ORSTTOP, input wire ORSTBOT, input wire OLOADTOP,
  input wire OLOADBOT, input wire ADDSUBTOP, input wire ADDSUBBOT, input wire OHOLDTOP, input wire OHOLDBOT,
  input wire CI, input wire ACCUMCI, input wire SIGNEXTIN, output wire [31:0] O, output wire CO,
  output wire ACCUMCO, output wire SIGNEXTOUT
);
endmodule
`endif
