// DVI 1.0 TMDS encoder (section 3.2.2): 8 data bits to a 10-bit symbol, transition-minimised, with the
// running disparity kept near 0; outside the data-enable period the two control bits (C1, C0) become
// one of the four control symbols. One symbol per pixel (en), registered.
module tmds_encoder (
  input  wire       clk,
  input  wire       en,
  input  wire       de,
  input  wire [7:0] d,
  input  wire [1:0] c,
  output reg  [9:0] q
);
  function automatic [3:0] ones(input [7:0] v);
    integer i;
    begin
      ones = 4'd0;
      for (i = 0; i < 8; i = i + 1) ones = ones + {3'd0, v[i]};
    end
  endfunction
  // stage 1: XOR or XNOR chain, whichever has fewer transitions
  wire       use_xnor = ones(d) > 4'd4 || (ones(d) == 4'd4 && !d[0]);
  reg  [8:0] qm;
  integer i;
  always @* begin
    qm[0] = d[0];
    for (i = 1; i < 8; i = i + 1) qm[i] = use_xnor ? !(qm[i-1] ^ d[i]) : qm[i-1] ^ d[i];
    qm[8] = !use_xnor;
  end
  // stage 2: DC balance. disp is the running count of ones minus zeros sent, in units of 1
  wire signed [4:0] n1 = {1'b0, ones(qm[7:0])};
  wire signed [4:0] diff = n1 - (5'sd8 - n1);          // ones - zeros of qm[7:0]
  reg  signed [4:0] disp = 5'sd0;
  always @(posedge clk) begin
    if (en) begin
      if (!de) begin
        disp <= 5'sd0;
        case (c)
          2'b00: q <= 10'b1101010100;
          2'b01: q <= 10'b0010101011;
          2'b10: q <= 10'b0101010100;
          default: q <= 10'b1010101011;
        endcase
      end else if (disp == 5'sd0 || diff == 5'sd0) begin
        q <= {!qm[8], qm[8], qm[8] ? qm[7:0] : ~qm[7:0]};
        disp <= qm[8] ? disp + diff : disp - diff;
      end else if ((disp > 5'sd0 && diff > 5'sd0) || (disp < 5'sd0 && diff < 5'sd0)) begin
        q <= {1'b1, qm[8], ~qm[7:0]};
        disp <= disp + (qm[8] ? 5'sd2 : 5'sd0) - diff;
      end else begin
        q <= {1'b0, qm[8], qm[7:0]};
        disp <= disp - (qm[8] ? 5'sd0 : 5'sd2) + diff;
      end
    end
  end
endmodule
