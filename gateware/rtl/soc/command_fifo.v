// Command FIFO (docs/protocol.md sections 3 and 4): queued writes {index, data} in arrival order.
// Strict link mode holds the entries pushed since the last LINK_CHECK (they count in FIFO_LEVEL but
// do not execute) until the check releases them or a failure / LINK_CTRL discards them.
//
// Storage is one block RAM (2^AW entries, AW chosen so that 2^AW > DEPTH); the executor sees the
// oldest released entry in a first-word-fall-through register and takes one entry per clock.
// HEAD = 1 (ecp5, issue 19 "fmax-cmd"; on the up5k it bought no clock): the entry the executor
// sees is a flip-flop copy of the block RAM's output register, loaded only while that copy is
// empty, so neither the RAM's slow clock-to-out runs into the executor's decode nor the executor's
// `pop` into the RAM's read and the count in the same clock; the price is a clock per entry taken
// from a backlog (two clocks an entry at most).
module command_fifo #(
  parameter DEPTH = 64,     // CAPS.FIFO_DEPTH
  parameter AW = 7,         // storage address bits, 2^AW > DEPTH
  parameter HEAD = 0        // 1: the executor's entry is a flip-flop copy of the RAM's output
) (
  input  wire        clk,
  input  wire        rst,            // power-on or RESET: empty
  input  wire        push,
  input  wire        push_held,      // strict mode: the pushed entry waits for a LINK_CHECK
  input  wire [70:0] push_entry,     // {index[6:0], data[63:0]}
  input  wire        release_held,
  input  wire        discard_held,
  output wire        full,
  output wire        nearly_full,    // fewer than 32 entries free (the BUSY pin)
  output wire [10:0] level,          // entries not yet taken by the executor, held ones included
  output wire        held,           // some entries wait for a LINK_CHECK
  output wire        out_valid,
  output wire [70:0] out_entry,
  output wire        read_any,       // an entry is read from the RAM (in q or h): work is waiting
  input  wire        pop
);
  (* no_rw_check *) reg [70:0] mem [0:(1 << AW) - 1];   // an entry is never read in the clock it is written
  reg [70:0] q;
  reg        q_valid;       // q holds an entry not yet taken (by the executor, or by h)
  reg [AW-1:0] wr, rel, rd;
  // entries not yet taken, 0..DEPTH (DEPTH <= 1023): in the bits DEPTH needs (7 on up5k, not 11).
  // Not a counter of its own: the entries in the RAM not yet read (wr - rd, below 2^AW > DEPTH)
  // plus the one waiting in q (and in h). A push adds to wr, a pop empties q (or q takes the next
  // entry, rd advancing with it), and a discard sets wr to rel, so this is the count those events
  // kept in every clock, with one subtractor instead of a register, its two update adders and wr - rel
  localparam integer CW = $clog2(DEPTH + 1);
  wire [AW-1:0] unread = wr - rd;
  wire          h_valid;
  wire [CW-1:0] count = CW'(unread) + CW'(q_valid) + CW'(h_valid);
`include "const_compare.vh"

  wire          q_take;     // q's entry leaves this clock (to the executor, or to h)
  assign read_any = q_valid || h_valid;
  wire          rd_fire = rd != rel && (!q_valid || q_take);

  generate
    if (HEAD != 0) begin : g_head
      // h and its valid depend on registers only: h loads when it is empty (the executor's pop,
      // which empties it, is a clock earlier), q then takes the next entry in the same clock
      reg [70:0] h;
      reg        hv;
      assign q_take    = q_valid && !hv;
      assign h_valid   = hv;
      assign out_valid = hv;
      assign out_entry = h;
      always @(posedge clk) begin
        if (q_take) h <= q;
        if (rst) hv <= 1'b0;
        else if (q_take) hv <= 1'b1;
        else if (pop) hv <= 1'b0;
      end
    end else begin : g_fwft
      assign q_take    = pop;
      assign h_valid   = 1'b0;
      assign out_valid = q_valid;
      assign out_entry = q;
    end
  endgenerate

  localparam [CW-1:0] DEPTH_C = DEPTH[CW-1:0];
  localparam [CW:0]   NEAR    = DEPTH > 31 ? DEPTH - 31 : 0;   // fewer than 32 free: count >= DEPTH - 31
  assign full        = count == DEPTH_C;
  assign nearly_full = ge_const(16'(count), 32'(NEAR));
  assign level       = 11'(count);
  assign held        = wr != rel;

  always @(posedge clk) begin
    if (push && !full) mem[wr] <= push_entry;
    if (rd_fire) q <= mem[rd];
  end

  always @(posedge clk) begin
    if (rst) begin
      wr <= {AW{1'b0}};
      rel <= {AW{1'b0}};
      rd <= {AW{1'b0}};
      q_valid <= 1'b0;
    end else begin
      if (rd_fire) rd <= rd + 1'b1;
      if (rd_fire) q_valid <= 1'b1;
      else if (q_take) q_valid <= 1'b0;
      if (discard_held) begin
        wr <= rel;
      end else begin
        if (push && !full) begin
          wr <= wr + 1'b1;
          if (!push_held) rel <= wr + 1'b1;
        end else if (release_held) begin
          rel <= wr;
        end
      end
    end
  end
endmodule
