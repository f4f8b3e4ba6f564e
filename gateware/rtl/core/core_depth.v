// Depth stage (docs/protocol.md section 11 steps 1-2): reads the stored depth of each pixel
// (Z_TEST), compares, writes the new depth of passing pixels (Z_WRITE) and drops failing ones.
// Reads are issued as pixels arrive and resolved in order from a read queue (2^AW in flight).
// Depth word of pixel i: FB_Z + 4i, bits [23:0]; bits [31:24] are written 0.
// Without Z_TEST and Z_WRITE pixels pass straight through. Memory requests depend on registered
// state only (never on a ready), as the core's memory port requires.
module core_depth #(
    parameter integer PW = 178,    // pixel record bits: {..., z[23:0] at ZLSB, idx at 0}
    parameter integer ZLSB = 20,
    parameter integer IDX_W = 20,
    parameter integer AW = 2,
    parameter integer ADDR_W = 32
) (
    input  wire          clk,
    input  wire          rst,
    input  wire          z_test,
    input  wire [2:0]    z_func,
    input  wire          z_write,
    input  wire [27:0]   fb_z16,   // FB_Z byte address / 16
    // pixels in (from a register)
    input  wire          in_valid,
    output wire          in_ready,
    input  wire [PW-1:0] in_pix,
    // pixels out (passed)
    output wire          out_valid,
    input  wire          out_ready,
    output wire [PW-1:0] out_pix,
    // memory: depth reads
    output wire          rd_valid,
    input  wire          rd_ready,
    output wire [29:0]   rd_addr,
    input  wire          rsp_valid,
    input  wire [23:0]   rsp_data,
    // memory: depth writes
    output wire          wr_valid,
    input  wire          wr_ready,
    output wire [29:0]   wr_addr,
    output wire [23:0]   wr_data,
    output wire          idle,
    output wire          passed    // a pixel passed this cycle (counter)
);
`include "core_addr.vh"
  function [29:0] zaddr(input [27:0] base, input [IDX_W-1:0] idx);  // word address of pixel idx
    zaddr = 30'(byte_addr(base, {{(22-IDX_W){1'b0}}, idx, 2'b00}) >> 2);
  endfunction

  // every function from one comparator (a subtractor's borrow) and one equality
  function passes(input [2:0] f, input [23:0] z, input [23:0] d);
    reg lt, eq;
    begin
      lt = z < d;
      eq = z == d;
      case (f)
        3'd0: passes = 1'b0;      // NEVER
        3'd1: passes = lt;        // LESS
        3'd2: passes = eq;        // EQUAL
        3'd3: passes = lt || eq;  // LEQUAL
        3'd4: passes = !lt && !eq;  // GREATER
        3'd5: passes = !eq;       // NOTEQUAL
        3'd6: passes = !lt;       // GEQUAL
        default: passes = 1'b1;   // ALWAYS
      endcase
    end
  endfunction

  wire active = z_test || z_write;

  // ---- read queue (Z_TEST) ----
  wire          q_full, q_empty, q_head;
  wire [PW-1:0] q_item;
  wire [23:0]   q_data;
  wire          take;
  core_rdq #(.IW(PW), .DW(24), .AW(AW)) queue (
      .clk(clk), .rst(rst),
      .push(rd_valid && rd_ready), .push_item(in_pix),
      .full(q_full), .empty(q_empty),
      .rsp_valid(rsp_valid), .rsp_data(rsp_data),
      .head_valid(q_head), .head_item(q_item), .head_data(q_data), .pop(z_test && take));

  assign rd_valid = z_test && in_valid && !q_full;

  // the pixel being resolved: the queue head (Z_TEST) or the input
  wire [PW-1:0] cur = z_test ? q_item : in_pix;
  wire          cur_valid = z_test ? q_head : in_valid;
  wire [23:0]   cur_z = cur[ZLSB+23:ZLSB];
  wire          pass = !z_test || passes(z_func, cur_z, q_data);

  // output register (depth active); room from registered state only
  reg           o_valid;
  reg [PW-1:0]  o_pix;
  wire          room = !o_valid;
  // a pixel is resolved when it fails, or passes with room behind and its depth write accepted
  wire          z_free;    // the depth write can be taken this cycle
  wire          z_idle;    // no depth write waiting
  assign take     = cur_valid && (!pass || (room && (!z_write || z_free)));
  generate
    if (AW == 0) begin : one_adder
      // one read in flight: a read is issued only while the queue is empty and a Z_TEST write
      // only for its head, so one address adder serves both (its input chosen by the queue's
      // registered state)
      wire [29:0] a = zaddr(fb_z16, (z_test && !q_empty) ? q_item[IDX_W-1:0] : in_pix[IDX_W-1:0]);
      assign rd_addr = a;
      assign wr_addr = a;
      assign wr_data = cur_z;
      assign wr_valid = active && cur_valid && pass && z_write && room;
      assign z_free = wr_ready;
      assign z_idle = 1'b1;
    end else begin : two_adders
      assign rd_addr = zaddr(fb_z16, in_pix[IDX_W-1:0]);
      // The depth write goes three registers behind the pixel's resolution (stages that close
      // up when the one ahead is empty), so that it reaches the memory port next to the pixel's
      // colour write, which the colour stage's PIPE steps delay: on the SDRAM the two writes
      // share one read-to-write turnaround, as before those steps (Z test + write 0.129 px/clock
      // with the write at resolution, 0.143 before the colour steps).
      reg [2:0]  zv;
      reg [53:0] zq0, zq1, zq2;    // {word address, depth}
      wire z2_free = !zv[2] || wr_ready;
      wire z1_free = !zv[1] || z2_free;
      assign z_free = !zv[0] || z1_free;
      wire z_push = active && cur_valid && pass && z_write && room && z_free;
      always @(posedge clk) begin
        if (rst) begin
          zv <= 3'd0;
        end else begin
          if (z2_free) zv[2] <= zv[1];
          if (z1_free) zv[1] <= zv[0];
          if (z_free)  zv[0] <= z_push;
        end
        if (z2_free) zq2 <= zq1;
        if (z1_free) zq1 <= zq0;
        if (z_free)  zq0 <= {zaddr(fb_z16, cur[IDX_W-1:0]), cur_z};
      end
      assign wr_valid = zv[2];
      assign wr_addr  = zq2[53:24];
      assign wr_data  = zq2[23:0];
      assign z_idle   = (zv == 3'd0);
    end
  endgenerate
  assign in_ready = !active ? out_ready : z_test ? (!q_full && rd_ready) : take;
  assign passed   = active ? (take && pass) : (in_valid && out_ready);

  always @(posedge clk) begin
    if (rst) begin
      o_valid <= 1'b0;
    end else if (active && take && pass) begin
      o_valid <= 1'b1;
      o_pix   <= cur;
    end else if (out_ready) begin
      o_valid <= 1'b0;
    end
  end
  assign out_valid = active ? o_valid : in_valid;
  assign out_pix   = active ? o_pix : in_pix;

  assign idle = q_empty && !o_valid && z_idle;
endmodule
