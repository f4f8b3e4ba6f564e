// Command FIFO (docs/protocol.md sections 3 and 4): queued writes {index, data} in arrival order.
// Strict link mode holds the entries pushed since the last LINK_CHECK (they count in FIFO_LEVEL but
// do not execute) until the check releases them or a failure / LINK_CTRL discards them.
//
// Storage is one block RAM (2^AW entries, AW chosen so that 2^AW > DEPTH); the executor sees the
// oldest released entry in a first-word-fall-through register and takes one entry per clock.
module command_fifo #(
  parameter DEPTH = 64,     // CAPS.FIFO_DEPTH
  parameter AW = 7          // storage address bits, 2^AW > DEPTH
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
  output reg         out_valid,
  output wire [70:0] out_entry,
  input  wire        pop
);
  (* no_rw_check *) reg [70:0] mem [0:(1 << AW) - 1];   // an entry is never read in the clock it is written
  reg [70:0] q;
  reg [AW-1:0] wr, rel, rd;
  // entries not yet taken, 0..DEPTH (DEPTH <= 1023): in the bits DEPTH needs (7 on up5k, not 11).
  // Not a counter of its own: the entries in the RAM not yet read (wr - rd, below 2^AW > DEPTH)
  // plus the one waiting in q. A push adds to wr, a pop empties q (or q takes the next entry, rd
  // advancing with it), and a discard sets wr to rel, so this is the count those events kept
  // in every clock, with one subtractor instead of a register, its two update adders and wr - rel
  localparam integer CW = $clog2(DEPTH + 1);
  wire [AW-1:0] unread = wr - rd;
  wire [CW-1:0] count = CW'(unread) + CW'(out_valid);
`include "const_compare.vh"

  wire          rd_fire = rd != rel && (!out_valid || pop);

  assign out_entry   = q;
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
      out_valid <= 1'b0;
    end else begin
      if (rd_fire) rd <= rd + 1'b1;
      if (rd_fire) out_valid <= 1'b1;
      else if (pop) out_valid <= 1'b0;
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
