// core_dsp_acc twice: with yosys's SB_MAC16 simulation model (gold) and with gateware/sim/SB_MAC16.v
// (gate; mac16_equiv.ys gives each its model); the outputs must agree at every step.
module mac16_eq (
    input  wire        clk,
    input  wire        en,
    input  wire        load,
    input  wire        sub,
    input  wire [31:0] b,
    input  wire [31:0] c,
    output wire [31:0] o_gold,
    output wire [31:0] o_gate
);
  core_dsp_acc gold (.clk(clk), .en(en), .load(load), .sub(sub), .b(b), .c(c), .out(o_gold));
  core_dsp_acc_model gate (.clk(clk), .en(en), .load(load), .sub(sub), .b(b), .c(c), .out(o_gate));
endmodule
