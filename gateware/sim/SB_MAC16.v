// Behavioural model of the iCE40 UltraPlus SB_MAC16 for Verilator, only the modes the gateware uses
// (core_dsp_acc's edge accumulators, dsp_counter's counters): no input or pipeline registers, the
// adders' inputs A / B direct (LOWERINPUT 0) and their output registers fed back (UPPERINPUT 0) or
// C / D (UPPERINPUT 1), outputs from the adders (OUTPUT_SELECT 0) or their registers (1), the bottom
// adder's carry in 0 or 1, the top's 0, 1, the bottom's raw carry (2: with one ADDSUB on both halves
// the pair is a 32-bit acc + {A, B} or acc - {A, B}) or that carry un-inverted (3), add or subtract,
// OLOAD (load C / D), OHOLD; the multiplier is not modelled and any other setting stops the
// simulation at time 0 instead of being modelled wrongly. The outputs' resets (ORST*) are
// asynchronous, as in the primitive. rtl.yosys.mac16 (core_dsp_acc's configuration, a bounded proof)
// and rtl.dsp_counter (dsp_counter's, iverilog) check it against yosys's own SB_MAC16 model, the one
// synth_ice40 and nextpnr go by.
module SB_MAC16 #(
  parameter [0:0] NEG_TRIGGER = 0, C_REG = 0, A_REG = 0, B_REG = 0, D_REG = 0,
  parameter [0:0] TOP_8x8_MULT_REG = 0, BOT_8x8_MULT_REG = 0,
  parameter [0:0] PIPELINE_16x16_MULT_REG1 = 0, PIPELINE_16x16_MULT_REG2 = 0,
  parameter [1:0] TOPOUTPUT_SELECT = 0, TOPADDSUB_LOWERINPUT = 0,
  parameter [0:0] TOPADDSUB_UPPERINPUT = 0,
  parameter [1:0] TOPADDSUB_CARRYSELECT = 0, BOTOUTPUT_SELECT = 0, BOTADDSUB_LOWERINPUT = 0,
  parameter [0:0] BOTADDSUB_UPPERINPUT = 0,
  parameter [1:0] BOTADDSUB_CARRYSELECT = 0,
  parameter [0:0] MODE_8x8 = 0, A_SIGNED = 0, B_SIGNED = 0
) (
  input  wire        CLK, CE,
  input  wire [15:0] C, A, B, D,
  input  wire        AHOLD, BHOLD, CHOLD, DHOLD, IRSTTOP, IRSTBOT, ORSTTOP, ORSTBOT,
  input  wire        OLOADTOP, OLOADBOT, ADDSUBTOP, ADDSUBBOT, OHOLDTOP, OHOLDBOT,
  input  wire        CI, ACCUMCI, SIGNEXTIN,
  output wire [31:0] O,
  output wire        CO, ACCUMCO, SIGNEXTOUT
);
  initial begin
    if (NEG_TRIGGER || C_REG || A_REG || B_REG || D_REG || TOP_8x8_MULT_REG || BOT_8x8_MULT_REG
        || PIPELINE_16x16_MULT_REG1 || PIPELINE_16x16_MULT_REG2 || TOPOUTPUT_SELECT > 2'd1
        || BOTOUTPUT_SELECT > 2'd1 || TOPADDSUB_LOWERINPUT != 2'd0 || BOTADDSUB_LOWERINPUT != 2'd0
        || BOTADDSUB_CARRYSELECT > 2'd1)
      $fatal(1, "SB_MAC16 model: a mode gateware/sim/SB_MAC16.v does not model");
  end
  reg  [15:0] q_top, q_bot;
  // the adders: lower input + (upper input, inverted when subtracting) + carry, then inverted back
  wire [15:0] up_top = TOPADDSUB_UPPERINPUT ? C : q_top;
  wire [15:0] up_bot = BOTADDSUB_UPPERINPUT ? D : q_bot;
  wire [16:0] sum_bot = {1'b0, B} + {1'b0, up_bot ^ {16{ADDSUBBOT}}} + {16'd0, BOTADDSUB_CARRYSELECT == 2'd1};
  wire        cin_top = TOPADDSUB_CARRYSELECT == 2'd1 ? 1'b1 : TOPADDSUB_CARRYSELECT == 2'd2 ? sum_bot[16] :
                        TOPADDSUB_CARRYSELECT == 2'd3 ? sum_bot[16] ^ ADDSUBBOT : 1'b0;
  wire [16:0] sum_top = {1'b0, A} + {1'b0, up_top ^ {16{ADDSUBTOP}}} + {16'd0, cin_top};
  wire [15:0] next_top = OLOADTOP ? C : sum_top[15:0] ^ {16{ADDSUBTOP}};
  wire [15:0] next_bot = OLOADBOT ? D : sum_bot[15:0] ^ {16{ADDSUBBOT}};
  always @(posedge CLK or posedge ORSTTOP) begin
    if (ORSTTOP) q_top <= 16'd0;
    else if (CE && !OHOLDTOP) q_top <= next_top;
  end
  always @(posedge CLK or posedge ORSTBOT) begin
    if (ORSTBOT) q_bot <= 16'd0;
    else if (CE && !OHOLDBOT) q_bot <= next_bot;
  end
  assign O = {TOPOUTPUT_SELECT == 2'd1 ? q_top : next_top, BOTOUTPUT_SELECT == 2'd1 ? q_bot : next_bot};
  assign ACCUMCO = sum_top[16];
  assign CO = sum_top[16] ^ ADDSUBTOP;
  assign SIGNEXTOUT = A[15];
  wire unused = &{1'b0, AHOLD, BHOLD, CHOLD, DHOLD, IRSTTOP, IRSTBOT, CI, ACCUMCI, SIGNEXTIN, MODE_8x8 != 1'b0,
                 A_SIGNED != 1'b0, B_SIGNED != 1'b0};
endmodule
