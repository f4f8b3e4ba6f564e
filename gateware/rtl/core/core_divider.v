// Exact floor division for triangle setup (docs/protocol.md section 9): quo = floor(num / den)
// modulo 2^QW and rem = num - floor(num / den) * den in [0, den), for den > 0 and any signed num.
//
// Restoring long division, one quotient bit per cycle, on the magnitude of num: a negative num
// is divided as ~num = -num - 1 and the result mapped back (floor(num/den) = ~floor(~num/den),
// rem = den - 1 - rem'). The numerator register shifts left and takes the quotient bits in at
// the bottom, already complemented for a negative num. The remainder is mapped back by the
// reader: `neg` says that rem and rem_c are exchanged (rem = rem_c' and rem_c = rem' below),
// so one multiplexer there picks either without a second one here. With SKIP, while the partial
// remainder is below den / 16 the next four quotient bits are known to be 0 and four numerator
// bits are taken at once (small numerators then cost a quarter cycle per leading bit); without
// it a division takes NW cycles. With NARROW > 0, a start with `narrow` says the magnitude is
// below 2^NARROW: only its low NARROW bits are taken, read at bit NARROW - 1 of the shifting
// register instead of its top (the bits above would give quotient bits beyond QW and leave the
// remainder 0), so the division takes NARROW + 1 cycles; the quotient bits still enter at the
// bottom, below what is left of the numerator. With COMP, a `comp` pulse while idle replaces rem by
// den - 1 - rem through the division's own subtractor (its trial is then {0, rem}, so diff =
// rem - den and ~diff = den - 1 - rem): a caller that needs both remainders in turn complements
// in place instead of keeping a second adder and a multiplexer for rem_c (fit10,
// docs/gateware.md); the complement is its own inverse.
module core_divider #(
    parameter integer NW = 72,  // numerator width (signed)
    parameter integer DW = 35,  // divisor / remainder width (unsigned)
    parameter integer QW = 32,  // quotient bits kept
    parameter integer SKIP = 1,
    parameter integer NARROW = 0, // 0: none; else at least QW (not with SKIP)
    parameter integer COMP = 0    // 1: the `comp` input complements rem in place (above)
) (
    input  wire                 clk,
    input  wire                 rst,
    input  wire                 start,  // pulse while idle: latch num
    input  wire signed [NW-1:0] num,
    input  wire                 narrow, // with NARROW: |num| < 2^NARROW (num >= -2^NARROW)
    input  wire [DW-1:0]        den,    // held by the caller until rem_c is read (not copied)
    input  wire                 comp,   // with COMP, while idle and not starting: rem <= den - 1 - rem
    output wire                 busy,
    output reg                  done,   // one-cycle pulse: quo / rem valid (held until next start)
    output wire [QW-1:0]        quo,
    output wire [DW-1:0]        rem,    // with neg = 0: num - quo * den; with neg = 1: den - 1 - that
    output wire [DW-1:0]        rem_c,  // den - 1 - rem (the step left's remainder, see core_setup)
    output reg                  neg     // num < 0: rem and rem_c exchanged
);
  localparam integer MW = NW - 1;  // magnitude bits
  localparam integer CW = $clog2(MW + 1);
  localparam [CW-1:0] MW_BITS = MW[CW-1:0];

  reg [MW-1:0] nq;      // numerator bits not yet consumed (top), quotient bits so far (bottom)
  reg [DW-1:0] pr;      // partial remainder, < den
  wire [DW-1:0] dv = den;
  reg [CW-1:0] left;    // numerator bits left
  reg          run;
  localparam integer NB = (NARROW > 0) ? NARROW - 1 : MW - 1;  // the narrowed run's next bit
  localparam [CW-1:0] NARROW_BITS = CW'(NB + 1);
  reg          nar;     // narrowed run

  assign busy = run;

  wire          cmp = (COMP != 0) && comp;
  wire [DW:0]   trial = cmp ? {1'b0, pr} : {pr, (NARROW > 0 && nar) ? nq[NB] : nq[MW-1]};
  wire [DW+1:0] diff = {1'b0, trial} - {2'b0, dv};
  wire          fits = !diff[DW+1];
  wire          skip = (SKIP != 0) && (pr < (dv >> 4)) && (left >= 4);
  assign rem_c = dv - 1'b1 - pr;

  always @(posedge clk) begin
    done <= 1'b0;
    if (rst) begin
      run <= 1'b0;
    end else if (start && !run) begin
      neg  <= num[NW-1];
      nq   <= num[NW-1] ? ~num[MW-1:0] : num[MW-1:0];
      nar  <= (NARROW > 0) && narrow;
      pr   <= {DW{1'b0}};
      left <= ((NARROW > 0) && narrow) ? NARROW_BITS : MW_BITS;
      run  <= 1'b1;
    end else if (run) begin
      if (left == 0) begin
        run  <= 1'b0;
        done <= 1'b1;
      end else if (skip) begin
        pr   <= {pr[DW-5:0], nq[MW-1:MW-4]};
        nq   <= {nq[MW-5:0], {4{neg}}};
        left <= left - 4;
      end else begin
        pr   <= fits ? diff[DW-1:0] : trial[DW-1:0];
        nq   <= {nq[MW-2:0], fits ^ neg};
        left <= left - 1'b1;
      end
    end else if (cmp) begin
      pr <= ~diff[DW-1:0];
    end
  end

  assign quo = nq[QW-1:0];
  assign rem = pr;
endmodule
