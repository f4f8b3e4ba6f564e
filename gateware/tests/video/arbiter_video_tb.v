// The memory arbiter's video client (gateware/rtl/soc/mem_arbiter.v) with the iCEBreaker's VRAM
// (2^15 words, SPRAM timing: every read answered in the next clock): the video output asks for words
// inside VRAM and beyond it (a displayed buffer running past VRAM's end, video_out's req_addr >= 2^15),
// while the render core reads and writes at random (now and then beyond VRAM too). Every answer must reach its own client, in order,
// with the word's data, and 0 for the video's words beyond VRAM; the video's reads beyond VRAM must
// not wait for ever behind the core's (rtl.video.arbiter; prints PASS).
`timescale 1ns / 1ps
module arbiter_video_tb;
  localparam AW = 15, N_VIDEO = 400;
  reg clk = 1'b0, rst = 1'b1;
  always #5 clk = !clk;

  reg         v_req_valid = 1'b0, c_req_valid = 1'b0, c_req_we = 1'b0;
  reg  [29:0] v_req_addr = 30'd0, c_req_addr = 30'd0;
  wire        v_req_ready, v_rsp_valid, c_req_ready, c_rsp_valid, m_req_ready, m_rsp_valid, s_req_ready, s_rsp_valid;
  wire [31:0] rsp_rdata;
  wire        c_range_err, core_stall;
  wire        b_req_valid, b_req_we;
  wire [AW-1:0] b_req_addr;
  wire [31:0] b_req_wdata;
  wire [3:0]  b_req_be;
  reg         b_rsp_valid = 1'b0;
  reg  [31:0] b_rsp_rdata = 32'd0;

  mem_arbiter #(.AW(AW), .TAG_AW(1)) dut (
    .clk(clk), .rst(rst), .v_req_valid(v_req_valid), .v_req_ready(v_req_ready), .v_req_addr(v_req_addr),
    .v_rsp_valid(v_rsp_valid), .m_req_valid(1'b0), .m_req_ready(m_req_ready), .m_req_we(1'b0), .m_req_addr(30'd0),
    .m_req_wdata(32'd0), .m_rsp_valid(m_rsp_valid), .s_req_valid(1'b0), .s_req_ready(s_req_ready), .s_req_addr(30'd0),
    .s_rsp_valid(s_rsp_valid), .c_req_valid(c_req_valid), .c_req_ready(c_req_ready), .c_req_we(c_req_we),
    .c_req_addr(c_req_addr), .c_req_wdata(32'd0), .c_req_be(4'hF), .c_rsp_valid(c_rsp_valid), .rsp_rdata(rsp_rdata),
    .c_range_err(c_range_err), .prot_active(1'b0), .prot_lo({(AW+1){1'b0}}), .prot_hi({(AW+1){1'b0}}),
    .b_req_valid(b_req_valid), .b_req_ready(1'b1), .b_req_we(b_req_we), .b_req_addr(b_req_addr),
    .b_req_wdata(b_req_wdata), .b_req_be(b_req_be), .b_rsp_valid(b_rsp_valid), .b_rsp_rdata(b_rsp_rdata),
    .core_stall(core_stall));

  // the SPRAM: a read answers in the next clock with a word made from its address
  function [31:0] word_at(input [AW-1:0] a);
    word_at = 32'hA5C30000 ^ {a, a[AW-1:AW-2]} ^ 32'h1;
  endfunction
  always @(posedge clk) begin
    b_rsp_valid <= b_req_valid && !b_req_we;
    b_rsp_rdata <= word_at(b_req_addr);
  end

  // expected answers of each client, oldest first
  reg [31:0] v_exp [0:1023];
  reg [31:0] c_exp [0:65535];
  integer v_head = 0, v_tail = 0, c_head = 0, c_tail = 0, v_sent = 0, v_beyond = 0, c_reads = 0, errors = 0;
  integer seed = 7, cycle = 0;

  always @(posedge clk) begin
    cycle <= cycle + 1;
    if (!rst) begin
      if (v_rsp_valid && c_rsp_valid) begin
        $display("FAIL cycle %0d: answers to the video and the core in one clock", cycle);
        errors = errors + 1;
      end
      if (v_rsp_valid) begin
        if (v_head == v_tail || rsp_rdata !== v_exp[v_head % 1024]) begin
          $display("FAIL cycle %0d: video answer %0d is %h, want %h", cycle, v_head, rsp_rdata, v_exp[v_head % 1024]);
          errors = errors + 1;
        end
        v_head = v_head + 1;
      end
      if (c_rsp_valid) begin
        if (c_head == c_tail || rsp_rdata !== c_exp[c_head % 65536]) begin
          $display("FAIL cycle %0d: core answer %0d is %h, want %h", cycle, c_head, rsp_rdata, c_exp[c_head % 65536]);
          errors = errors + 1;
        end
        c_head = c_head + 1;
      end
      // requests accepted in this clock
      if (v_req_valid && v_req_ready) begin
        v_exp[v_tail % 1024] = v_req_addr[29:AW] != 0 ? 32'd0 : word_at(v_req_addr[AW-1:0]);
        v_tail = v_tail + 1;
        v_sent = v_sent + 1;
        if (v_req_addr[29:AW] != 0) v_beyond = v_beyond + 1;
        v_req_valid <= 1'b0;
      end
      if (c_req_valid && c_req_ready) begin
        if (!c_req_we) begin
          c_exp[c_tail % 65536] = c_req_addr[29:AW] != 0 ? 32'd0 : word_at(c_req_addr[AW-1:0]);
          c_tail = c_tail + 1;
          c_reads = c_reads + 1;
        end
        c_req_valid <= 1'b0;
      end
      // new requests (held until taken): the video in runs inside or beyond VRAM, the core nearly always
      if ((!v_req_valid || v_req_ready) && v_sent < N_VIDEO && ($random(seed) & 1) != 0) begin
        v_req_valid <= 1'b1;
        v_req_addr <= (((v_sent / 16) % 3 == 2) ? 30'h8000 : 30'd0) | (30'($unsigned($random(seed))) & 30'h7FFF);
      end
      if ((!c_req_valid || c_req_ready) && v_sent < N_VIDEO && ($random(seed) & 7) != 0) begin
        c_req_valid <= 1'b1;
        c_req_we <= ($random(seed) & 3) == 0;
        // now and then beyond VRAM (answered 0 after the reads in flight, a write dropped)
        c_req_addr <= (($random(seed) & 31) == 0 ? 30'h10000 : 30'd0) | (30'($unsigned($random(seed))) & 30'h7FFF);
      end
    end
  end

  initial begin
    repeat (3) @(posedge clk);
    rst <= 1'b0;
    wait (v_sent == N_VIDEO || cycle > 200000);
    repeat (8) @(posedge clk);   // the last answers (the core asks no more once the video is done)
    if (v_sent != N_VIDEO) begin
      $display("FAIL: %0d of %0d video reads taken in %0d clocks", v_sent, N_VIDEO, cycle);
      errors = errors + 1;
    end
    if (v_beyond < N_VIDEO / 4 || c_reads < 100) begin
      $display("FAIL: too few reads beyond VRAM (%0d) or core reads (%0d) to test", v_beyond, c_reads);
      errors = errors + 1;
    end
    if (v_head != v_tail || c_head != c_tail) begin
      $display("FAIL: answers missing: video %0d of %0d, core %0d of %0d", v_head, v_tail, c_head, c_tail);
      errors = errors + 1;
    end
    if (errors == 0) $display("PASS: %0d video reads (%0d beyond VRAM), %0d core reads, %0d clocks", v_sent, v_beyond, c_reads, cycle);
    $finish;
  end
endmodule
