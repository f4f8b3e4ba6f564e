// Scanout (docs/protocol.md section 12): display timing, the swap at vertical sync, FRAME_CRC,
// STATUS.VBLANK / SWAP_PENDING and the frame counter.
//
// An executed FB_DISPLAY write asks for a swap with its address and the FB_FORMAT of that moment;
// the buffer length W x H x bpp is computed (12 clocks; the product on a multiplier, a DSP) and the
// swap becomes pending. At the next vertical sync (start of vertical blanking) the pending swap is
// latched and the frame is read, in address order, into the CRC-32 and out of the frame port (the
// video output of a board, and what the co-simulation captures). When its last byte has been read
// the frame is "scanned out": FRAME_COUNT advances, FRAME_CRC = {frame number, CRC} and SWAP_PENDING
// clears, so a host that sees SWAP_PENDING = 0 reads the CRC of that frame. Bytes beyond VRAM read as 0 and
// raise ERR_MEM_RANGE when the swap is requested (the simulator raises it when FB_DISPLAY executes).
// Until the reader has passed them, the not-yet-read words of the pending frame are write-protected
// (mem_arbiter), so the frame is the buffer as it was when FB_DISPLAY executed.
// Timing is in core clocks: LINE_CLOCKS per line, V_ACTIVE visible lines of V_TOTAL. A board whose
// pixels run on their own clock (ULX3S) advances it by `tick`, one core clock per pixel-clock edge
// (video_out's synchronised pixel tick), and LINE_CLOCKS is then the line's pixels; elsewhere tick = 1.
module scanout #(
  parameter        VAW = 15,              // VRAM size = 2^VAW 32-bit words
  parameter        LINE_CLOCKS = 800,
  parameter        V_ACTIVE = 480,
  parameter        V_TOTAL = 525,
  parameter        CRC_BYTES = 1,         // bytes folded into the CRC per clock: 1 or 4
  parameter        BUF_WORDS = 2,         // read-ahead words (2 or 4)
  parameter        BYTES_W = 24,          // bits of the largest frame's W x H x 4 (the sizes FB_FORMAT can hold)
  parameter        DSP = 0,               // 1: FRAME_COUNT and the read address in an SB_MAC16 (up5k)
  parameter        CRC_ROM = 0,           // 1 (CRC_BYTES = 1): the byte fold's table in block RAM (up5k,
                                          // docs/gateware.md up5k-cells); the frame's end a clock later
  parameter        ICE40 = 0              // 1 (CRC_BYTES = 1): bytes_left's next value in one cell a bit
) (
  input  wire        clk,
  input  wire        rst,
  input  wire        soft_reset,   // RESET: the pending swap and a frame being read are dropped, counters 0
  input  wire        tick,         // the display timing advances (1: every core clock)
  // swap request from the executor
  input  wire        swap_req,
  input  wire [27:0] swap_addr,    // byte address / 16
  input  wire [1:0]  swap_format,
  input  wire [10:0] swap_width,
  input  wire [10:0] swap_height,
  output wire        swap_ready,   // no swap being computed, pending or read
  output wire        swap_pending, // STATUS.SWAP_PENDING
  output reg         err_range,
  // timing
  output reg         vblank,
  output wire        vsync,        // one clock at the start of vertical blanking
  output wire [10:0] hcount,       // clock in the line, 0 .. LINE_CLOCKS - 1 (a board's video output
  output wire [10:0] vcount,       // runs on these), line 0 .. V_TOTAL - 1
  // memory (reads, in VRAM only)
  output wire        req_valid,
  input  wire        req_ready,
  output wire [29:0] req_addr,
  input  wire        rsp_valid,
  input  wire [31:0] rsp_rdata,
  // write protection of the frame not yet read: words [prot_lo, prot_hi) of VRAM (both at most
  // 2^VAW: only writes inside VRAM are compared)
  output wire        prot_active,
  output wire [VAW:0] prot_lo,
  output wire [VAW:0] prot_hi,
  // registers
  output wire [15:0] frame_count,
  output wire [47:0] frame_crc,
  // the frame's bytes, in order: the top frame_nbytes bytes of frame_word (combinational)
  output wire        frame_valid,
  output wire [31:0] frame_word,
  output wire [2:0]  frame_nbytes,
  output wire        frame_start,  // the clock a frame's reading starts (frame_format/width/height valid)
  output wire        frame_end,    // the clock of its last byte
  output wire [27:0] frame_addr,   // with frame_start: the frame's byte address / 16 (beyond VRAM: the bits
                                   // from VRAM's size up all ones, the rest the address's)
  output reg  [1:0]  frame_format,
  output reg  [10:0] frame_width,
  output reg  [10:0] frame_height
);
  // --- display timing ---
  wire line_end = tick && hcount == LINE_CLOCKS[10:0] - 11'd1;
  wire frame_last = vcount == V_TOTAL[10:0] - 11'd1;
  assign vsync  = line_end && vcount == V_ACTIVE[10:0] - 11'd1;
  // vblank = vcount >= V_ACTIVE, as a flag turned at the two edges (no magnitude comparator)
  // the counters (LINE_CLOCKS and V_TOTAL are at most 2^11): dsp_counter's logic form; the UP5K's
  // SB_MAC16s hold counters worth more cells each (docs/gateware.md, fit-soc3 and the merge after it)
  wire [15:0] hcount16, vcount16;
  dsp_counter #(.DSP(0), .WIDE(0)) u_display (
    .clk(clk), .ld_top(rst || line_end), .d_top(16'd0), .inc_top(tick),
    .ld_bot(rst || (line_end && frame_last)), .d_bot(16'd0), .inc_bot(line_end), .q_top(hcount16), .q_bot(vcount16));
  assign hcount = hcount16[10:0];
  assign vcount = vcount16[10:0];
  wire unused_count = &{1'b0, hcount16[15:11], vcount16[15:11]};
  always @(posedge clk) begin
    if (rst) begin
      vblank <= 1'b0;
    end else begin
      if (vsync) vblank <= 1'b1;
      else if (line_end && frame_last) vblank <= 1'b0;
    end
  end

  // --- swap request: length, end and range ---
  reg        computing, pending, reading;
  reg [3:0]  mul_step;
  reg [BYTES_W-1:0] mul_acc;   // width x height x bytes per pixel
  // Addresses in VRAM words: the reader stops at the end of VRAM (what lies beyond reads as 0), so
  // the next word to read needs VAW + 1 bits, plus `above` for a frame starting beyond VRAM.
  reg [VAW:0] rd_addr;         // next word to read (the frame's first word until reading starts)
  reg         above;           // the frame starts beyond VRAM
  reg [VAW:0] end_vram;        // min(first word after the frame, 2^VAW)
  localparam [VAW:0] VRAM_END = {1'b1, {VAW{1'b0}}};
  reg  [BYTES_W-1:0] bytes_left; // bytes still to fold
  reg [31:0] crc_value;
  wire       frame_done;       // the frame's last byte is folded
  wire       end_now;          // its end takes effect: FRAME_COUNT, FRAME_CRC and SWAP_PENDING (g_fold)
  wire [31:0] crc_final;       // the frame's CRC (not yet complemented) in end_now's clock
  wire       issued;           // a read of the frame was accepted: rd_addr advances
  // FRAME_COUNT, and rd_addr in the bottom half (VAW < 16; the ecp5 profile's is its own register).
  // rd_addr loads and counts also in a reset's clock: its value matters only while a swap is
  // computed, pending or read, each of which a later swap_req starts with a load.
  wire [15:0] rd_addr16;
  dsp_counter #(.DSP(DSP), .WIDE(0)) u_frame_count (
    .clk(clk), .ld_top(rst || soft_reset), .d_top(16'd0), .inc_top(end_now),
    .ld_bot(swap_req), .d_bot(16'({1'b0, swap_addr[VAW-3:0], 2'b00})), .inc_bot(issued),
    .q_top(frame_count), .q_bot(rd_addr16));
  generate
    if (VAW < 16) begin : g_rd_dsp
      always @* rd_addr = rd_addr16[VAW:0];
      wire unused_rd = &{1'b0, rd_addr16};
    end else begin : g_rd_logic
      reg [VAW:0] rd_next;
      always @(posedge clk) begin
        if (swap_req) rd_next <= {1'b0, swap_addr[VAW-3:0], 2'b00};
        else if (issued) rd_next <= rd_next + 1'b1;
      end
      always @* rd_addr = rd_next;
      wire unused_rd = &{1'b0, rd_addr16};
    end
  endgenerate
  assign swap_ready   = !computing && !pending && !reading;
  assign swap_pending = computing || pending || reading;
  assign frame_crc    = {frame_count, crc_value};  // the frame number is FRAME_COUNT itself

  // bytes of the frame, W x H x bpp (into bytes_left one clock before the end is computed); its
  // words are ceil(bytes / 4), the rounding the carry into the end's adder below. The bytes per
  // pixel scale the height on the multiplier's input (13 bits), not the product (BYTES_W bits)
  wire [BYTES_W-1:0] bytes = mul_acc;
  wire [12:0] height_bpp = frame_format == 2'd0 ? {frame_height, 2'b00} : frame_format == 2'd1 ? {1'b0, frame_height, 1'b0}
                         : {2'b00, frame_height};

  // --- frame reading ---
  localparam       BAW = BUF_WORDS == 4 ? 2 : 1;
  localparam [2:0] BUFW = BUF_WORDS[2:0];
  reg  [2:0]  outstanding;     // reads issued, answer not yet seen
  reg  [2:0]  drop;            // answers to ignore after a RESET
  reg  [31:0] buf_word [0:BUF_WORDS-1];
  reg  [BAW-1:0] buf_rd, buf_wr;
  reg  [2:0]  buf_count;
  reg  [1:0]  byte_in_word;    // CRC_BYTES = 1: next byte of the head word

  // words of the frame still to read from VRAM (the rest, beyond VRAM, reads as 0). Used only while
  // reading, when end_vram is the frame's and rd_addr counts up from its first word (at most end_vram,
  // both inside VRAM unless `above`) and stops there: an equality, not a magnitude comparator
  wire in_frame  = !above && rd_addr != end_vram;
  assign req_valid   = reading && in_frame && outstanding + buf_count < BUFW;
  assign req_addr    = 30'(rd_addr[VAW-1:0]);
  // a frame starting beyond VRAM protects nothing (no multiplexer on prot_lo for it); while the end
  // is being computed, everything from the frame's start up is protected: end_vram is VRAM_END from
  // the swap request until the end is known (no multiplexer on prot_hi)
  assign prot_active = !above && (computing || pending || (reading && in_frame));
  assign prot_lo     = rd_addr;
  assign prot_hi     = end_vram;
  // the frame's end in words, rd_addr + ceil(bytes / 4), from its start inside VRAM (beyond it:
  // above): one adder, the rounding as its carry in (bit 0 of the doubled operands)
  localparam integer EW = (VAW + 2 > BYTES_W - 1) ? VAW + 2 : BYTES_W - 1;
  wire [EW:0]   end_x2 = {EW'(rd_addr), 1'b1} + {EW'(bytes_left[BYTES_W-1:2]), bytes_left[1:0] != 2'b00};
  wire [EW-1:0] end_in = end_x2[EW:1];
  wire [23:0]   product = frame_width * height_bpp;
  wire          unused_ok = &{1'b0, end_x2[0], product};
  // end_in > 2^VAW: a bit above VRAM's, or VRAM's own bit and any below it
  wire          end_beyond = above || end_in[EW-1:VAW+1] != 0 || (end_in[VAW] && end_in[VAW-1:0] != 0);

  // the head word: from memory while there are answers; zeros once the reader left VRAM
  wire        mem_done  = !in_frame && outstanding == 3'd0 && buf_count == 3'd0;
  wire        have_word = buf_count != 3'd0 || mem_done;
  wire [31:0] head_word;        // the head buffer word, or 0 (g_head below)

  function automatic [31:0] crc_byte(input [31:0] c, input [7:0] b);
    integer i;
    reg [31:0] x;
    begin
      x = c ^ {24'd0, b};
      for (i = 0; i < 8; i = i + 1) x = x[0] ? ({1'b0, x[31:1]} ^ 32'hEDB88320) : {1'b0, x[31:1]};
      crc_byte = x;
    end
  endfunction

  reg  [2:0]  n_fold;
  // CRC_BYTES = 4: min(4, bytes_left), a flip-flop loaded with bytes_left (g_bytes_left), so that
  // the four byte folds' choices start at a register, not at bytes_left's 4-or-more test (the
  // ULX3S estimate's worst cone, bytes_left -> crc_final, 23 levels: docs/gateware.md up5k-clip)
  reg  [2:0]  n_fold4;
  reg  [31:0] fold_word;       // bytes to fold, first one in [31:24]
  reg         word_done;
  always @* begin
    if (CRC_BYTES == 4) begin
      fold_word = head_word;
      n_fold = n_fold4;
      word_done = 1'b1;
    end else begin
      case (byte_in_word)
        2'd0: fold_word = {head_word[31:24], 24'd0};
        2'd1: fold_word = {head_word[23:16], 24'd0};
        2'd2: fold_word = {head_word[15:8], 24'd0};
        default: fold_word = {head_word[7:0], 24'd0};
      endcase
      n_fold = 3'd1;
      word_done = byte_in_word == 2'd3 || bytes_left == BYTES_W'(1);
    end
  end
  wire folding = reading && have_word && bytes_left != 0;
  wire start   = vsync && pending;   // reading starts (the CRC from all ones)
  // bytes_left: loaded one clock before the end is computed, counted down by the bytes folded
  wire bl_load = !(rst || soft_reset) && computing && !swap_req && mul_step == 4'd10;
  wire bl_step = !(rst || soft_reset) && !(vsync && pending) && folding;
  generate
    if (ICE40 != 0 && CRC_BYTES == 1) begin : g_bytes_left
      // a byte a fold: the load and the decrement in ice40_load_step's cells. Its choice drives all the
      // carries, so it is bl_load without the late terms (RESET's decode, the executor's swap_req):
      // computing and reading never overlap, so it is 0 whenever bl_step counts
      wire               bl_choose = computing && mul_step == 4'd10;
      wire [BYTES_W-1:0] bl_next, bl_co;
      ice40_load_step #(.W(BYTES_W), .DOWN(1)) u_bl (.ld(bl_choose), .d(bytes), .q(bytes_left), .q_next(bl_next), .co(bl_co));
      always @(posedge clk) if (bl_load || bl_step) bytes_left <= bl_next;
      wire unused_bl = &{1'b0, bl_co};
      always @* n_fold4 = 3'd1;   // CRC_BYTES = 4 only
    end else begin : g_bytes_left
      wire [BYTES_W-1:0] bl_next = bl_load ? bytes : bytes_left - BYTES_W'(n_fold);
      always @(posedge clk) begin
        if (bl_load || bl_step) bytes_left <= bl_next;
        // n_fold4 changes with bytes_left only: min(4, bytes_left) in every clock after the first
        // load (a frame is folded only after its swap's computation loaded bytes_left)
        if (bl_load || bl_step) n_fold4 <= bl_next >= BYTES_W'(4) ? 3'd4 : bl_next[2:0];
      end
    end
  endgenerate
  wire popping = folding && word_done && buf_count != 3'd0;
  assign issued = req_valid && req_ready;
  wire take    = rsp_valid && drop == 3'd0;
  generate
    if (CRC_BYTES == 4) begin : g_head
      // ecp5: the head word is a register loaded a clock ahead (the word after the head while one is
      // popped, the answer arriving into an emptied buffer, else 0), so the 4-byte CRC fold starts at a
      // register, not at the buffer's LUT-RAM read (docs/gateware.md, branch ecp5-scan). The same value
      // as the read below every clock: writes never land on the head's slot while the buffer holds it
      wire [BAW-1:0] buf_rd1 = buf_rd + 1'b1;
      wire [2:0]     kept    = buf_count - {2'd0, popping};
      reg  [31:0]    head_q;
      always @(posedge clk) begin
        if (rst || soft_reset) head_q <= 32'd0;
        else if (kept == 3'd0) head_q <= take ? rsp_rdata : 32'd0;
        else if (popping) head_q <= buf_word[buf_rd1];
      end
      assign head_word = head_q;
    end else begin : g_head
      assign head_word = buf_count != 3'd0 ? buf_word[buf_rd] : 32'd0;
    end
  endgenerate
  wire last    = folding && bytes_left == BYTES_W'(n_fold);
  assign frame_valid  = folding;
  assign frame_word   = fold_word;
  assign frame_nbytes = n_fold;
  assign frame_start  = vsync && pending;
  // until reading starts, rd_addr is the frame's first word (and above says it lies beyond VRAM):
  // beyond VRAM the bits above VRAM's are all ones and the rest are the wrapped address's (a
  // video output shows such a frame black whatever its low bits say: no 13-bit choice here)
  assign frame_addr   = {{(30 - VAW){above}}, rd_addr[VAW-1:2]};
  assign frame_end    = last;
  assign frame_done   = folding && last;

  // --- the CRC ---
  generate
    if (CRC_ROM == 0) begin : g_fold
      // in logic: the fold of n_fold bytes in the clock they are read
      reg  [31:0] crc, crc_next;
      always @* begin
        crc_next = crc;
        if (n_fold >= 3'd1) crc_next = crc_byte(crc_next, fold_word[31:24]);
        if (CRC_BYTES == 4) begin
          if (n_fold >= 3'd2) crc_next = crc_byte(crc_next, fold_word[23:16]);
          if (n_fold >= 3'd3) crc_next = crc_byte(crc_next, fold_word[15:8]);
          if (n_fold >= 3'd4) crc_next = crc_byte(crc_next, fold_word[7:0]);
        end
      end
      always @(posedge clk) begin
        if (!(rst || soft_reset)) begin
          if (start) crc <= 32'hFFFFFFFF;
          else if (folding) crc <= crc_next;
        end
      end
      assign end_now = frame_done;
      assign crc_final = crc_next;
    end else begin : g_fold
      // The byte fold crc_byte(c, b) = (c >> 8) ^ T[(c ^ b) & 0xFF], the table T in a block RAM (256 x 32:
      // two SB_RAM40_4K) instead of the 8-step XOR network on 32 bits (about 100 LUT4). The RAM's read
      // is registered, so the CRC is kept as acc ^ tab_q, tab_q = T[i] read with the index i of the byte
      // folded last: folding b takes acc <= (acc ^ tab_q) >> 8 and reads T[(acc ^ tab_q)[7:0] ^ b]. A
      // frame starts with acc all ones and tab_q = T[0] = 0. The last byte's CRC is known a clock after
      // its fold, so the frame's end (FRAME_COUNT, FRAME_CRC, SWAP_PENDING clearing) takes effect a
      // clock after frame_done, all three together; nothing else changes (no read is issued and no
      // byte folded in that clock: the frame's words are all read, bytes_left is 0)
      reg  [31:0] crc_tab [0:255];
      integer     t;
      initial for (t = 0; t < 256; t = t + 1) crc_tab[t] = crc_byte(32'd0, 8'(t));
      reg  [31:0] acc, tab_q;
      reg         done_q;
      wire [31:0] crc_now = acc ^ tab_q;
      wire [7:0]  tab_idx = start ? 8'd0 : crc_now[7:0] ^ fold_word[31:24];
      always @(posedge clk) begin
        if (start || folding) tab_q <= crc_tab[tab_idx];
        if (start) acc <= 32'hFFFFFFFF;
        else if (folding) acc <= {8'd0, crc_now[31:8]};
        done_q <= frame_done && !(rst || soft_reset);
      end
      assign end_now = done_q;
      assign crc_final = crc_now;
    end
  endgenerate

  always @(posedge clk) begin
    err_range <= 1'b0;
    if (rst || soft_reset) begin
      computing <= 1'b0;
      pending <= 1'b0;
      reading <= 1'b0;
      crc_value <= 32'd0;
      buf_rd <= {BAW{1'b0}};
      buf_wr <= {BAW{1'b0}};
      buf_count <= 3'd0;
      byte_in_word <= 2'd0;
      // answers to reads in flight still arrive after a RESET
      drop <= rst ? 3'd0 : drop - {2'd0, rsp_valid && drop != 3'd0} + outstanding - {2'd0, take};
      outstanding <= 3'd0;
    end else begin
      if (rsp_valid && drop != 3'd0) drop <= drop - 3'd1;
      outstanding <= outstanding + {2'd0, issued} - {2'd0, take};
      if (take) begin
        buf_word[buf_wr] <= rsp_rdata;
        buf_wr <= buf_wr + 1'b1;
      end
      buf_count <= buf_count + {2'd0, take} - {2'd0, popping};
      if (popping) buf_rd <= buf_rd + 1'b1;

      if (swap_req) begin
        computing <= 1'b1;
        end_vram <= VRAM_END;
        above <= swap_addr[27:VAW-2] != {(30 - VAW){1'b0}};
        frame_format <= swap_format;
        frame_width <= swap_width;
        frame_height <= swap_height;
        mul_step <= 4'd0;
      end else if (computing) begin
        // mul_acc = width x height, on a multiplier; the swap keeps its 12 clocks
        // (no frame is being read while a swap is computed, so bytes_left is free)
        if (mul_step != 4'd11) begin
          mul_acc <= product[BYTES_W-1:0];
          mul_step <= mul_step + 4'd1;
        end else begin
          computing <= 1'b0;
          pending <= 1'b1;
          end_vram <= end_beyond ? VRAM_END : end_in[VAW:0];
          if (end_beyond) err_range <= 1'b1;
        end
      end

      if (start) begin
        pending <= 1'b0;
        reading <= 1'b1;
        byte_in_word <= 2'd0;
      end else if (folding) begin
        byte_in_word <= word_done ? 2'd0 : byte_in_word + 2'd1;
      end
      if (end_now) begin
        reading <= 1'b0;
        crc_value <= ~crc_final;
      end
    end
  end
endmodule
