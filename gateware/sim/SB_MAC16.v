// Behavioural model of the iCE40 UltraPlus SB_MAC16 for Verilator, limited to the accumulator
// configuration the design uses (gateware/rtl/core/core_dsp_acc.v): no input, multiplier or
// pipeline registers, both adders fed by the accumulator (Q / S) and by A / B, the upper adder
// taking the lower one's carry, outputs straight from the adders. In that configuration each
// half computes X + (W ^ ADDSUB) + carry-in and the result is that sum ^ ADDSUB, so with one
// ADDSUB on both halves the pair is acc + {A, B} or acc - {A, B}; OLOAD puts {C, D} on the output
// and into the register instead, OHOLD keeps the register. Any other parameter value stops the
// simulation at time 0 instead of being modelled wrongly. rtl.yosys.mac16 proves this model equal
// to yosys's own SB_MAC16 simulation model (the one synth_ice40 and nextpnr go by) in this
// configuration.
module SB_MAC16 #(
    parameter [0:0] NEG_TRIGGER = 1'b0,
    parameter [0:0] C_REG = 1'b0,
    parameter [0:0] A_REG = 1'b0,
    parameter [0:0] B_REG = 1'b0,
    parameter [0:0] D_REG = 1'b0,
    parameter [0:0] TOP_8x8_MULT_REG = 1'b0,
    parameter [0:0] BOT_8x8_MULT_REG = 1'b0,
    parameter [0:0] PIPELINE_16x16_MULT_REG1 = 1'b0,
    parameter [0:0] PIPELINE_16x16_MULT_REG2 = 1'b0,
    parameter [1:0] TOPOUTPUT_SELECT = 2'd0,
    parameter [1:0] TOPADDSUB_LOWERINPUT = 2'd0,
    parameter [0:0] TOPADDSUB_UPPERINPUT = 1'b0,
    parameter [1:0] TOPADDSUB_CARRYSELECT = 2'd0,
    parameter [1:0] BOTOUTPUT_SELECT = 2'd0,
    parameter [1:0] BOTADDSUB_LOWERINPUT = 2'd0,
    parameter [0:0] BOTADDSUB_UPPERINPUT = 1'b0,
    parameter [1:0] BOTADDSUB_CARRYSELECT = 2'd0,
    parameter [0:0] MODE_8x8 = 1'b0,
    parameter [0:0] A_SIGNED = 1'b0,
    parameter [0:0] B_SIGNED = 1'b0
) (
    input  wire        CLK,
    input  wire        CE,
    input  wire [15:0] C,
    input  wire [15:0] A,
    input  wire [15:0] B,
    input  wire [15:0] D,
    input  wire        AHOLD,
    input  wire        BHOLD,
    input  wire        CHOLD,
    input  wire        DHOLD,
    input  wire        IRSTTOP,
    input  wire        IRSTBOT,
    input  wire        ORSTTOP,
    input  wire        ORSTBOT,
    input  wire        OLOADTOP,
    input  wire        OLOADBOT,
    input  wire        ADDSUBTOP,
    input  wire        ADDSUBBOT,
    input  wire        OHOLDTOP,
    input  wire        OHOLDBOT,
    input  wire        CI,
    input  wire        ACCUMCI,
    input  wire        SIGNEXTIN,
    output wire [31:0] O,
    output wire        CO,
    output wire        ACCUMCO,
    output wire        SIGNEXTOUT
);
  localparam SUPPORTED = NEG_TRIGGER == 1'b0 && C_REG == 1'b0 && A_REG == 1'b0 && B_REG == 1'b0 &&
                         D_REG == 1'b0 && TOP_8x8_MULT_REG == 1'b0 && BOT_8x8_MULT_REG == 1'b0 &&
                         PIPELINE_16x16_MULT_REG1 == 1'b0 && PIPELINE_16x16_MULT_REG2 == 1'b0 &&
                         TOPOUTPUT_SELECT == 2'd0 && TOPADDSUB_LOWERINPUT == 2'd0 &&
                         TOPADDSUB_UPPERINPUT == 1'b0 && TOPADDSUB_CARRYSELECT == 2'd2 &&
                         BOTOUTPUT_SELECT == 2'd0 && BOTADDSUB_LOWERINPUT == 2'd0 &&
                         BOTADDSUB_UPPERINPUT == 1'b0 && BOTADDSUB_CARRYSELECT == 2'd0;
`ifndef SYNTHESIS
  initial begin
    if (!SUPPORTED) $fatal(1, "SB_MAC16 model: only the accumulator configuration of core_dsp_acc is modelled");
  end
`endif
  reg  [15:0] q, s;  // the accumulator's upper and lower halves
  wire [16:0] lo = {1'b0, B} + {1'b0, s ^ {16{ADDSUBBOT}}};
  wire [16:0] hi = {1'b0, A} + {1'b0, q ^ {16{ADDSUBTOP}}} + {16'd0, lo[16]};
  wire [15:0] o_hi = OLOADTOP ? C : hi[15:0] ^ {16{ADDSUBTOP}};
  wire [15:0] o_lo = OLOADBOT ? D : lo[15:0] ^ {16{ADDSUBBOT}};
  always @(posedge CLK) begin
    if (CE && !OHOLDTOP) q <= o_hi;
    if (CE && !OHOLDBOT) s <= o_lo;
  end
  assign O = {o_hi, o_lo};
  assign CO = hi[16] ^ ADDSUBTOP;
  assign ACCUMCO = hi[16];
  assign SIGNEXTOUT = A[15];
  wire unused_ok = &{1'b0, SUPPORTED, AHOLD, BHOLD, CHOLD, DHOLD, IRSTTOP, IRSTBOT, ORSTTOP, ORSTBOT, CI, ACCUMCI,
                     SIGNEXTIN, MODE_8x8, A_SIGNED, B_SIGNED};
endmodule
