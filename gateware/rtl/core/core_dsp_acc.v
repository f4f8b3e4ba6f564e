// A 32-bit accumulator in one iCE40 SB_MAC16 (the UP5K has 8, the design infers 3 multipliers),
// its multipliers unused: out = acc + b, or acc - b with sub, combinationally (the DSP's adder
// output, not its register); at a clock edge with `en` the accumulator takes `c` (load) or out.
// Its 32 flip-flops, 32 adder bits and the load multiplexer leave the fabric: what remains there
// is whatever computes b and c. The primitive is Verilated through gateware/sim/SB_MAC16.v.
//
// Configuration: both adders take the accumulator (ADDSUB_UPPERINPUT 0, the output registers Q / S)
// and A / B (ADDSUB_LOWERINPUT 0); the upper adder takes the lower one's carry (CARRYSELECT 2), so
// the two 16-bit halves are one 32-bit adder, and ADDSUB on both makes it acc - {A, B}; OLOAD
// loads {C, D}; OHOLD keeps the register; OUTPUT_SELECT 0 is the adder (or, while loading, {C, D})
// unregistered. No input or pipeline register.
module core_dsp_acc (
    input  wire        clk,
    input  wire        en,
    input  wire        load,
    input  wire        sub,
    input  wire [31:0] b,
    input  wire [31:0] c,
    output wire [31:0] out
);
  /* verilator lint_off PINCONNECTEMPTY */
  SB_MAC16 #(
      .NEG_TRIGGER(1'b0), .C_REG(1'b0), .A_REG(1'b0), .B_REG(1'b0), .D_REG(1'b0),
      .TOP_8x8_MULT_REG(1'b0), .BOT_8x8_MULT_REG(1'b0),
      .PIPELINE_16x16_MULT_REG1(1'b0), .PIPELINE_16x16_MULT_REG2(1'b0),
      .TOPOUTPUT_SELECT(2'd0), .TOPADDSUB_LOWERINPUT(2'd0), .TOPADDSUB_UPPERINPUT(1'b0),
      .TOPADDSUB_CARRYSELECT(2'd2),
      .BOTOUTPUT_SELECT(2'd0), .BOTADDSUB_LOWERINPUT(2'd0), .BOTADDSUB_UPPERINPUT(1'b0),
      .BOTADDSUB_CARRYSELECT(2'd0),
      .MODE_8x8(1'b0), .A_SIGNED(1'b0), .B_SIGNED(1'b0)
  ) mac (
      .CLK(clk), .CE(1'b1),
      .C(c[31:16]), .A(b[31:16]), .B(b[15:0]), .D(c[15:0]),
      .AHOLD(1'b0), .BHOLD(1'b0), .CHOLD(1'b0), .DHOLD(1'b0),
      .IRSTTOP(1'b0), .IRSTBOT(1'b0), .ORSTTOP(1'b0), .ORSTBOT(1'b0),
      .OLOADTOP(load), .OLOADBOT(load), .ADDSUBTOP(sub), .ADDSUBBOT(sub),
      .OHOLDTOP(!en), .OHOLDBOT(!en),
      .CI(1'b0), .ACCUMCI(1'b0), .SIGNEXTIN(1'b0),
      .O(out), .CO(), .ACCUMCO(), .SIGNEXTOUT());
  /* verilator lint_on PINCONNECTEMPTY */
endmodule
