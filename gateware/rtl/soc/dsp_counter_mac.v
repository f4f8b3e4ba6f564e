// dsp_counter's SB_MAC16 (gateware/rtl/soc/dsp_counter.v), kept as its own module through synthesis:
// yosys 0.23's DSP packer (ice40_dsp) otherwise takes the instantiated accumulator for a multiplier
// to merge registers into and fails an assertion on it.
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
  SB_MAC16 #(
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
