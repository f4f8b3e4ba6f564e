// dsp_counter in an SB_MAC16 (both halves, and wide) against the same counters in logic: random
// counts and loads for 100,000 clocks; prints "dsp_counter mismatches=N final=..." (check_dsp_counter.py).
module dsp_counter_tb;
  reg clk = 1'b0;
  reg ld_t, inc_t, ld_b, inc_b;
  reg [15:0] d_t, d_b;
  wire [15:0] t1, b1, t0, b0, wt1, wb1, wt0, wb0;
  dsp_counter #(.DSP(1), .WIDE(0)) u_dsp (clk, ld_t, d_t, inc_t, ld_b, d_b, inc_b, t1, b1);
  dsp_counter #(.DSP(0), .WIDE(0)) u_logic (clk, ld_t, d_t, inc_t, ld_b, d_b, inc_b, t0, b0);
  dsp_counter #(.DSP(1), .WIDE(1)) u_dsp_wide (clk, ld_t, d_t, inc_t, ld_b, d_b, inc_b, wt1, wb1);
  dsp_counter #(.DSP(0), .WIDE(1)) u_logic_wide (clk, ld_t, d_t, inc_t, ld_b, d_b, inc_b, wt0, wb0);
  integer i, errs;
  initial begin
    errs = 0;
    {ld_t, ld_b, inc_t, inc_b, d_t, d_b} = {4'b1100, 32'd0};
    #1 clk = 1'b1; #1 clk = 1'b0;
    for (i = 0; i < 100000; i = i + 1) begin
      // loads of random values, a third of them 0 and, for the bottom half, a third just below
      // 2^16, so that it wraps and a wide counter carries into its top half between loads
      ld_t = ($random % 5000) == 0;
      ld_b = ($random % 2000) == 0;
      d_t = ($random % 3) == 0 ? 16'd0 : $random;
      d_b = ($random % 3) == 0 ? 16'd0 : ($random % 2) == 0 ? 16'hFFFF - 16'($random % 512) : $random;
      inc_t = $random;
      inc_b = ($random % 8) != 0;
      #1 clk = 1'b1; #1 clk = 1'b0;
      if ({t1, b1, wt1, wb1} !== {t0, b0, wt0, wb0}) begin
        errs = errs + 1;
        if (errs < 5) $display("clock %0d: dsp %h %h wide %h%h, logic %h %h wide %h%h", i, t1, b1, wt1, wb1, t0, b0, wt0, wb0);
      end
    end
    $display("dsp_counter mismatches=%0d final=%h%h%h%h", errs, t0, b0, wt0, wb0);
    $finish;
  end
endmodule
