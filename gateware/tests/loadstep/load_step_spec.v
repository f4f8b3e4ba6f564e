// ice40_load_step (rtl/soc/ice40_load_step.v) against what it stands for, for both directions:
// q_next = ld ? d : q + 1 (DOWN = 0) or q - 1 (DOWN = 1), and while counting the carry out of bit i
// = &q[i:0] (up) or |q[i:0] (down). load_step.ys proves `ok` for every input, once with the cell
// models synthesis and nextpnr go by (yosys's SB_LUT4 / SB_CARRY) and once with the co-simulation's
// (gateware/sim), so the hand-written LUT_INIT constants are checked against the real cells and the
// co-simulation's cells against yosys's.
module load_step_spec #(
  parameter W = 9
) (
  input  wire         ld,
  input  wire [W-1:0] d,
  input  wire [W-1:0] q,
  output wire         ok
);
  wire [W-1:0] up_next, up_co, down_next, down_co;
  ice40_load_step #(.W(W), .DOWN(0)) u_up (.ld(ld), .d(d), .q(q), .q_next(up_next), .co(up_co));
  ice40_load_step #(.W(W), .DOWN(1)) u_down (.ld(ld), .d(d), .q(q), .q_next(down_next), .co(down_co));
  reg [W-1:0] all_ones_below, any_one_below;  // &q[i:0], |q[i:0]
  integer i;
  always @* begin
    all_ones_below[0] = q[0];
    any_one_below[0] = q[0];
    for (i = 1; i < W; i = i + 1) begin
      all_ones_below[i] = all_ones_below[i - 1] & q[i];
      any_one_below[i] = any_one_below[i - 1] | q[i];
    end
  end
  assign ok = up_next == (ld ? d : q + 1'b1) && down_next == (ld ? d : q - 1'b1) &&
              (ld || (up_co == all_ones_below && down_co == any_one_below));
endmodule
