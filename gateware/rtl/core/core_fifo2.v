// Two-entry FIFO between pipeline stages. `room` comes from registered state only, so a stage
// may offer a memory request conditioned on it without a combinational path from the next
// stage's ready; two entries keep one transfer per cycle.
module core_fifo2 #(
    parameter integer W = 8
) (
    input  wire         clk,
    input  wire         rst,
    input  wire         push,
    input  wire [W-1:0] din,
    output wire         room,     // fewer than two entries at the start of this cycle
    output wire         valid,
    output wire [W-1:0] dout,
    input  wire         pop
);
  reg [W-1:0] m0, m1;  // m0 = head
  reg [1:0]   n;
  assign room  = (n != 2'd2);
  assign valid = (n != 2'd0);
  assign dout  = m0;
  wire do_pop = pop && valid;
  always @(posedge clk) begin
    if (rst) begin
      n <= 2'd0;
    end else begin
      case ({push, do_pop})
        2'b10: begin
          if (n == 2'd0) m0 <= din; else m1 <= din;
          n <= n + 2'd1;
        end
        2'b01: begin
          m0 <= m1;
          n  <= n - 2'd1;
        end
        2'b11: begin
          if (n == 2'd1) m0 <= din;
          else begin m0 <= m1; m1 <= din; end
        end
        default: ;
      endcase
    end
  end
endmodule
