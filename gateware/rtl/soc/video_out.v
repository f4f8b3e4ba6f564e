// Video output of a board (docs/gateware.md "Video out"): the displayed buffer, every refresh.
//
// The scanout reads a frame once per swap (FRAME_CRC, the co-simulation's frame port); a monitor needs
// the displayed buffer 60 times a second. This stage runs on the scanout's display timing (its line
// and clock counters: VESA 640 x 480 at 60 Hz when the scanout's line is H_TOTAL x PIX_DIV clocks, a
// pixel every PIX_DIV core clocks; no counters of its own), follows the swaps the scanout latches
// (frame_start gives the address, format and size at the vertical sync) and fills a two-line
// block-RAM line buffer through its own memory-arbiter client: while one source line is shown, the
// next is read. Pixels are expanded from RGBA8888 / RGB565 / RGBA2222 to 8 bits as
// docs/protocol.md section 6 says and the top OUT_BITS bits leave (4 for the 12-bit DVI Pmod, 8 for
// TMDS). A framebuffer is scaled by 2^SCALE_LOG2 and centred (CENTRE = 1) or placed at the top left
// (CENTRE = 0: no placement adders, the iCEBreaker); what does not fit the screen is cropped,
// and so are pixels beyond the 2^LINE_AW words a line buffer half holds. Words beyond VRAM show as 0
// (the arbiter answers them so).
// The timing is the scanout's (LINE_CLOCKS = H_TOTAL x PIX_DIV), so its vertical sync, where the swap is
// latched, is the end of this stage's last visible line.
//
// PCLK = 1 (the ULX3S): the pixels have their own clock `pclk` (25 MHz, the sink's), independent of the
// core clock `clk` (faster, from the same PLL, but treated as unrelated). Split in two domains:
//   - pclk: the display timing counters (hc, vc: H_TOTAL x V_TOTAL pixels), the line buffer's read
//     port, the pixel pipeline and the pins (pix_en = 1);
//   - clk: the swap's latch (frame_start), the line decisions and the fill through the arbiter client;
//     the scanout's timing is advanced by `tick` (LINE_CLOCKS = H_TOTAL), so hcount / vcount here are
//     pclk's counters a few core clocks late, and frame_start (the swap, VBLANK) falls at the same
//     pixel as before: the end of the last visible line, as pclk shows it;
//   - the line buffer is a block RAM written in clk and read in pclk (a true dual-clock RAM);
//   - crossings: (1) a toggle flipping at every pixel, through three flip-flops into clk: `tick`,
//     one core clock per pixel. Each level of the toggle lasts a pixel (40 ns), longer than a core
//     clock plus a flip-flop's aperture, so some core edge samples it cleanly: no pixel is lost or
//     counted twice; a metastable first stage only moves a tick a clock later. The scanout's
//     counters therefore stay in step with pclk's, both starting at the reset (pclk's reset is clk's
//     `rst` through two flip-flops; the toggle is not reset, so a reset makes no edge, and rst must
//     last at least 12 core clocks so that the ticks still in flight arrive inside it).
//     (2) everything pclk takes from clk (the line's show / half / lead, the picture's x0, x_end and
//     format) is sampled at pclk's line end only. clk changes these only at its own line ends,
//     frame_start included, which come 2-3 core clocks (at least 2 x 19.2 ns) after pclk's line end
//     that caused them through (1): at pclk's sample they have been still for a line less a few core
//     clocks and stay still for at least two more, so all their bits are taken in one consistent state.
//     (3) the line buffer: a half is read in pclk while the other one is written in clk, as in
//     one clock (the write of line n + 2 begins after pclk has left line n, whose half it reuses).
//   pclk's reset comes from rst; nothing goes from pclk to clk but the toggle.
module video_out #(
  parameter VAW        = 15,   // VRAM = 2^VAW 32-bit words
  parameter PIX_DIV    = 1,    // core clocks per pixel: 1 or 2
  parameter SCALE_LOG2 = 1,    // 0: 1:1, 1: every framebuffer pixel 2 x 2 on screen
  parameter LINE_AW    = 8,    // 2^LINE_AW words per line buffer half
  parameter OUT_BITS   = 4,    // bits per colour channel at the pins
  parameter H_ACTIVE   = 640,
  parameter H_FRONT    = 16,
  parameter H_SYNC     = 96,
  parameter H_BACK     = 48,
  parameter V_ACTIVE   = 480,
  parameter V_FRONT    = 10,
  parameter V_SYNC     = 2,
  parameter V_BACK     = 33,
  parameter SYNC_NEG   = 1,    // sync pulses low (640 x 480 at 60 Hz)
  parameter CENTRE     = 1,    // 1: a smaller picture centred; 0: at the top left (no placement adders)
  parameter PCLK       = 0,    // 1: pixels on their own clock pclk (then PIX_DIV is 1), 0: on clk's pix_en
  parameter ICE40      = 0     // 1: the fill's address and count in one logic cell a bit (ice40_load_step)
) (
  input  wire                clk,
  input  wire                rst,
  input  wire                pclk,          // PCLK = 1: the pixel clock (else unused)
  output wire                tick,          // PCLK = 1: in clk, one clock per pixel (the scanout's
                                            // timing advance); 0: 1
  // the scanout's display timing: clock in the line (0 .. H_TOTAL x PIX_DIV - 1) and line
  input  wire [10:0]         hcount,
  input  wire [10:0]         vcount,
  // swaps, as the scanout latches them
  input  wire                frame_start,   // the scanout latched the pending swap (vertical sync)
  input  wire [27:0]         frame_addr,    // its byte address / 16 (valid with frame_start)
  input  wire [1:0]          frame_format,
  input  wire [10:0]         frame_width,
  input  wire [10:0]         frame_height,
  // memory-arbiter client (reads, answered in order; at or beyond 2^VAW words the arbiter answers 0)
  output wire                req_valid,
  input  wire                req_ready,
  output wire [29:0]         req_addr,
  input  wire                rsp_valid,
  input  wire [31:0]         rsp_rdata,
  // to the pins (registered; PCLK = 1: in pclk): pixel clock enable, syncs at their pin level, data
  // enable, colour
  output wire                pix_en,
  output reg                 hsync,
  output reg                 vsync,
  output reg                 de,
  output reg  [OUT_BITS-1:0] red,
  output reg  [OUT_BITS-1:0] green,
  output reg  [OUT_BITS-1:0] blue
);
  localparam H_TOTAL = H_ACTIVE + H_FRONT + H_SYNC + H_BACK;
  localparam V_TOTAL = V_ACTIVE + V_FRONT + V_SYNC + V_BACK;
  localparam S = SCALE_LOG2;

`include "const_compare.vh"

  // --- pixel enable and display timing: the scanout's counters (a pixel in the last clock of each
  // PIX_DIV; PCLK = 1: a pixel a tick) ---
  wire [10:0] hc, vc;
  wire        pix_c;                       // clk: a pixel's clock
  wire        prst;                        // pclk's reset (PCLK = 1)
  generate
    if (PCLK != 0) begin : g_tick
      // crossing (1): the pixel toggle into clk, three flip-flops (two to settle, one to see the edge)
      // (public: the video bench reads them and resolves the first stage's metastability at random)
      reg       ptoggle /*verilator public_flat_rd*/ = 1'b0;
      reg [2:0] tsync /*verilator public_flat_rw*/ = 3'b000;
      always @(posedge pclk) ptoggle <= prst ? ptoggle : !ptoggle;
      always @(posedge clk) tsync <= {tsync[1:0], ptoggle};
      assign tick = tsync[2] != tsync[1];
      assign pix_c = tick;
      assign hc = hcount;
    end else if (PIX_DIV == 2) begin : g_div2
      assign tick = 1'b1;
      assign pix_c = hcount[0];
      assign hc = {1'b0, hcount[10:1]};
    end else begin : g_div1
      assign tick = 1'b1;
      assign pix_c = 1'b1;
      assign hc = hcount;
    end
  endgenerate
  assign vc = vcount;
  wire        h_last = hc == 11'(H_TOTAL - 1);
  wire        line_end = pix_c && h_last;

  // --- the displayed buffer, from frame_start on: where it is and its placement on the screen,
  // centred: [x0, x_end) x [y0, y_end), cropped from the top left when larger (only these are kept,
  // not the buffer's size) ---
  reg         shown;                       // a frame was swapped in since reset
  reg         beyond;                      // it starts beyond VRAM
  reg  [VAW+1:0] base;                     // its first byte
  reg  [1:0]  ppw_l2;                      // log2 pixels per word: RGBA8888 0, RGB565 1, RGBA2222 2
  wire [10:0] x0, y0_m2;                   // constants at the top left (CENTRE = 0)
  reg  [10:0] x_end, y_end_m2;             // y0 and y_end two lines earlier (mod V_TOTAL): the line
                                           // decisions are made two lines ahead, at vc
  reg  [12:0] stride;                      // bytes per framebuffer line
  reg  [LINE_AW:0] n_words;                // words read per line minus 2 (the 2 any lead may add): at
                                           // most a half
  wire [1:0]  ppw_new = frame_format == 2'd0 ? 2'd0 : frame_format == 2'd1 ? 2'd1 : 2'd2;
  wire [11:0] sw = {1'b0, frame_width} << S, sh = {1'b0, frame_height} << S;
  wire [10:0] x0_new, x_end_new, y0_m2_new, y_end_m2_new;
  generate
    if (CENTRE != 0) begin : g_centre
      wire [12:0] x_gap = 13'(H_ACTIVE) - {1'b0, sw}, x_sum = 13'(H_ACTIVE) + {1'b0, sw};
      // y0 - 2 = (V_ACTIVE - sh - 4) / 2 and y_end - 2 = (V_ACTIVE + sh - 4) / 2: the same adders with
      // another constant; y0 = 1 (gap -2 or -1) is V_TOTAL - 1 and y0 = 0 (cropped too) V_TOTAL - 2
      wire [12:0] y_gap4 = 13'(V_ACTIVE - 4) - {1'b0, sh}, y_sum4 = 13'(V_ACTIVE - 4) + {1'b0, sh};
      wire        y_crop = y_gap4[12] && !(&y_gap4[12:2]);   // sh > V_ACTIVE
      reg  [10:0] x0_r, y0_m2_r;
      always @(posedge clk) if (!rst && frame_start) {x0_r, y0_m2_r} <= {x0_new, y0_m2_new};
      assign x0 = x0_r;
      assign y0_m2 = y0_m2_r;
      assign x0_new    = x_gap[12] ? 11'd0 : x_gap[11:1];
      assign x_end_new = x_gap[12] ? 11'(H_ACTIVE) : x_sum[11:1];
      assign y0_m2_new    = !y_gap4[12] ? y_gap4[11:1] : &y_gap4[12:1] ? 11'(V_TOTAL - 1) : 11'(V_TOTAL - 2);
      assign y_end_m2_new = y_crop ? 11'(V_ACTIVE - 2) : y_sum4[11:1];
      wire unused_place = &{1'b0, x_gap[0], y_gap4[0], x_sum[12], x_sum[0], y_sum4[12], y_sum4[0]};
    end else begin : g_top_left
      // [0, min(sw, H_ACTIVE)) x [0, min(sh, V_ACTIVE)): y0 - 2 is V_TOTAL - 2, y_end - 2 is sh - 2
      // (mod V_TOTAL: sh = 0 or 1 gives V_TOTAL - 2 or - 1)
      wire [11:0] sh_m2 = sh - 12'd2;
      assign x0 = 11'd0;
      assign y0_m2 = 11'(V_TOTAL - 2);
      assign x0_new = 11'd0;
      assign y0_m2_new = 11'(V_TOTAL - 2);
      assign x_end_new = ge_const(16'(sw), H_ACTIVE + 1) ? 11'(H_ACTIVE) : sw[10:0];
      assign y_end_m2_new = ge_const(16'(sh), V_ACTIVE + 1) ? 11'(V_ACTIVE - 2) : sh_m2[11] ? 11'(V_TOTAL) + sh_m2[10:0] : sh_m2[10:0];
    end
  endgenerate
  // only the pixels the screen shows are read: at most H_ACTIVE / 2^S of a line
  wire [10:0] w_shown = ge_const(16'(frame_width), (H_ACTIVE >> S) + 1) ? 11'(H_ACTIVE >> S) : frame_width;
  wire [10:0] words_w = w_shown >> ppw_new;
  always @(posedge clk) begin
    if (rst) begin
      shown <= 1'b0;
    end else if (frame_start) begin
      shown <= 1'b1;
      beyond <= frame_addr[27:VAW-2] != 0;
      base <= {frame_addr[VAW-3:0], 4'd0};
      ppw_l2 <= ppw_new;
      x_end <= x_end_new;
      y_end_m2 <= y_end_m2_new;
      stride <= {frame_width, 2'b00} >> ppw_new;
      n_words <= ge_const(16'(words_w), (1 << LINE_AW) - 1) ? (LINE_AW+1)'((1 << LINE_AW) - 2) : words_w[LINE_AW:0];
    end
  end

  // --- line decisions, at the end of each screen line: for the line after next, is it in the picture,
  // does it start a framebuffer line (then read it now), and in which line buffer half is it ---
  reg         f_in, f_rep, f_half;         // the line after next
  reg         n_show, n_half;              // the next line (decided a line earlier)
  reg         l_show, l_half;              // the line being shown
  reg  [1:0]  l_lead;
  wire        f_first = shown && vc == y0_m2 && y0_m2 != y_end_m2;
  wire        f_in_new = f_first || (f_in && vc != y_end_m2);
  wire        f_rep_new = f_first ? 1'b0 : S == 0 ? 1'b0 : !f_rep;   // second screen line of a 2x line
  wire        f_half_new = f_first ? 1'b0 : f_rep_new ? f_half : !f_half;
  wire        fetch_new = f_in_new && !f_rep_new;

  // --- line buffer fill: at the end of screen line n, the framebuffer line of line n + 2 if it is new.
  // The reads must finish within one screen line (iCEBreaker: at most 256 SPRAM words in 800 clocks;
  // ULX3S: 642 SDRAM words at 2 clocks each in 1,600, row misses, refreshes and MEM_* beside); a fill
  // still running when the next one starts is abandoned, and its late answers would land in the new one ---
  // no_rw_check: a half is read only while the other one fills (a fill that overruns its screen line
  // is abandoned, its words are garbage anyway), so a read never meets a write to its address and the
  // block RAM needs no soft bypass for that collision (yosys adds about 75 flip-flops for one otherwise)
  (* no_rw_check *) reg [31:0] lb [0:(2 << LINE_AW) - 1];
  // the next framebuffer line's first byte, and whether it (so every later line) starts beyond VRAM.
  // Outside the picture they are rewound to the buffer's first line at every line end, so the
  // picture's first fetch finds them there too (no choice between them and base, beyond): the
  // picture is always followed by blank lines (V_TOTAL > V_ACTIVE), and the swap's new base, taken
  // at the vertical sync, is rewound at the next line end, before the first line is fetched
  reg  [VAW+1:0] line_byte;
  reg         line_beyond;
  wire [VAW+1:0] byte0 = line_byte;
  wire        beyond0 = line_beyond;
  wire [VAW+2:0] byte_next = {1'b0, byte0} + (VAW+3)'(stride);
  reg  [VAW:0] f_addr;                     // next word to read (>= 2^VAW: the line ran beyond VRAM)
  reg         f_beyond;
  reg  [LINE_AW:0] f_left;                 // words still to read, minus 2: the fill ends at F_DONE = -2
  localparam [LINE_AW:0] F_DONE = ~(LINE_AW+1)'(1);   // (no adder for the + 2 at the latch)
  reg  [LINE_AW-1:0] wr_idx;
  reg         wr_half;
  reg  [1:0]  lead [0:1];                  // pixels before the line's first pixel in its first word
  wire [1:0]  lead0 = ppw_l2 == 2'd2 ? byte0[1:0] : ppw_l2 == 2'd1 ? {1'b0, byte0[1]} : 2'd0;
  // a word beyond VRAM is asked for at an address >= 2^VAW, which the arbiter answers with 0 in order
  // (no zero fill here: no count of reads in flight, no multiplexer on the line buffer's data)
  assign req_valid = f_left != F_DONE;
  assign req_addr  = 30'({f_beyond || f_addr[VAW], f_addr[VAW-1:0]});
  wire        issued = req_valid && req_ready;
  always @(posedge clk) begin
    if (rst) begin
      wr_idx <= {LINE_AW{1'b0}};
      {f_in, f_rep, f_half, n_show, n_half} <= 5'd0;
    end else begin
      if (rsp_valid) begin
        lb[{wr_half, wr_idx}] <= rsp_rdata;
        wr_idx <= wr_idx + 1'b1;
      end
      if (line_end) begin
        {f_in, f_rep, f_half} <= {f_in_new, f_rep_new, f_half_new};
        {n_show, n_half} <= {f_in_new, f_half_new};
        if (fetch_new) begin
          wr_half <= f_half_new;
          wr_idx <= {LINE_AW{1'b0}};
          lead[f_half_new] <= lead0;
          f_beyond <= beyond0;
          line_byte <= byte_next[VAW+1:0];
          line_beyond <= beyond0 || byte_next[VAW+2];
        end else if (!f_in_new) begin
          line_byte <= base;
          line_beyond <= beyond;
        end
      end
    end
  end

  // the fill's next word and words left: a read issued steps them, a fetch's start loads them (and wins)
  wire        f_load = line_end && fetch_new;
  generate
    if (ICE40 != 0) begin : g_fill
      // each bit's next value one SB_LUT4 beside its SB_CARRY, not a sum LUT and a choice LUT
      wire [VAW:0]     fa_next, fa_co;
      wire [LINE_AW:0] fl_next, fl_co;
      ice40_load_step #(.W(VAW + 1), .DOWN(0)) u_fa (.ld(f_load), .d({1'b0, byte0[VAW+1:2]}), .q(f_addr), .q_next(fa_next), .co(fa_co));
      ice40_load_step #(.W(LINE_AW + 1), .DOWN(1)) u_fl (.ld(f_load), .d(n_words), .q(f_left), .q_next(fl_next), .co(fl_co));
      always @(posedge clk) begin
        if (!rst && (issued || f_load)) f_addr <= fa_next;
        if (rst) f_left <= F_DONE;
        else if (issued || f_load) f_left <= fl_next;
      end
      wire unused_fill = &{1'b0, fa_co, fl_co};
    end else begin : g_fill
      always @(posedge clk) begin
        if (rst) begin
          f_left <= F_DONE;
        end else begin
          if (issued) begin
            f_addr <= f_addr + 1'b1;
            f_left <= f_left - 1'b1;
          end
          if (f_load) begin
            f_addr <= {1'b0, byte0[VAW+1:2]};
            f_left <= n_words;
          end
        end
      end
    end
  endgenerate

  // --- the display's clock, reset, pixel enable and timing: clk's (PCLK = 0) or pclk's own, with the
  // values it takes from clk sampled at its line end (PCLK = 1, crossing (2)) ---
  wire        dclk, drst, den;
  wire [10:0] dhc, dvc;
  wire [10:0] dx0, dx_end;
  wire [1:0]  dppw;
  wire        d_line_end = den && dhc == 11'(H_TOTAL - 1);
  generate
    if (PCLK != 0) begin : g_pclk
      reg  [1:0]  prst_sync = 2'b11;
      reg  [10:0] phc /*verilator public_flat_rd*/, pvc;
      reg  [10:0] px0, px_end;
      reg  [1:0]  pppw;
      // rst into pclk (it is held long enough for two flip-flops to pass it)
      always @(posedge pclk) prst_sync <= {prst_sync[0], rst};
      assign prst = prst_sync[1];
      always @(posedge pclk) begin
        if (prst) begin
          {phc, pvc} <= 22'd0;
        end else if (d_line_end) begin
          phc <= 11'd0;
          pvc <= pvc == 11'(V_TOTAL - 1) ? 11'd0 : pvc + 11'd1;
        end else begin
          phc <= phc + 11'd1;
        end
        if (d_line_end) {px0, px_end, pppw} <= {x0, x_end, ppw_l2};
      end
      assign {dclk, drst, den, dhc, dvc} = {pclk, prst, 1'b1, phc, pvc};
      assign {dx0, dx_end, dppw} = {px0, px_end, pppw};
      assign pix_en = 1'b1;
    end else begin : g_one
      assign prst = rst;
      assign {dclk, drst, den, dhc, dvc} = {clk, rst, pix_c, hc, vc};
      wire unused_pclk = &{1'b0, pclk, prst};
      assign {dx0, dx_end, dppw} = {x0, x_end, ppw_l2};
      assign pix_en = pix_c;
    end
  endgenerate
  // the line being shown, from the decisions a line earlier (at the display's line end)
  always @(posedge dclk) begin
    if (drst) begin
      l_show <= 1'b0;
    end else if (d_line_end) begin
      {l_show, l_half} <= {n_show, n_half};
      l_lead <= lead[n_half];
    end
  end

  // --- display: a two-stage pixel pipeline ---
  // the pixel's place in the framebuffer line: from dx0 on, a pixel every 2^S screen pixels, a word
  // every 2^dppw pixels (the first word from the line's lead on)
  reg         x_in_r, rep_r;
  reg  [1:0]  sub_r;
  reg  [LINE_AW:0] widx_r;                 // the top bit: beyond the line buffer half (black)
  wire        x_start = dhc == dx0;
  wire        x_in = dhc != dx_end && (x_start || x_in_r);
  wire        rep = x_start ? 1'b0 : rep_r;
  wire [1:0]  sub = x_start ? l_lead : sub_r;
  wire [LINE_AW:0] widx = x_start ? {(LINE_AW+1){1'b0}} : widx_r;
  wire        advance = S == 0 || rep;
  wire        word_end = sub == (2'd1 << dppw) - 2'd1;
  always @(posedge dclk) begin
    if (den) begin
      x_in_r <= x_in;
      rep_r <= !rep;
      sub_r <= advance ? (word_end ? 2'd0 : sub + 2'd1) : sub;
      widx_r <= advance && word_end && !widx[LINE_AW] ? widx + 1'b1 : widx;
    end
  end
  // visible part and sync pulses of the line and the frame, decoded from dhc / dvc (no flag registers)
  wire        active = !ge_const(16'(dhc), H_ACTIVE) && !ge_const(16'(dvc), V_ACTIVE);
  wire        hs0 = ge_const(16'(dhc), H_ACTIVE + H_FRONT) && !ge_const(16'(dhc), H_ACTIVE + H_FRONT + H_SYNC);
  wire        vs0 = ge_const(16'(dvc), V_ACTIVE + V_FRONT) && !ge_const(16'(dvc), V_ACTIVE + V_FRONT + V_SYNC);
  reg  [31:0] word1;
  reg         on1, de1, hs1, vs1;
  reg  [1:0]  sub1;
  always @(posedge dclk) begin
    if (den) begin
      word1 <= lb[{l_half, widx[LINE_AW-1:0]}];
      sub1 <= sub;
    end
    if (drst) begin
      {on1, de1, hs1, vs1} <= 4'd0;
    end else if (den) begin
      on1 <= active && l_show && x_in && !widx[LINE_AW];
      de1 <= active;
      hs1 <= hs0;
      vs1 <= vs0;
    end
  end
  // expansion to 8 bits (docs/protocol.md section 6); big-endian: the first pixel is the high part
  wire [15:0] half = sub1[0] ? word1[15:0] : word1[31:16];
  reg  [7:0]  byte_px;
  always @* begin
    case (sub1)
      2'd0: byte_px = word1[31:24];
      2'd1: byte_px = word1[23:16];
      2'd2: byte_px = word1[15:8];
      default: byte_px = word1[7:0];
    endcase
  end
  wire [7:0] r8 = dppw == 2'd0 ? word1[31:24] : dppw == 2'd1 ? {half[15:11], half[15:13]} : {4{byte_px[7:6]}};
  wire [7:0] g8 = dppw == 2'd0 ? word1[23:16] : dppw == 2'd1 ? {half[10:5], half[10:9]} : {4{byte_px[5:4]}};
  wire [7:0] b8 = dppw == 2'd0 ? word1[15:8] : dppw == 2'd1 ? {half[4:0], half[4:2]} : {4{byte_px[3:2]}};
  // the bits below OUT_BITS and the alpha of RGBA2222 do not leave; rows past the line parity are
  // the fetch side's
  wire unused_ok = &{1'b0, byte_px[1:0], r8, g8, b8, x0_new, y0_m2_new};
  always @(posedge dclk) begin
    if (drst) begin
      {hsync, vsync} <= SYNC_NEG != 0 ? 2'b11 : 2'b00;
      de <= 1'b0;
      {red, green, blue} <= {(3 * OUT_BITS){1'b0}};
    end else if (den) begin
      hsync <= hs1 ^ (SYNC_NEG != 0);
      vsync <= vs1 ^ (SYNC_NEG != 0);
      de <= de1;
      red   <= on1 ? r8[7 -: OUT_BITS] : {OUT_BITS{1'b0}};
      green <= on1 ? g8[7 -: OUT_BITS] : {OUT_BITS{1'b0}};
      blue  <= on1 ? b8[7 -: OUT_BITS] : {OUT_BITS{1'b0}};
    end
  end

endmodule
