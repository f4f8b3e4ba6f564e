// sdram_ctrl (gateware/rtl/soc) against the behavioural chip (gateware/sim/sdram_model.v) with the
// chip clocked as a board clocks it (docs/gateware.md "SDRAM", issue 19): random 32-bit words with
// random byte enables written across banks and rows, read back in a random order mixed with more
// writes, every answer compared with a copy kept here. Parameters:
//   CLK_INVERTED  the chip's clock is the controller's inverted (the ULX3S) or in phase;
//   CAPTURE_FALL  the controller samples DQ on the falling edge (the boards) or the rising one;
//   EXPECT_OK     1: every word must read back right (and, with CLK_INVERTED, the chip see no timing
//                 violation); 0: the capture is at the wrong edge for this clock, so reads must come
//                 back wrong (the chip's data is changing at that edge) — the model must tell.
// Also checks the controller's registered ready: issue_next is only ever set for a clock in which the
// held request issues. Prints "PASS:" or "FAIL:" (ctest matches them).
`timescale 1ns / 1ps
module sdram_capture_tb;
  parameter CLK_INVERTED = 1;
  parameter CAPTURE_FALL = 1;
  parameter EXPECT_OK = 1;
  parameter CLK_MHZ = 50;
  parameter CL = 2;
  localparam integer WORDS = 512, OPS = 6000;

  reg clk = 1'b0;
  reg rst = 1'b1;
  always #(500.0 / CLK_MHZ) clk = !clk;

  reg         req_valid = 1'b0, req_we = 1'b0;
  reg  [22:0] req_addr = 23'd0;
  reg  [31:0] req_wdata = 32'd0;
  reg  [3:0]  req_be = 4'd0;
  wire        req_ready, rsp_valid, init_done, refresh;
  wire [31:0] rsp_rdata;
  wire        sd_cke, sd_cs_n, sd_ras_n, sd_cas_n, sd_we_n, sd_dq_oe;
  wire [1:0]  sd_ba, sd_dqm;
  wire [12:0] sd_a;
  wire [15:0] sd_dq_o, chip_dq, sd_dq_i;
  wire        chip_oe;
  wire [31:0] violations, reads, writes, activates;

  sdram_ctrl #(.CLK_MHZ(CLK_MHZ), .CL(CL), .CAPTURE_FALL(CAPTURE_FALL)) ctrl (
    .clk(clk), .rst(rst), .req_valid(req_valid), .req_ready(req_ready), .req_we(req_we), .req_addr(req_addr),
    .req_wdata(req_wdata), .req_be(req_be), .rsp_valid(rsp_valid), .rsp_rdata(rsp_rdata), .sd_cke(sd_cke),
    .sd_cs_n(sd_cs_n), .sd_ras_n(sd_ras_n), .sd_cas_n(sd_cas_n), .sd_we_n(sd_we_n), .sd_ba(sd_ba), .sd_a(sd_a),
    .sd_dqm(sd_dqm), .sd_dq_o(sd_dq_o), .sd_dq_oe(sd_dq_oe), .sd_dq_i(sd_dq_i), .init_done(init_done),
    .refresh(refresh));
  sdram_model #(.CLK_MHZ(CLK_MHZ), .CL(CL), .CLK_INVERTED(CLK_INVERTED)) chip (
    .clk(clk), .cke(sd_cke), .cs_n(sd_cs_n), .ras_n(sd_ras_n), .cas_n(sd_cas_n), .we_n(sd_we_n), .ba(sd_ba),
    .a(sd_a), .dqm(sd_dqm), .dq_in(sd_dq_o), .dq_in_oe(sd_dq_oe), .dq_out(chip_dq), .dq_out_oe(chip_oe),
    .violations(violations), .reads(reads), .writes(writes), .activates(activates));
  assign sd_dq_i = chip_oe ? chip_dq : 16'hFFFF;   // the co-simulation's pull-up (gateware/sim/spigpu_sim.v)

  // the words under test: addresses spread over the banks and rows, their expected contents
  reg [22:0] addr [0:WORDS-1];
  reg [31:0] shadow [0:WORDS-1];
  // reads in flight, oldest first, with the word's contents when the read was asked for (requests are
  // served in order, so a later write to it does not change what the read returns)
  reg [31:0] pend_idx [0:63];
  reg [31:0] pend_exp [0:63];
  integer    pend_head = 0, pend_tail = 0;
  integer    checked = 0, wrong = 0, i, op, idx;
  reg [31:0] seed = 32'd20261127;

  function [31:0] rnd(input integer unused);
    begin
      seed = seed * 32'd1664525 + 32'd1013904223;
      rnd = seed ^ (seed >> 15);
    end
  endfunction

  // the controller's registered ready (issue 19) promises that the request it holds issues in this
  // clock: a broken promise would take a second request into the one slot
  integer broken = 0;
  always @(posedge clk) if (!rst && ctrl.issue_next && !ctrl.do_rw) broken = broken + 1;

  // answers arrive in request order
  always @(posedge clk) begin
    if (rsp_valid) begin
      if (pend_head == pend_tail) begin
        $display("FAIL: an answer without a read in flight");
        $finish;
      end
      if (rsp_rdata !== pend_exp[pend_head % 64]) begin
        if (wrong < 4)
          $display("read of word %0d (address 0x%06h): 0x%08h, expected 0x%08h", pend_idx[pend_head % 64],
                   addr[pend_idx[pend_head % 64]], rsp_rdata, pend_exp[pend_head % 64]);
        wrong = wrong + 1;
      end
      checked = checked + 1;
      pend_head = pend_head + 1;
    end
  end

  task automatic issue(input we, input integer w, input [31:0] data, input [3:0] be);
    begin
      req_valid <= 1'b1;
      req_we <= we;
      req_addr <= addr[w];
      req_wdata <= data;
      req_be <= be;
      @(posedge clk);
      while (!req_ready) @(posedge clk);
      req_valid <= 1'b0;
      if (!we) begin
        pend_idx[pend_tail % 64] = w;
        pend_exp[pend_tail % 64] = shadow[w];
        pend_tail = pend_tail + 1;
      end
    end
  endtask

  function [31:0] merge(input [31:0] old, input [31:0] d, input [3:0] be);
    integer j;
    begin
      for (j = 0; j < 4; j = j + 1) merge[8*j +: 8] = be[j] ? d[8*j +: 8] : old[8*j +: 8];
    end
  endfunction

  reg [31:0] d;
  reg [3:0]  be;
  initial begin
    for (i = 0; i < WORDS; i = i + 1) begin
      d = rnd(0);
      addr[i] = {d[22:10], i[1:0], d[7:0]};   // bank i[1:0]: every bank, random rows and columns
      shadow[i] = rnd(0);
    end
    repeat (4) @(posedge clk);
    rst <= 1'b0;
    while (!init_done) @(posedge clk);
    for (i = 0; i < WORDS; i = i + 1) issue(1'b1, i, shadow[i], 4'hF);
    for (op = 0; op < OPS; op = op + 1) begin
      idx = rnd(0) % WORDS;
      if (rnd(0) % 4 == 0) begin
        d = rnd(0);
        be = rnd(0) % 16;
        shadow[idx] = merge(shadow[idx], d, be);
        issue(1'b1, idx, d, be);
      end else begin
        issue(1'b0, idx, 32'd0, 4'h0);
      end
      // sometimes idle, so reads also meet an empty controller
      if (rnd(0) % 8 == 0) repeat (rnd(0) % 6) @(posedge clk);
    end
    repeat (40) @(posedge clk);
    $display("CLK_INVERTED=%0d CAPTURE_FALL=%0d: %0d reads checked, %0d wrong; chip: %0d reads, %0d writes, %0d activates, %0d timing violations",
             CLK_INVERTED, CAPTURE_FALL, checked, wrong, reads, writes, activates, violations);
    if (broken != 0)
      $display("FAIL: issue_next set in %0d clocks without a READ or WRITE issuing", broken);
    else if (checked == 0 || pend_head != pend_tail)
      $display("FAIL: %0d reads answered of %0d", pend_head, pend_tail);
    else if (EXPECT_OK != 0 && wrong != 0)
      $display("FAIL: reads came back wrong");
    else if (EXPECT_OK != 0 && CLK_INVERTED != 0 && violations != 0)
      $display("FAIL: the chip saw timing violations");
    else if (EXPECT_OK == 0 && wrong == 0)
      $display("FAIL: reads captured at the wrong edge came back right: the model does not tell the edges apart");
    else if (EXPECT_OK != 0)
      $display("PASS: every read right");
    else
      $display("PASS: the wrong edge reads wrong data, as it must");
    $finish;
  end
endmodule
