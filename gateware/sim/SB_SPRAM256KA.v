// Behavioural model of the iCE40 UP5K SB_SPRAM256KA (16K x 16 single-port RAM) for Verilator:
// a read returns DATAOUT at the next clock edge; a write stores the nibbles whose MASKWREN bit is 1
// (MASKWREN[n] covers DATAIN[4n+3:4n]) and leaves DATAOUT unchanged. Power-saving pins are ignored
// (tied off by the design). The array is public so the co-simulation can read video memory.
module SB_SPRAM256KA (
  input  wire [13:0] ADDRESS,
  input  wire [15:0] DATAIN,
  input  wire [3:0]  MASKWREN,
  input  wire        WREN,
  input  wire        CHIPSELECT,
  input  wire        CLOCK,
  input  wire        STANDBY,
  input  wire        SLEEP,
  input  wire        POWEROFF,
  output reg  [15:0] DATAOUT
);
  reg [15:0] mem [0:16383] /* verilator public_flat_rw */;
  wire [15:0] bitmask = {{4{MASKWREN[3]}}, {4{MASKWREN[2]}}, {4{MASKWREN[1]}}, {4{MASKWREN[0]}}};
  always @(posedge CLOCK) begin
    if (CHIPSELECT) begin
      if (WREN) mem[ADDRESS] <= (mem[ADDRESS] & ~bitmask) | (DATAIN & bitmask);
      else DATAOUT <= mem[ADDRESS];
    end
  end
  wire unused_ok = &{1'b0, STANDBY, SLEEP, POWEROFF};
endmodule
