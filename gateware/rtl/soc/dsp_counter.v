// Two 16-bit counters, or one 32-bit counter, in the accumulators of one iCE40 SB_MAC16 (DSP = 1,
// the up5k profile, which has DSP blocks to spare and no logic cells) or in logic (DSP = 0).
// A counter in logic costs a logic cell per bit (LUT, carry and flip-flop); in the DSP it costs none:
// the accumulator adds its A (top) or B (bottom) input, the constant 1, to its own output register,
// OLOAD loads C / D (d_top / d_bot; 0 for a clear) and OHOLD holds it. Each half: a load wins over
// counting; the value is the register (a clock after the control). WIDE = 1: one 32-bit counter
// {q_top, q_bot} on the bottom half's controls (the bottom's carry into the top adder; a load puts
// {d_top, d_bot}; the top's own controls are unused).
// Simulation: gateware/sim/SB_MAC16.v, a model of the modes used here (Verilator has no primitives).
module dsp_counter #(
  parameter DSP  = 1,
  parameter WIDE = 0
) (
  input  wire        clk,
  input  wire        ld_top,
  input  wire [15:0] d_top,
  input  wire        inc_top,
  input  wire        ld_bot,
  input  wire [15:0] d_bot,
  input  wire        inc_bot,
  output wire [15:0] q_top,
  output wire [15:0] q_bot
);
  wire load_top = WIDE != 0 ? ld_bot : ld_top;
  wire step_top = WIDE != 0 ? inc_bot : inc_top;
  generate
    if (DSP != 0) begin : g_dsp
      wire [31:0] o;
      dsp_counter_mac #(.WIDE(WIDE)) u_mac (
        .clk(clk), .d_top(d_top), .d_bot(d_bot), .load_top(load_top), .load_bot(ld_bot),
        .hold_top(!(load_top || step_top)), .hold_bot(!(ld_bot || inc_bot)), .o(o));
      assign {q_top, q_bot} = o;
    end else begin : g_logic
      reg [15:0] top, bot;
      wire [16:0] bot_next = {1'b0, bot} + 17'd1;
      always @(posedge clk) begin
        if (ld_bot) bot <= d_bot;
        else if (inc_bot) bot <= bot_next[15:0];
        if (load_top) top <= d_top;
        else if (step_top) top <= top + (WIDE != 0 ? {15'd0, bot_next[16]} : 16'd1);
      end
      assign {q_top, q_bot} = {top, bot};
    end
  endgenerate
endmodule
