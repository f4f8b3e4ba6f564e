// A counter's next value on the iCE40 in one logic cell a bit: q_next = ld ? d : q + 1 (DOWN = 0) or
// q - 1 (DOWN = 1); the register is the caller's (its D input is q_next and nothing else, so each LUT
// packs with its flip-flop and its carry). docs/gateware.md "up5k-cells".
//
// Written as an adder and a multiplexer, yosys maps the adder to SB_CARRY cells with their own SB_LUT4
// (the sum) and the multiplexer to a second LUT4 a bit: ABC cannot merge logic into a carry cell's
// LUT. Here each bit is one SB_LUT4 beside its SB_CARRY, the carry's second operand being `ld` (up) or
// `!ld` (down): while counting that is the constant the step needs (0 with carry in 1 for + 1, all ones
// with carry in 0 for - 1), and while loading the carries are garbage that q_next does not read. The
// LUT (I0 = d, I1 = q, I2 = that operand, I3 = the carry in) gives d when loading, else the sum bit.
// co[i], the carry out of bit i, is valid while counting: &q[i:0] (up) or |q[i:0] (down).
module ice40_load_step #(
  parameter W    = 8,
  parameter DOWN = 0
) (
  input  wire         ld,
  input  wire [W-1:0] d,
  input  wire [W-1:0] q,
  output wire [W-1:0] q_next,
  output wire [W-1:0] co
);
  wire       op = DOWN != 0 ? !ld : ld;
  wire [W:0] c;
  assign c[0] = DOWN == 0;
  // the LUT's index is {I3, I2, I1, I0}: up I2 ? I0 : I1 ^ I3 (A3AC), down I2 ? !(I1 ^ I3) : I0 (CA3A)
  genvar i;
  generate
    for (i = 0; i < W; i = i + 1) begin : g_bit
      SB_LUT4 #(.LUT_INIT(DOWN != 0 ? 16'hCA3A : 16'hA3AC)) u_lut (
        .O(q_next[i]), .I0(d[i]), .I1(q[i]), .I2(op), .I3(c[i]));
      SB_CARRY u_carry (.CO(c[i + 1]), .I0(q[i]), .I1(op), .CI(c[i]));
    end
  endgenerate
  assign co = c[W:1];
endmodule
