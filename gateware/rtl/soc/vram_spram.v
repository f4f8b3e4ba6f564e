// Video memory of the up5k profile: the iCE40 UP5K's four 16K x 16 single-port RAMs (SB_SPRAM256KA)
// as 32K words of 32 bits (128 KiB). Two RAMs side by side make one 16K x 32 bank; word address
// bit 14 picks the bank. One access per clock, reads answer one clock later; byte enables map to the
// RAMs' nibble write masks. (Simulation uses gateware/sim/sb_spram256ka.v, synthesis the primitive.)
module vram_spram (
  input  wire        clk,
  input  wire        req_valid,
  output wire        req_ready,
  input  wire        req_we,
  input  wire [14:0] req_addr,
  input  wire [31:0] req_wdata,
  input  wire [3:0]  req_be,      // be[3] = bits [31:24] (the byte at the lowest address)
  output reg         rsp_valid,
  output wire [31:0] rsp_rdata
);
  assign req_ready = 1'b1;
  wire [1:0] cs = {req_valid && req_addr[14], req_valid && !req_addr[14]};
  wire [3:0] mask_hi = {req_be[3], req_be[3], req_be[2], req_be[2]};
  wire [3:0] mask_lo = {req_be[1], req_be[1], req_be[0], req_be[0]};
  wire [15:0] q [0:3];
  reg bank_q;

  genvar b;
  generate
    for (b = 0; b < 2; b = b + 1) begin : g_bank
      SB_SPRAM256KA ram_hi (
        .ADDRESS(req_addr[13:0]), .DATAIN(req_wdata[31:16]), .MASKWREN(mask_hi), .WREN(req_we),
        .CHIPSELECT(cs[b]), .CLOCK(clk), .STANDBY(1'b0), .SLEEP(1'b0), .POWEROFF(1'b1), .DATAOUT(q[2 * b + 1]));
      SB_SPRAM256KA ram_lo (
        .ADDRESS(req_addr[13:0]), .DATAIN(req_wdata[15:0]), .MASKWREN(mask_lo), .WREN(req_we),
        .CHIPSELECT(cs[b]), .CLOCK(clk), .STANDBY(1'b0), .SLEEP(1'b0), .POWEROFF(1'b1), .DATAOUT(q[2 * b]));
    end
  endgenerate

  always @(posedge clk) begin
    rsp_valid <= req_valid && !req_we;
    if (req_valid && !req_we) bank_q <= req_addr[14];
  end
  assign rsp_rdata = bank_q ? {q[3], q[2]} : {q[1], q[0]};
endmodule
