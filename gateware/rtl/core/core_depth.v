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
    parameter integer ADDR_W = 32,
    // 1 (ecp5): the output is the register also without Z_TEST and Z_WRITE (a clock of latency);
    // 0 (up5k, no depth buffer: the stage is a wire there): the input passes straight through
    parameter integer OUT_REG = 0
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
  wire          q_pass;   // the head's test result (with several reads in flight: decided on arrival)
  wire          take;
  wire          push = rd_valid && rd_ready;
  wire [PW-1:0] cur;
  generate
    if (AW == 0) begin : one_read
      wire [23:0] q_data;
      core_rdq #(.IW(PW), .DW(24), .AW(AW)) queue (
          .clk(clk), .rst(rst),
          .push(push), .push_item(in_pix),
          .full(q_full), .empty(q_empty),
          .rsp_valid(rsp_valid), .rsp_data(rsp_data),
          .head_valid(q_head), .head_item(q_item), .head_data(q_data), .pop(z_test && take));
      assign q_pass = passes(z_func, cur[ZLSB+23:ZLSB], q_data);
    end else begin : many_reads
      // The comparison is made when the response arrives (against the depth of the pixel it
      // answers, kept here in push order beside the queue's items) and the queue stores its
      // result, so the head's resolution reads one bit instead of comparing two 24-bit words it
      // has just read from the queue: that compare sat between the queue's head and the
      // memory port's request (the ULX3S clock, docs/gateware.md "Pipelining the ecp5 cones").
      // Z_FUNC holds for the draw and the queue is empty when a draw starts.
      localparam integer N = 1 << AW;
      reg  [23:0] zs[0:N-1];
      reg  [AW-1:0] zwp, zdp;
      always @(posedge clk) begin
        if (rst) begin
          zwp <= {AW{1'b0}};
          zdp <= {AW{1'b0}};
        end else begin
          if (push) begin
            zs[zwp] <= in_pix[ZLSB+23:ZLSB];
            zwp     <= zwp + 1'b1;
          end
          if (rsp_valid) zdp <= zdp + 1'b1;
        end
      end
      wire [24:0] q_data;
      core_rdq #(.IW(PW), .DW(25), .AW(AW)) queue (
          .clk(clk), .rst(rst),
          .push(push), .push_item(in_pix),
          .full(q_full), .empty(q_empty),
          .rsp_valid(rsp_valid), .rsp_data({passes(z_func, zs[zdp], rsp_data), rsp_data}),
          .head_valid(q_head), .head_item(q_item), .head_data(q_data), .pop(z_test && take));
      assign q_pass = q_data[24];
      wire unused_q = &{1'b0, q_data[23:0]};
    end
  endgenerate

  assign rd_valid = z_test && in_valid && !q_full;

  // the pixel being resolved: the queue head (Z_TEST) or the input
  assign        cur = z_test ? q_item : in_pix;
  wire          cur_valid = z_test ? q_head : in_valid;
  wire [23:0]   cur_z = cur[ZLSB+23:ZLSB];
  wire          pass = !z_test || q_pass;

  // output register (depth active); room from registered state only
  reg           o_valid;
  reg [PW-1:0]  o_pix;
  wire          room = !o_valid;
  wire          through = OUT_REG != 0 && !active && in_valid && (out_ready || !o_valid);   // below
  // a pixel is resolved when it fails, or passes with room behind and its depth write accepted
  assign take     = cur_valid && (!pass || (room && (!z_write || wr_ready)));
  assign wr_valid = active && cur_valid && pass && z_write && room;
  generate
    if (AW == 0) begin : one_adder
      // one read in flight: a read is issued only while the queue is empty and a Z_TEST write
      // only for its head, so one address adder serves both (its input chosen by the queue's
      // registered state)
      wire [29:0] a = zaddr(fb_z16, (z_test && !q_empty) ? q_item[IDX_W-1:0] : in_pix[IDX_W-1:0]);
      assign rd_addr = a;
      assign wr_addr = a;
    end else begin : two_adders
      assign rd_addr = zaddr(fb_z16, in_pix[IDX_W-1:0]);
      assign wr_addr = zaddr(fb_z16, cur[IDX_W-1:0]);
    end
  endgenerate
  assign wr_data  = cur_z;
  assign in_ready = !active ? (OUT_REG != 0 ? out_ready || !o_valid : out_ready) : z_test ? (!q_full && rd_ready) : take;
  assign passed   = active ? (take && pass) : OUT_REG != 0 ? through : (in_valid && out_ready);

  // OUT_REG: without Z_TEST and Z_WRITE the register passes every pixel on (a pixel a clock, taken while
  // it is empty or being emptied), so the stage's output is always a flip-flop: the next stages'
  // input cones (the texture's and the colour's) start there, not at a multiplexer between this
  // register and the input (the ULX3S clock, docs/gateware.md "Clock estimate"). A clock of
  // latency a draw; the register is empty when a draw starts, so `active` switches only then.
  always @(posedge clk) begin
    if (rst) begin
      o_valid <= 1'b0;
    end else if ((active && take && pass) || through) begin
      o_valid <= 1'b1;
      o_pix   <= cur;
    end else if (out_ready) begin
      o_valid <= 1'b0;
    end
  end
  assign out_valid = (OUT_REG != 0 || active) ? o_valid : in_valid;
  assign out_pix   = (OUT_REG != 0 || active) ? o_pix : in_pix;

  assign idle = q_empty && !o_valid;
endmodule
