// Memory arbiter: one video-memory port shared by the memory-access unit (MEM_ADDR / MEM_DATA), a
// board's video output (video_out, reads; tied off in the co-simulation), the scanout reader and the
// render core, in that priority (the scanout reader wins over the core after waiting 16 clocks). The
// memory-access unit asks for at most two words per SPI frame and must reload its prefetch within
// one (docs/protocol.md 2.4), so it stays first; the video output, which reads a line buffer half per
// screen line and cannot wait for a frame, comes before the scanout and the core. One request per
// clock; responses return in request order to whoever asked.
//
// VRAM bounds (docs/protocol.md section 6) for the core: a write beyond VRAM is dropped and a read
// beyond returns 0, both raising ERR_MEM_RANGE. Such a read waits until no other read is in flight
// so that its zero can be answered in order. The video output's reads beyond VRAM (a displayed buffer
// running past its end) are answered with 0 the same way, the scanout and the core waiting meanwhile;
// the memory-access unit and the scanout never ask beyond VRAM.
//
// Swap protection (docs/gateware.md "Scanout"): from the FB_DISPLAY write's execution until the
// frame has been read, writes into the part of the display buffer the scanout has not read yet wait.
// The scanned frame is therefore the buffer as it was when FB_DISPLAY executed, exactly the
// simulator's frame; rendering into another buffer never waits.
module mem_arbiter #(
  parameter        AW = 15,                 // back-end word address bits: VRAM is 2^AW words
  // in-flight reads tracked: 2^TAG_AW. The SPRAM answers every read in the next clock, so at most
  // one is ever in flight there (TAG_AW = 1 never runs out); the SDRAM controller keeps up to 8.
  parameter        TAG_AW = 3
) (
  input  wire        clk,
  input  wire        rst,
  // video output (reads; beyond VRAM answered 0; constant 0 where there is none)
  input  wire        v_req_valid,
  output wire        v_req_ready,
  input  wire [29:0] v_req_addr,
  output wire        v_rsp_valid,
  // memory-access unit (32-bit words, all bytes)
  input  wire        m_req_valid,
  output wire        m_req_ready,
  input  wire        m_req_we,
  input  wire [29:0] m_req_addr,
  input  wire [31:0] m_req_wdata,
  output wire        m_rsp_valid,
  // scanout reader (reads)
  input  wire        s_req_valid,
  output wire        s_req_ready,
  input  wire [29:0] s_req_addr,
  output wire        s_rsp_valid,
  // render core
  input  wire        c_req_valid,
  output wire        c_req_ready,
  input  wire        c_req_we,
  input  wire [29:0] c_req_addr,
  input  wire [31:0] c_req_wdata,
  input  wire [3:0]  c_req_be,
  output wire        c_rsp_valid,
  output wire [31:0] rsp_rdata,       // data of whichever response is valid
  output reg         c_range_err,
  // swap protection window [prot_lo, prot_hi) in VRAM words (scanout: both at most 2^AW)
  input  wire        prot_active,
  input  wire [AW:0] prot_lo,
  input  wire [AW:0] prot_hi,
  // back end (SPRAM or SDRAM controller): in-order read responses
  output wire          b_req_valid,
  input  wire          b_req_ready,
  output wire          b_req_we,
  output wire [AW-1:0] b_req_addr,
  output wire [31:0]   b_req_wdata,
  output wire [3:0]    b_req_be,
  input  wire          b_rsp_valid,
  input  wire [31:0]   b_rsp_rdata,
  output wire          core_stall      // a core request waits this clock (protection, priority, back end)
);
  // in-flight reads: the client of each, oldest first
  localparam [TAG_AW:0] TAGS = {1'b1, {TAG_AW{1'b0}}};
  reg [1:0] tag [0:(1 << TAG_AW) - 1];
  reg [TAG_AW-1:0] tag_rd, tag_wr;
  reg [TAG_AW:0] tag_count;
  reg       zero_rsp;     // answer a core or video read beyond VRAM with 0 in this cycle
  reg       zero_v;       // that answer is the video output's
  reg [3:0] scan_wait;

  wire tags_room  = tag_count != TAGS;
  wire tags_empty = tag_count == 0;
  // A comparator pair per writer, each on its own address register: one pair on the address the
  // memory-access unit's phase chose (m_writes ? m : c) put that choice, 16 multiplexers driven by
  // one net, in front of the compare on the arbiter's one-clock decision (issue 19, 25.125 MHz).
  // The memory-access unit writes only while the core is idle (the executor starts MEM_* after the
  // core finished and no core command during them), so both never block at once.
  wire        m_writes = m_req_valid && m_req_we;
  // only writes inside VRAM meet the compare (the core's beyond it are dropped, MEM_DATA's are
  // never issued), so AW + 1 bits are enough
  wire [AW:0] m_vram   = {1'b0, m_req_addr[AW-1:0]};
  wire [AW:0] c_vram   = {1'b0, c_req_addr[AW-1:0]};
  // Whether the window is active is last clock's (m_act_r, below) for the core too (the ULX3S
  // clock, docs/gateware.md "The next cones toward 52 MHz": prot_active is the scanout's equality
  // compare of its read address, a LUT tree, and it led through this compare, the grant and the
  // core's stall logic into the walk). Exact for the same reason as for the memory-access unit: a
  // window starts only when FB_DISPLAY executes, which the executor does only with the core idle
  // and its memory requests done, so no core request meets a window in the clock it starts; one
  // that ends is seen a clock late (a write may wait a clock longer, never less).
  wire        c_act;
  wire        c_prot   = c_act && c_vram >= prot_lo && c_vram < prot_hi;
  // The memory-access unit's write is compared a clock before it is granted (issue 19, 25.125 MHz
  // on the UP5K: the compare on its address, whose low bit is the unit's phase, led through its
  // grant into the executor's FIFO pop in one clock). m_out_r: last clock the window was active
  // and that clock's write outside it. The unit holds a refused request (m_wait_r: this clock's is
  // last clock's), and while the window is active it only shrinks (prot_lo counts up, prot_hi only
  // comes down; a new window starts only from an inactive one), so a write outside it then is
  // outside it now: the registered answer can be late, never early. A write while the window is
  // active waits its first clock (the unit writes at most two words an SPI frame); without a
  // window nothing waits, as before. Whether the window is active is last clock's too (m_act_r:
  // prot_active is the scanout's equality compare of its read address, a LUT tree): a window
  // starts only when FB_DISPLAY executes, which the executor does only after the unit's last write
  // was granted and a clock before it can start another, so no unit write meets a window in the
  // clock it starts (checked in the co-simulation); one that ends is seen a clock late.
  reg         m_wait_r, m_out_r, m_act_r;
  wire        m_in_win = m_vram >= prot_lo && m_vram < prot_hi;
  wire m_block = m_writes && m_act_r && !(m_wait_r && m_out_r);
  assign c_act = m_act_r;
  wire c_block = c_req_we && c_prot;   // (no core request while the unit writes: see pick_c)
  wire c_oor   = c_req_addr[29:AW] != 0;   // beyond VRAM: an upper bit, no comparator
  wire v_oor   = v_req_addr[29:AW] != 0;
  wire v_hold  = v_req_valid && v_oor;       // the scanout and the core wait while it drains the reads

  wire m_ok  = m_req_valid && !m_block && (m_req_we || tags_room);
  wire s_ok  = s_req_valid && tags_room;
  wire c_zero = c_req_valid && c_oor && (c_req_we || (tags_empty && !b_rsp_valid));
  wire c_ok  = c_req_valid && !c_oor && !c_block && (c_req_we || tags_room);

  // choice (independent of b_req_ready)
  wire pick_m = m_ok;
  wire pick_v = !pick_m && v_req_valid && (v_oor ? tags_empty && !b_rsp_valid : tags_room);
  wire pick_s = !pick_v && !v_hold && !pick_m && s_ok && (scan_wait == 4'd15 || !(c_ok || c_zero));
  // The core's grant as if no write of the memory-access unit were blocked: the unit writes only
  // while the core is idle (no core request), so whenever m_block can be 1, c_req_valid is 0 and
  // pick_c is 0 either way. This takes the unit's address compare off c_req_ready, which reaches
  // deep into the core's stall logic (issue 19, 25.125 MHz).
  wire mc_ok  = m_req_valid && (m_req_we || tags_room);
  wire vc_pick = !mc_ok && v_req_valid && (v_oor ? tags_empty && !b_rsp_valid : tags_room);
  wire sc_pick = !vc_pick && !v_hold && !mc_ok && s_ok && (scan_wait == 4'd15 || !(c_ok || c_zero));
  wire pick_c = !vc_pick && !v_hold && !mc_ok && !sc_pick && c_ok;
  wire pick_z = !vc_pick && !v_hold && !mc_ok && !sc_pick && !c_ok && c_zero;

  assign b_req_valid = (pick_v && !v_oor) || pick_m || pick_s || pick_c;
  assign b_req_we    = pick_m ? m_req_we : pick_c ? c_req_we : 1'b0;
  wire [29:0] addr   = pick_m ? m_req_addr : pick_v ? v_req_addr : pick_s ? s_req_addr : c_req_addr;
  assign b_req_addr  = addr[AW-1:0];
  assign b_req_wdata = pick_m ? m_req_wdata : c_req_wdata;
  assign b_req_be    = pick_c ? c_req_be : 4'hF;

  assign v_req_ready = pick_v && (b_req_ready || v_oor);
  assign m_req_ready = pick_m && b_req_ready;
  assign s_req_ready = pick_s && b_req_ready;
  assign c_req_ready = (pick_c && b_req_ready) || pick_z;

  wire granted_read = b_req_valid && b_req_ready && !b_req_we;
  wire [1:0] granted_client = pick_m ? 2'd0 : pick_v ? 2'd3 : pick_s ? 2'd1 : 2'd2;
  wire [1:0] head = tag[tag_rd];

  assign v_rsp_valid = (b_rsp_valid && head == 2'd3) || zero_v;
  assign m_rsp_valid = b_rsp_valid && head == 2'd0;
  assign s_rsp_valid = b_rsp_valid && head == 2'd1;
  assign c_rsp_valid = (b_rsp_valid && head == 2'd2) || (zero_rsp && !zero_v);
  assign rsp_rdata   = zero_rsp ? 32'd0 : b_rsp_rdata;
  assign core_stall  = c_req_valid && !c_req_ready;

  always @(posedge clk) begin
    m_wait_r <= !rst && m_writes && !m_req_ready;
    m_out_r  <= prot_active && !m_in_win;
    m_act_r  <= prot_active;
    c_range_err <= pick_z;
    zero_rsp <= (pick_z && !c_req_we) || (pick_v && v_oor);
    zero_v <= pick_v && v_oor;
    if (rst) begin
      tag_rd <= 0;
      tag_wr <= 0;
      tag_count <= 0;
      scan_wait <= 4'd0;
      zero_rsp <= 1'b0;
      zero_v <= 1'b0;
      c_range_err <= 1'b0;
    end else begin
      if (granted_read) begin
        tag[tag_wr] <= granted_client;
        tag_wr <= tag_wr + 1'b1;
      end
      if (b_rsp_valid) tag_rd <= tag_rd + 1'b1;
      tag_count <= tag_count + (TAG_AW+1)'(granted_read) - (TAG_AW+1)'(b_rsp_valid);
      if (s_req_valid && !s_req_ready) scan_wait <= scan_wait == 4'd15 ? scan_wait : scan_wait + 4'd1;
      else scan_wait <= 4'd0;
    end
  end

`ifndef SYNTHESIS
  // the invariants pick_c, pick_z, c_block and m_block rely on, checked in every co-simulation
  reg [29:0] m_addr_r;
  always @(posedge clk) begin
    m_addr_r <= m_req_addr;
    if (!rst && m_writes && c_req_valid) begin
      $display("mem_arbiter: a write of the memory-access unit while the core requests");
      $stop;
    end
    if (!rst && m_writes && prot_active && !m_act_r) begin
      $display("mem_arbiter: a write of the memory-access unit in the clock a protection window starts");
      $stop;
    end
    if (!rst && c_req_valid && c_req_we && prot_active && !m_act_r) begin
      $display("mem_arbiter: a core write in the clock a protection window starts");
      $stop;
    end
    if (!rst && m_wait_r && m_writes && m_req_addr != m_addr_r) begin
      $display("mem_arbiter: the memory-access unit moved a refused write");
      $stop;
    end
  end
`endif

  wire unused_ok = &{1'b0, addr[29:AW]};
endmodule
