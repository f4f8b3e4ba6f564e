// The core's one memory request stream (the soc's arbiter port): a fixed-priority choice among
// the stages' requests, a write combiner on colour writes, the order of outstanding reads, and
// an output register. The stages' requests depend only on their registered state; the grants
// depend on those requests, the output register and mem_req_ready (which may depend on
// mem_req_valid: that is a register). SKID = 1 (up5k) puts a second register behind the output
// one, so the grants depend on registered state only and mem_req_ready reaches no stage.
//
// Priority, highest first: clear writes, colour writes, colour reads, texel reads, depth
// writes, depth reads - later pipeline stages first, so the pipeline drains (READS_FIRST = 1
// lets colour reads before colour writes, in runs). Reads complete in
// request order; a small tag queue routes each response to the stage that asked.
//
// Colour writes to the same word merge (RGB565 and RGBA2222 pixels share words; byte enables
// OR together) while the pipeline keeps producing them; the pending word is sent when a write to
// another word arrives or on `flush`. No read of a draw can observe the pending bytes: within a
// draw the buffers are disjoint unless the core runs in serial mode, which flushes after every
// pixel, and the core drains (flushes) between draws. COMBINE = 0 (the up5k profile) leaves the
// combiner out: each colour write is a request of its own.
module core_memport #(
    parameter integer TAGS_AW = 3,   // log2 of reads in flight
    parameter integer COMBINE = 1,
    // 1: a skid register behind the output register; the stages see a flip-flop (the skid
    // empty), not the soc's mem_req_ready (below)
    parameter integer SKID = 0,
    // 1 (ecp5): colour reads before colour writes, writes in runs (below)
    parameter integer READS_FIRST = 0
) (
    input  wire        clk,
    input  wire        rst,
    input  wire        flush,
    // clear writes
    input  wire        clr_valid,
    output wire        clr_ready,
    input  wire [29:0] clr_addr,
    input  wire [31:0] clr_data,
    input  wire [3:0]  clr_be,
    // colour writes
    input  wire        cw_valid,
    output wire        cw_ready,
    input  wire [29:0] cw_addr,
    input  wire [31:0] cw_data,
    input  wire [3:0]  cw_be,
    // colour reads
    input  wire        cr_valid,
    output wire        cr_ready,
    input  wire [29:0] cr_addr,
    output wire        cr_rsp,
    // texel reads
    input  wire        tr_valid,
    output wire        tr_ready,
    input  wire [29:0] tr_addr,
    output wire        tr_rsp,
    // depth writes
    input  wire        zw_valid,
    output wire        zw_ready,
    input  wire [29:0] zw_addr,
    input  wire [23:0] zw_data,
    // depth reads
    input  wire        zr_valid,
    output wire        zr_ready,
    input  wire [29:0] zr_addr,
    output wire        zr_rsp,
    // the soc's port
    output wire        mem_req_valid,
    input  wire        mem_req_ready,
    output wire        mem_req_we,
    output wire [29:0] mem_req_addr,
    output wire [31:0] mem_req_wdata,
    output wire [3:0]  mem_req_be,
    input  wire        mem_rsp_valid,
    output wire        idle,
    output wire        pending_write  // the combiner holds a word
);
  // ---- write combiner ----
  // COMBINE = 0 (up5k) has none: colour writes go to the grant as they come, one request a pixel
  // (RGB565 and RGBA2222 pixels sharing a word take a request each), and the 66 flip-flops of the
  // pending word and its byte merge go; what lands in memory is the same.
  wire        p_valid;
  wire [29:0] p_addr;
  wire [31:0] p_data;
  wire [3:0]  p_be;
  wire        p_req;
  wire        p_gnt;
  if (COMBINE != 0) begin : combiner
    reg        q_valid;
    reg [29:0] q_addr;
    reg [31:0] q_data;
    reg [3:0]  q_be;
    wire same = q_valid && (q_addr == cw_addr);
    assign p_req = q_valid && ((cw_valid && !same) || flush);
    // an incoming colour write merges, fills an empty combiner, or replaces the word being sent
    assign cw_ready = same || !q_valid || p_gnt;
    wire [31:0] merged = {cw_be[3] ? cw_data[31:24] : q_data[31:24], cw_be[2] ? cw_data[23:16] : q_data[23:16],
                          cw_be[1] ? cw_data[15:8] : q_data[15:8], cw_be[0] ? cw_data[7:0] : q_data[7:0]};
    always @(posedge clk) begin
      if (rst) begin
        q_valid <= 1'b0;
      end else if (cw_valid && cw_ready) begin
        q_valid <= 1'b1;
        q_addr  <= cw_addr;
        q_data  <= (same && !p_gnt) ? merged : cw_data;
        q_be    <= (same && !p_gnt) ? (q_be | cw_be) : cw_be;
      end else if (p_gnt) begin
        q_valid <= 1'b0;
      end
    end
    assign {p_valid, p_addr, p_data, p_be} = {q_valid, q_addr, q_data, q_be};
  end else begin : no_combiner
    wire unused_flush = flush;
    assign p_req    = cw_valid;
    assign cw_ready = p_gnt;
    assign p_valid  = 1'b0;  // nothing is held here
    assign {p_addr, p_data, p_be} = {cw_addr, cw_data, cw_be};
  end
  assign pending_write = p_valid;

  // ---- tag queue: who asked for each outstanding read ----
  localparam [1:0] T_CR = 2'd0, T_TR = 2'd1, T_ZR = 2'd2;
  localparam integer NT = 1 << TAGS_AW;
  reg [1:0] tags[0:NT-1];
  reg [TAGS_AW:0] tw, tr;
  wire tag_room = (tw - tr) != NT[TAGS_AW:0];
  wire [1:0] rsp_tag = tags[tr[TAGS_AW-1:0]];
  assign cr_rsp = mem_rsp_valid && rsp_tag == T_CR;
  assign tr_rsp = mem_rsp_valid && rsp_tag == T_TR;
  assign zr_rsp = mem_rsp_valid && rsp_tag == T_ZR;

  // ---- output register ----
  // SKID = 0: a request is granted when the output register is free or being accepted, so the
  // soc's mem_req_ready (the arbiter's decision of this clock: priority, swap protection) reaches
  // every stage's stall logic in one clock. SKID = 1 (issue 19, 25.125 MHz on the UP5K): a
  // request is granted when the skid register is empty, a flip-flop; a granted request goes to
  // the output register when that is free or being accepted, else to the skid, and the skid goes
  // first when the output register frees. One request a clock still leaves, in grant order; a
  // refusal stops the stages a clock later and lets them go a clock later, as long.
  reg        o_valid;
  wire       o_room = !o_valid || mem_req_ready;
  wire       s_valid;  // the skid holds a request (0 without SKID)
  wire       g_room = (SKID != 0) ? !s_valid : o_room;
  reg        g_we;
  reg [29:0] g_addr;
  reg [31:0] g_data;
  reg [3:0]  g_be;
  reg        g_any, g_read;
  reg [1:0]  g_tag;
  reg [5:0]  gnt;  // one-hot: clr, cw (combiner), cr, tr, zw, zr
  // READS_FIRST (issue 19, the ULX3S's SDRAM): a colour write waits while a colour read can go,
  // unless the last of the two granted was a write (wmode): the port then sends whole runs of
  // reads and of writes. In plain priority order the blend's reads and writes fell into one of
  // several stable patterns (runs of 5-6, or a write after every read), each costing the SDRAM a
  // 4-clock read-to-write turn per switch, and a refresh's phase picked which: the draw's clocks
  // varied by 8 % with the moment it started (docs/gateware.md "Why the blended draw depended on
  // the SPI clock"). A read may overtake a colour write because a draw writes a pixel once, the
  // buffers are disjoint outside serial mode (which moves a pixel at a time) and a draw starts
  // with the port drained: the write combiner's held word relies on the same.
  reg        wmode;
  always @(posedge clk) begin
    if (rst) wmode <= 1'b0;
    else if (gnt[1]) wmode <= 1'b1;
    else if (gnt[2]) wmode <= 1'b0;
  end
  always @(*) begin
    gnt = 6'd0;
    if (g_room) begin
      if (clr_valid) gnt[0] = 1'b1;
      else if (p_req && (READS_FIRST == 0 || wmode || !(cr_valid && tag_room))) gnt[1] = 1'b1;
      else if (cr_valid && tag_room) gnt[2] = 1'b1;
      else if (tr_valid && tag_room) gnt[3] = 1'b1;
      else if (zw_valid) gnt[4] = 1'b1;
      else if (zr_valid && tag_room) gnt[5] = 1'b1;
    end
    g_any  = |gnt;
    g_read = gnt[2] | gnt[3] | gnt[5];
    g_tag  = gnt[2] ? T_CR : gnt[3] ? T_TR : T_ZR;
    g_we   = gnt[0] | gnt[1] | gnt[4];
    g_addr = gnt[0] ? clr_addr : gnt[1] ? p_addr : gnt[2] ? cr_addr : gnt[3] ? tr_addr :
             gnt[4] ? zw_addr : zr_addr;
    g_data = gnt[0] ? clr_data : gnt[1] ? p_data : {8'd0, zw_data};
    g_be   = gnt[0] ? clr_be : gnt[1] ? p_be : 4'b1111;
  end
  assign clr_ready = gnt[0];
  assign p_gnt     = gnt[1];
  assign cr_ready  = gnt[2];
  assign tr_ready  = gnt[3];
  assign zw_ready  = gnt[4];
  assign zr_ready  = gnt[5];

  always @(posedge clk) begin
    if (rst) begin
      tw <= 0;
      tr <= 0;
    end else begin
      if (g_any && g_read) begin
        tags[tw[TAGS_AW-1:0]] <= g_tag;
        tw <= tw + 1'b1;
      end
      if (mem_rsp_valid) tr <= tr + 1'b1;
    end
  end

  // what enters the output register: the skid's request first, else this clock's grant
  wire        n_we;
  wire [29:0] n_addr;
  wire [31:0] n_data;
  wire [3:0]  n_be;
  if (SKID != 0) begin : skid
    reg        k_valid;
    reg        k_we;
    reg [29:0] k_addr;
    reg [31:0] k_data;
    reg [3:0]  k_be;
    always @(posedge clk) begin
      if (rst) k_valid <= 1'b0;
      else if (o_room) k_valid <= 1'b0;
      else if (g_any) k_valid <= 1'b1;
      // a grant implies an empty skid, so loading it on every grant overwrites nothing; one the
      // output register takes in the same clock leaves k_valid 0
      if (g_any) begin
        k_we   <= g_we;
        k_addr <= g_addr;
        k_data <= g_data;
        k_be   <= g_be;
      end
    end
    assign s_valid = k_valid;
    assign {n_we, n_addr, n_data, n_be} = k_valid ? {k_we, k_addr, k_data, k_be} : {g_we, g_addr, g_data, g_be};
  end else begin : no_skid
    assign s_valid = 1'b0;
    assign {n_we, n_addr, n_data, n_be} = {g_we, g_addr, g_data, g_be};
  end

  reg        o_we;
  reg [29:0] o_addr;
  reg [31:0] o_data;
  reg [3:0]  o_be;
  always @(posedge clk) begin
    if (rst) begin
      o_valid <= 1'b0;
    end else if (o_room) begin
      o_valid <= s_valid || g_any;
      if (s_valid || g_any) begin
        o_we   <= n_we;
        o_addr <= n_addr;
        o_data <= n_data;
        o_be   <= n_be;
      end
    end
  end
  assign mem_req_valid = o_valid;
  assign mem_req_we    = o_we;
  assign mem_req_addr  = o_addr;
  assign mem_req_wdata = o_data;
  assign mem_req_be    = o_be;

  assign idle = !p_valid && !o_valid && !s_valid && (tw == tr);
endmodule
