// DVI 1.0 TMDS encoder (section 3.2.2): 8 data bits to a 10-bit symbol, transition-minimised, with the
// running disparity kept near 0; outside the data-enable period the two control bits (C1, C0) become
// one of the four control symbols. One symbol per pixel (en), in two register stages (issue 19: the
// ones count, the XOR/XNOR chain and the DC balance in one clock were the ULX3S's worst cone): stage 1
// takes the pixel on en and registers the chain's word, its ones-minus-zeros and DE / C beside it;
// stage 2 makes the symbol and the running disparity one clock later, so q changes one core clock
// after en (the ULX3S top delays its pixel toggle to match; pixels come every second clock).
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
  // stage 1 registers: the chain's word, its ones - zeros, DE and C of the same pixel
  wire signed [4:0] n1 = {1'b0, ones(qm[7:0])};
  reg  [8:0]        qm_r = 9'd0;
  reg  signed [4:0] diff_r = 5'sd0;                    // ones - zeros of qm[7:0]
  reg               de_r = 1'b0, en_r = 1'b0;
  reg  [1:0]        c_r = 2'b00;
  always @(posedge clk) begin
    en_r <= en;
    if (en) begin
      qm_r <= qm;
      diff_r <= n1 - (5'sd8 - n1);
      de_r <= de;
      c_r <= c;
    end
  end
  // stage 2: DC balance. disp is the running count of ones minus zeros sent, in units of 1
  reg  signed [4:0] disp = 5'sd0;
  always @(posedge clk) begin
    if (en_r) begin
      if (!de_r) begin
        disp <= 5'sd0;
        case (c_r)
          2'b00: q <= 10'b1101010100;
          2'b01: q <= 10'b0010101011;
          2'b10: q <= 10'b0101010100;
          default: q <= 10'b1010101011;
        endcase
      end else if (disp == 5'sd0 || diff_r == 5'sd0) begin
        q <= {!qm_r[8], qm_r[8], qm_r[8] ? qm_r[7:0] : ~qm_r[7:0]};
        disp <= qm_r[8] ? disp + diff_r : disp - diff_r;
      end else if ((disp > 5'sd0 && diff_r > 5'sd0) || (disp < 5'sd0 && diff_r < 5'sd0)) begin
        q <= {1'b1, qm_r[8], ~qm_r[7:0]};
        disp <= disp + (qm_r[8] ? 5'sd2 : 5'sd0) - diff_r;
      end else begin
        q <= {1'b0, qm_r[8], qm_r[7:0]};
        disp <= disp - (qm_r[8] ? 5'sd0 : 5'sd2) + diff_r;
      end
    end
  end
endmodule
