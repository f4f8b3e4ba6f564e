// Exact floor division for triangle setup (docs/protocol.md section 9): quo = floor(num / den)
// modulo 2^QW and rem = num - floor(num / den) * den in [0, den), for den > 0 and any signed num.
//
// Restoring long division, one quotient bit per cycle, on the magnitude of num: a negative num
// is divided as ~num = -num - 1 and the result mapped back (floor(num/den) = ~floor(~num/den),
// rem = den - 1 - rem'). While the partial remainder is below den / 16 the next four quotient
// bits are known to be 0, so four numerator bits are taken at once: the leading bits of a
// small numerator cost a quarter cycle each.
module core_divider #(
    parameter integer NW = 72,  // numerator width (signed)
    parameter integer DW = 35,  // divisor / remainder width (unsigned)
    parameter integer QW = 32   // quotient bits kept
) (
    input  wire                 clk,
    input  wire                 rst,
    input  wire                 start,  // pulse while idle: latch num / den
    input  wire signed [NW-1:0] num,
    input  wire [DW-1:0]        den,
    output wire                 busy,
    output reg                  done,   // one-cycle pulse: quo / rem valid (held until next start)
    output wire [QW-1:0]        quo,
    output wire [DW-1:0]        rem,
    output wire [DW-1:0]        rem_c   // den - 1 - rem (the step left's remainder, see core_setup)
);
  localparam integer MW = NW - 1;  // magnitude bits
  localparam integer CW = $clog2(MW + 1);
  localparam [CW-1:0] MW_BITS = MW[CW-1:0];

  reg [MW-1:0] nr;      // numerator bits not yet consumed, MSB first
  reg [DW-1:0] pr;      // partial remainder, < den
  reg [QW-1:0] qr;      // quotient bits so far (low QW kept)
  reg [DW-1:0] dv;
  reg          neg;
  reg [CW-1:0] left;    // numerator bits left
  reg          run;

  assign busy = run;

  wire [DW:0]   trial = {pr, nr[MW-1]};
  wire [DW+1:0] diff = {1'b0, trial} - {2'b0, dv};
  wire          fits = !diff[DW+1];
  wire          skip = (pr < (dv >> 4)) && (left >= 4);
  wire [DW-1:0] pr4 = {pr[DW-5:0], nr[MW-1:MW-4]};

  always @(posedge clk) begin
    done <= 1'b0;
    if (rst) begin
      run <= 1'b0;
    end else if (start && !run) begin
      neg  <= num[NW-1];
      nr   <= num[NW-1] ? ~num[MW-1:0] : num[MW-1:0];
      pr   <= {DW{1'b0}};
      qr   <= {QW{1'b0}};
      dv   <= den;
      left <= MW_BITS;
      run  <= 1'b1;
    end else if (run) begin
      if (left == 0) begin
        run  <= 1'b0;
        done <= 1'b1;
        if (neg) begin
          qr <= ~qr;
          pr <= rem_c;
        end
      end else if (skip) begin
        pr   <= pr4;
        nr   <= nr << 4;
        qr   <= qr << 4;
        left <= left - 4;
      end else begin
        pr   <= fits ? diff[DW-1:0] : trial[DW-1:0];
        nr   <= nr << 1;
        qr   <= {qr[QW-2:0], fits};
        left <= left - 1'b1;
      end
    end
  end

  assign quo = qr;
  assign rem = pr;
  assign rem_c = dv - 1'b1 - pr;
endmodule
