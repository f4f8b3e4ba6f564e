// Read queue of a pixel stage: an item is pushed when its memory read is issued, its response
// (in request order) is attached to the oldest item still waiting, and the head leaves once its
// data is there. Every issued read has a reserved slot, so responses are never refused.
// AW = 0 is a single slot (the iCE40 profile: one read in flight per stage).
module core_rdq #(
    parameter integer IW = 8,   // item bits
    parameter integer DW = 32,  // response bits
    parameter integer AW = 2    // log2 of the depth
) (
    input  wire          clk,
    input  wire          rst,
    input  wire          push,
    input  wire [IW-1:0] push_item,
    output wire          full,
    output wire          empty,
    input  wire          rsp_valid,
    input  wire [DW-1:0] rsp_data,
    output wire          head_valid,  // head item has its data
    output wire [IW-1:0] head_item,
    output wire [DW-1:0] head_data,
    input  wire          pop
);
  generate
    if (AW == 0) begin : one
      reg          used, got;
      reg [IW-1:0] item;
      reg [DW-1:0] data;
      assign full = used;
      assign empty = !used;
      assign head_valid = got;
      assign head_item = item;
      assign head_data = data;
      always @(posedge clk) begin
        if (rst) begin
          used <= 1'b0;
          got  <= 1'b0;
        end else begin
          if (push) begin
            item <= push_item;
            used <= 1'b1;
          end else if (pop) begin
            used <= 1'b0;
          end
          if (rsp_valid) begin
            data <= rsp_data;
            got  <= 1'b1;
          end else if (pop) begin
            got <= 1'b0;
          end
        end
      end
    end else begin : many
      localparam integer N = 1 << AW;
      reg [IW-1:0] items[0:N-1];
      reg [DW-1:0] datas[0:N-1];
      reg [AW:0] wp, dp, rp;
      assign full = (wp - rp) == N[AW:0];
      assign empty = (wp == rp);
      assign head_valid = (dp != rp);
      assign head_item = items[rp[AW-1:0]];
      assign head_data = datas[rp[AW-1:0]];
      always @(posedge clk) begin
        if (rst) begin
          wp <= 0;
          dp <= 0;
          rp <= 0;
        end else begin
          if (push) begin
            items[wp[AW-1:0]] <= push_item;
            wp <= wp + 1'b1;
          end
          if (rsp_valid) begin
            datas[dp[AW-1:0]] <= rsp_data;
            dp <= dp + 1'b1;
          end
          if (pop) rp <= rp + 1'b1;
        end
      end
    end
  endgenerate
endmodule
