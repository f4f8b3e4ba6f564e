// Command executor (docs/protocol.md sections 5, 7, 12 and 13): takes the oldest released entry of
// the command FIFO, validates it (reserved bits -> enumerations -> register ranges -> features the
// profile lacks, in that order), applies it to the render state and primitive assembly, and starts
// what it commands:
//   - VERTEX forms a vertex from the latched COLOR and TEXCOORD; a completed triangle (LIST, STRIP,
//     FAN) becomes one TRIANGLE command to the render core with the render state of that moment;
//   - CLEAR / CLEAR_Z become core commands; FB_DISPLAY a swap request to the scanout (after the core
//     has written everything and the previous swap has been scanned out);
//   - MEM_ADDR / MEM_DATA become operations of the memory-access unit (after the core is idle);
//   - FENCE records its ID when everything before it has completed.
// Vertices reach the core in one of two ways (VPORT): as three flat 184-bit buses held in
// flip-flops (cmd_v0..2, the parallel setup of the ecp5 profile), or through a read port
// (VPORT = 1, up5k): the executor keeps three vertex slots in block RAM, three 32-bit words each
// ({Y, X}, Z, COLOR; no texture coordinates), and the core reads word w of triangle vertex k as
// vp_addr = {k, w}, vp_data a clock later. A VERTEX writes its three words (three clocks) before
// it executes; STRIP and FAN rotate slot numbers instead of copying vertices. "Vertex" 3 is
// CLEAR_COLOR (word 0) and CLEAR_DEPTH (word 1), which a clear reads the same way: written when
// they execute, and with their reset values in the two clocks after a reset (nothing executes
// before); cmd_clear_color / cmd_clear_depth are then 0.
// Plain register writes take one clock each. Read-write registers are also written, validated, to
// the register file's shadow RAM when they execute (a clock later if the SPI side is writing it); a
// kicking VERTEX writes it first and then offers the triangle to the core, so cmd_valid, once high,
// stays high until cmd_ready.
module command_exec #(
  parameter [7:0] FEATURES = 8'h3F,
  parameter       MAX_WIDTH = 1024,
  parameter       MAX_HEIGHT = 1024,
  parameter       VRAM_KIB = 32768,
  parameter       DEPTH = 1,          // CAPS2.FEATURES2 bit 0; 0: Z_TEST/Z_WRITE/CLEAR_Z refused (1.4)
  parameter       VPORT = 0,          // 1: vertices through the read port, cmd_v0..2 are 0
  parameter       IDX5 = 0            // 1: the entry's index from its five low bits (up5k, below)
) (
  input  wire         clk,
  input  wire         rst,           // power-on or RESET
  // command FIFO
  input  wire         in_valid,
  input  wire [70:0]  in_entry,
  output wire         in_pop,
  // shadow RAM of the register file
  output wire         sh_wr_req,
  output wire [4:0]   sh_wr_idx,
  output wire [63:0]  sh_wr_data,
  input  wire         sh_wr_ack,
  output wire [4:0]   sh_rd_idx,     // VPORT: COLOR, read from the shadow RAM (no copy here)
  input  wire [63:0]  sh_rd_data,
  input  wire         sh_rd_valid,
  output reg  [6:0]   err_set,       // {.., BAD_VALUE (bit 4), RESERVED_BITS (bit 3), ..}
  input  wire         core_drain,
  // render core command port (docs: soc <-> core interface)
  output wire         cmd_valid,
  input  wire         cmd_ready,
  output wire [1:0]   cmd_op,
  output wire [31:0]  cmd_tri_mode,
  output wire [27:0]  cmd_tex_base,
  output wire [17:0]  cmd_tex_fmt,
  output wire [43:0]  cmd_scissor,
  output wire [27:0]  cmd_fb_draw,
  output wire [27:0]  cmd_fb_z,
  output wire [1:0]   cmd_fb_format,
  output wire [10:0]  cmd_fb_width,
  output wire [10:0]  cmd_fb_height,
  output wire [31:0]  cmd_clear_color,
  output wire [23:0]  cmd_clear_depth,
  output wire [183:0] cmd_v0,
  output wire [183:0] cmd_v1,
  output wire [183:0] cmd_v2,
  input  wire [3:0]   vp_addr,       // {triangle vertex 0-2, word 0-2} (VPORT = 1)
  output reg  [31:0]  vp_data,       // the word, a clock later
  input  wire         core_idle,
  // memory-access unit: the operation's data stays in the FIFO head until mem_op_ack
  output wire         mem_set_addr,  // MEM_ADDR offered
  output wire         mem_addr_head, // the FIFO's head is a MEM_ADDR, offered or not (no readiness terms)
  output wire         mem_write,     // MEM_DATA write offered
  output wire [63:0]  mem_op_data,
  input  wire         mem_op_ack,    // taken (MEM_ADDR: at once; MEM_DATA: both words written)
  input  wire         mem_idle,      // no MEM_ADDR / MEM_DATA operation of the executor in progress
  // scanout
  output wire         swap_req,      // FB_DISPLAY executes
  output wire [27:0]  swap_addr,
  input  wire         swap_ready,    // no swap pending or being scanned
  output wire         waiting_vsync, // an FB_DISPLAY waits for the previous swap's scan
  output wire         executed       // one clock per FIFO entry executed (timing-model counter C)
);
`include "spigpu_regs.vh"
`include "const_compare.vh"

  // --- validation (section 5) ---
  // Only queued registers reach the FIFO (COLOR .. FB_FORMAT 0x00-0x0F, FENCE 0x18, MEM_ADDR 0x70,
  // MEM_DATA 0x71), and their five low index bits tell them apart (0x70 / 0x71 are 0x10 / 0x11 there,
  // no other queued index has bit 4 without bit 3). IDX5 = 1 rebuilds the index from those five, so
  // the validation's decodes (reserved masks, enumerations, clamps, the command decodes) are
  // functions of five bits instead of seven (docs/gateware.md up5k-cells); the same value for
  // every entry the FIFO can hold
  wire        idx_mem = in_entry[68] && !in_entry[67];
  wire [6:0]  idx = IDX5 != 0 ? {idx_mem, idx_mem, in_entry[68:64]} : in_entry[70:64];
  wire [63:0] raw = in_entry[63:0];
  wire [63:0] rsv = reg_reserved(idx);
  wire        rsv_err = (raw & rsv) != 64'h0;
  wire [64:0] enum_fix = reg_enum_fix(idx, raw & ~rsv);
  localparam [10:0] MAXW = MAX_WIDTH[10:0];
  localparam [10:0] MAXH = MAX_HEIGHT[10:0];

  function automatic [3:0] clamp_log2(input [3:0] v);
    clamp_log2 = !ge_const(16'(v), 3) ? 4'd3 : ge_const(16'(v), 11) ? 4'd10 : v;
  endfunction
  function automatic [10:0] clamp_dim(input [10:0] v, input [10:0] max);
    clamp_dim = v == 11'd0 ? 11'd1 : ge_const(16'(v), 32'(max) + 1) ? max : v;   // max is a constant
  endfunction
  function automatic [10:0] clamp_1024(input [10:0] v);
    clamp_1024 = ge_const(16'(v), 1025) ? 11'd1024 : v;
  endfunction
  // the clamps change a value exactly when these hold (ERR_BAD_VALUE from the range tests, not from
  // comparing the clamped value with the received one)
  function automatic log2_out(input [3:0] v);
    log2_out = !ge_const(16'(v), 3) || ge_const(16'(v), 11);
  endfunction
  function automatic dim_out(input [10:0] v, input [10:0] max);
    dim_out = v == 11'd0 || ge_const(16'(v), 32'(max) + 1);   // max is a constant
  endfunction
  function automatic out_1024(input [10:0] v);
    out_1024 = ge_const(16'(v), 1025);
  endfunction
  function automatic format_ok(input [1:0] f);
    format_ok = !((f == 2'd1 && !FEATURES[4]) || (f == 2'd2 && !FEATURES[5]));
  endfunction

  reg [63:0] d;     // validated value
  reg        bad;   // ERR_BAD_VALUE
  always @* begin
    d = enum_fix[63:0];
    bad = enum_fix[64];
    case (idx)
      `SPIGPU_REG_TEX_FMT: begin
        d[3:0] = clamp_log2(d[3:0]);
        d[7:4] = clamp_log2(d[7:4]);
        if (log2_out(enum_fix[3:0]) || log2_out(enum_fix[7:4])) bad = 1'b1;
        if (d[12] && !FEATURES[0]) begin d[12] = 1'b0; bad = 1'b1; end
        if (!format_ok(d[17:16])) begin d[17:16] = 2'd0; bad = 1'b1; end
      end
      `SPIGPU_REG_FB_FORMAT: begin
        d[10:0] = clamp_dim(d[10:0], MAXW);
        d[26:16] = clamp_dim(d[26:16], MAXH);
        if (dim_out(enum_fix[10:0], MAXW) || dim_out(enum_fix[26:16], MAXH)) bad = 1'b1;
        if (!format_ok(d[33:32])) begin d[33:32] = 2'd0; bad = 1'b1; end
      end
      `SPIGPU_REG_SCISSOR: begin
        d[10:0] = clamp_1024(d[10:0]);
        d[26:16] = clamp_1024(d[26:16]);
        d[42:32] = clamp_1024(d[42:32]);
        d[58:48] = clamp_1024(d[58:48]);
        if (out_1024(enum_fix[10:0]) || out_1024(enum_fix[26:16]) || out_1024(enum_fix[42:32])
            || out_1024(enum_fix[58:48])) bad = 1'b1;
      end
      `SPIGPU_REG_TRI_MODE: begin
        if (d[1] && !FEATURES[7]) begin d[1] = 1'b0; bad = 1'b1; end
        if (d[8:7] != 2'd0 && !FEATURES[1]) begin d[8:7] = 2'd0; bad = 1'b1; end
        if (d[9] && !FEATURES[2]) begin d[9] = 1'b0; bad = 1'b1; end
        // TEMPORAL [15] and DITHER_PHASE [19:16] (protocol 1.1)
        if (d[19:15] != 5'd0 && !FEATURES[6]) begin d[19:15] = 5'd0; bad = 1'b1; end
        // Z_WRITE [6] and Z_TEST [2] without a depth buffer (protocol 1.4)
        if ((d[6] || d[2]) && DEPTH == 0) begin d[6] = 1'b0; d[2] = 1'b0; bad = 1'b1; end
      end
      // without a depth buffer CLEAR_Z is refused when it executes and clears nothing (1.4)
      `SPIGPU_REG_CLEAR_Z: if (DEPTH == 0) bad = 1'b1;
      default: ;
    endcase
  end

  localparam [63:0] RESET_TEX_FMT     = reg_reset(`SPIGPU_REG_TEX_FMT);
  localparam [63:0] RESET_SCISSOR     = reg_reset(`SPIGPU_REG_SCISSOR);
  localparam [63:0] RESET_FB_FORMAT   = reg_reset(`SPIGPU_REG_FB_FORMAT);
  localparam [63:0] RESET_CLEAR_COLOR = reg_reset(`SPIGPU_REG_CLEAR_COLOR);
  localparam [63:0] RESET_CLEAR_DEPTH = reg_reset(`SPIGPU_REG_CLEAR_DEPTH);
  localparam [63:0] RESET_COLOR       = reg_reset(`SPIGPU_REG_COLOR);
  localparam [63:0] RESET_TEXCOORD    = reg_reset(`SPIGPU_REG_TEXCOORD);

  // --- state ---
  // Only what the core can tell apart is stored: FB_FORMAT's sizes in the bits their largest
  // values need (MAX_WIDTH / MAX_HEIGHT after validation, or the reset value, 640 x 480, which is
  // not validated), and FB_DRAW / FB_Z as their block address below the core's 2^ADDR_W
  // (ADDR_W = log2 VRAM_KIB + 10) plus one bit for "at or beyond it", which the core's address
  // arithmetic (core_addr.vh) reads from the upper bits: they are all that bit.
  localparam [10:0]  RESET_W = RESET_FB_FORMAT[10:0];
  localparam [10:0]  RESET_H = RESET_FB_FORMAT[26:16];
  localparam integer WB  = $clog2(((MAX_WIDTH > RESET_W) ? MAX_WIDTH : RESET_W) + 1);
  localparam integer HB  = $clog2(((MAX_HEIGHT > RESET_H) ? MAX_HEIGHT : RESET_H) + 1);
  localparam integer B16 = $clog2(VRAM_KIB) + 6;
  function automatic [B16:0] base_sat(input [27:0] b16);
    base_sat = {(b16 >> B16) != 28'd0, b16[B16-1:0]};
  endfunction
  function automatic [27:0] base_out(input [B16:0] b);
    base_out = {{(28 - B16){b[B16]}}, b[B16-1:0]};
  endfunction
  reg [63:0]  color, texcoord;
  reg [1:0]   prim_type;
  reg [1:0]   vcount;
  reg [183:0] stored0, stored1;
  reg [31:0]  tri_mode;
  reg [27:0]  tex_base;
  reg [B16:0] fb_draw, fb_z;
  reg [17:0]  tex_fmt;
  reg [43:0]  scissor;
  reg [1:0]   fb_format;
  reg [WB-1:0] fb_width;
  reg [HB-1:0] fb_height;
  reg [31:0]  clear_color;
  reg [23:0]  clear_depth;
  reg         kick_shadowed;   // the kicking VERTEX has written its shadow entry

  wire [183:0] vertex = {texcoord[31:0], texcoord[63:32], color[63:32], color[31:0], d[55:32], d[31:16], d[15:0]};

  wire is_vertex  = idx == `SPIGPU_REG_VERTEX;
  wire is_clear   = idx == `SPIGPU_REG_CLEAR;
  wire is_clear_z = idx == `SPIGPU_REG_CLEAR_Z && DEPTH != 0;
  wire is_display = idx == `SPIGPU_REG_FB_DISPLAY;
  wire is_memaddr = idx == `SPIGPU_REG_MEM_ADDR;
  wire is_memdata = idx == `SPIGPU_REG_MEM_DATA;
  wire is_fence   = idx == `SPIGPU_REG_FENCE;
  wire kick       = is_vertex && vcount == 2'd2;
  wire to_core    = kick || is_clear || is_clear_z;
  wire to_shadow  = idx[6:5] == 2'b00 && reg_is_rw(idx);

  // Conditions for executing the entry now.
  wire core_quiet = core_idle && !core_drain;                  // every earlier core command completed
  wire quiet      = core_quiet && mem_idle;                    // ... and every earlier memory operation
  wire is_mem     = is_memaddr || is_memdata;
  wire core_ok    = !to_core || (cmd_ready && mem_idle && !core_drain && (!to_shadow || kick_shadowed));
  wire mem_ok     = !is_mem || mem_op_ack;                     // the unit waits for its own idle
  wire wait_ok    = is_mem ? core_quiet : (is_display || is_fence) ? quiet : 1'b1;
  wire swap_ok    = !is_display || swap_ready;
  wire shadow_ok  = !to_shadow || sh_wr_ack || kick_shadowed;
  wire vert_ok;                                                // VPORT: the vertex's words are written
  wire go         = in_valid && core_ok && wait_ok && swap_ok && shadow_ok && mem_ok && vert_ok;

  assign in_pop    = go;
  // Stable until cmd_ready: mem_idle and kick_shadowed only become true while the entry waits, and
  // core_drain only becomes false. A kick offers its triangle once its shadow entry is written.
  assign cmd_valid = in_valid && to_core && mem_idle && !core_drain && (!to_shadow || kick_shadowed) && vert_ok;
  assign cmd_op    = is_clear ? 2'd1 : is_clear_z ? 2'd2 : 2'd0;
  assign cmd_tri_mode = tri_mode;
  assign cmd_tex_base = tex_base;
  assign cmd_tex_fmt = tex_fmt;
  assign cmd_scissor = scissor;
  assign cmd_fb_draw = base_out(fb_draw);
  // without a depth buffer (DEPTH = 0) the core never reads or writes Z (TRI_MODE's Z_TEST and Z_WRITE
  // and CLEAR_Z are refused here), so FB_Z need not reach it: a constant 0 lets synthesis drop this
  // copy and the core's snapshot of it (FB_Z still reads back from the register file's shadow RAM)
  assign cmd_fb_z = DEPTH != 0 ? base_out(fb_z) : 28'd0;
  assign cmd_fb_format = fb_format;
  assign cmd_fb_width = 11'(fb_width);
  assign cmd_fb_height = 11'(fb_height);
  assign cmd_clear_color = VPORT != 0 ? 32'd0 : clear_color;
  assign cmd_clear_depth = VPORT != 0 ? 24'd0 : clear_depth;
  assign cmd_v0 = VPORT != 0 ? 184'd0 : stored0;
  assign cmd_v1 = VPORT != 0 ? 184'd0 : stored1;
  assign cmd_v2 = VPORT != 0 ? 184'd0 : vertex;

  // --- vertex slots (VPORT = 1): the vertex being formed goes to slot sl[vcount]; a triangle is
  // (sl[0], sl[1], sl[2]); after it, STRIP rotates the slots left, FAN exchanges sl[1] and sl[2]
  // (the first vertex stays), LIST starts again at sl[0].
  generate
    if (VPORT != 0) begin : g_vport
      (* ram_style = "block", no_rw_check *) reg [31:0] vmem[0:15];
      reg  [1:0] sl0, sl1, sl2, wc;
      wire [1:0] wslot = (vcount == 2'd0) ? sl0 : (vcount == 2'd1) ? sl1 : sl2;
      wire [1:0] rslot = (vp_addr[3:2] == 2'd0) ? sl0 : (vp_addr[3:2] == 2'd1) ? sl1 : sl2;
      wire       rslot3 = vp_addr[3:2] == 2'd3;
      reg  [1:0] cinit;   // 0, 1: writing CLEAR_COLOR's, CLEAR_DEPTH's reset value; 2: done
      // the third word is COLOR, from the register file's shadow RAM, which holds the validated
      // value of the last executed COLOR (or its reset value): no 32 flip-flops of its own here. An
      // SPI read of a shadowed register takes the RAM's read port for a clock; the word then waits
      wire       vwrite = in_valid && is_vertex && wc != 2'd3 && cinit[1] && (wc != 2'd2 || sh_rd_valid);
      wire       is_cd  = idx == `SPIGPU_REG_CLEAR_DEPTH;
      wire       cwrite = go && (idx == `SPIGPU_REG_CLEAR_COLOR || is_cd);
      wire       iwrite = !cinit[1];
      // CLEAR_COLOR and CLEAR_DEPTH are d[31:0] (validation clears the bits above CLEAR_DEPTH's 24).
      // Without a depth buffer (DEPTH = 0) nothing reads word 1 (a vertex's Z, CLEAR_DEPTH: Z_TEST,
      // Z_WRITE and CLEAR_Z are refused), so it is written in the same clock as before with d[31:0]
      // (no Z source on the 32-bit write multiplexer)
      wire [31:0] wdata = iwrite ? ((cinit[0] && DEPTH != 0) ? RESET_CLEAR_DEPTH[31:0] : RESET_CLEAR_COLOR[31:0])
                        : (vwrite && wc == 2'd1 && DEPTH != 0) ? {8'd0, d[55:32]}
                        : (vwrite && wc == 2'd2) ? sh_rd_data[31:0] : d[31:0];
      wire [3:0]  waddr = vwrite ? {wslot, wc} : iwrite ? {3'b110, cinit[0]} : {3'b110, is_cd};
      assign vert_ok = (!is_vertex || wc == 2'd3) && !iwrite;
      always @(posedge clk) begin
        if (vwrite || cwrite || iwrite) vmem[waddr] <= wdata;
        vp_data <= vmem[{rslot3 ? 2'd3 : rslot, vp_addr[1:0]}];
        if (rst) begin
          cinit <= 2'd0;
          wc <= 2'd0;
          sl0 <= 2'd0;
          sl1 <= 2'd1;
          sl2 <= 2'd2;
        end else begin
          if (iwrite) cinit <= cinit + 2'd1;
          if (vwrite) wc <= wc + 2'd1;
          if (go) wc <= 2'd0;
          if (go && kick && prim_type == 2'd1) begin         // STRIP
            sl0 <= sl1;
            sl1 <= sl2;
            sl2 <= sl0;
          end else if (go && kick && prim_type == 2'd2) begin  // FAN
            sl1 <= sl2;
            sl2 <= sl1;
          end
        end
      end
      localparam [6:0] COLOR_IDX = `SPIGPU_REG_COLOR;
      assign sh_rd_idx = COLOR_IDX[4:0];
      wire unused_vp = &{1'b0, color, texcoord, stored0, stored1, clear_color, clear_depth, sh_rd_data[63:32]};
    end else begin : g_vflat
      assign vert_ok = 1'b1;
      always @(*) vp_data = 32'd0;
      assign sh_rd_idx = 5'd0;
      wire unused_vp = &{1'b0, vp_addr, sh_rd_data, sh_rd_valid};
    end
  endgenerate

  wire   mem_offer    = in_valid && core_quiet;
  assign mem_set_addr = mem_offer && is_memaddr;
  assign mem_addr_head = is_memaddr;
  assign mem_write    = mem_offer && is_memdata;
  // MEM_DATA has no reserved, enumerated or clamped bit and MEM_ADDR none in the pointer's bits
  // [31:3], the only ones the unit reads of it, so the validated value is the entry's there: the
  // write data and the pointer come from the FIFO's output without the validation's multiplexer on
  // the index (in the clock of the SPRAM's write, docs/gateware.md fmax-soc11)
  assign mem_op_data  = raw;
  assign swap_req     = go && is_display;
  assign swap_addr    = raw[31:4];   // FB_DISPLAY reserves [3:0] and [63:32] only: [31:4] as received
  assign waiting_vsync = in_valid && is_display && quiet && !swap_ready;

  // the shadow write happens in the cycle the entry executes (or, for a kick, before it is offered)
  assign sh_wr_req  = in_valid && to_shadow && !kick_shadowed && (kick ? (mem_idle && !core_drain) :
                      core_ok && wait_ok && swap_ok && mem_ok);
  assign sh_wr_idx  = idx[4:0];
  assign sh_wr_data = d;
  assign executed   = go;

  always @(posedge clk) begin
    err_set <= 7'd0;
    if (rst) begin
      color <= RESET_COLOR;
      texcoord <= RESET_TEXCOORD;
      prim_type <= 2'd0;
      vcount <= 2'd0;
      stored0 <= 184'd0;
      stored1 <= 184'd0;
      tri_mode <= 32'd0;
      tex_base <= 28'd0;
      tex_fmt <= RESET_TEX_FMT[17:0];
      scissor <= {RESET_SCISSOR[58:48], RESET_SCISSOR[42:32], RESET_SCISSOR[26:16], RESET_SCISSOR[10:0]};
      fb_draw <= {(B16 + 1){1'b0}};
      fb_z <= {(B16 + 1){1'b0}};
      fb_format <= RESET_FB_FORMAT[33:32];
      fb_width <= WB'(RESET_W);
      fb_height <= HB'(RESET_H);
      clear_color <= RESET_CLEAR_COLOR[31:0];
      clear_depth <= RESET_CLEAR_DEPTH[23:0];
      kick_shadowed <= 1'b0;
    end else begin
      if (kick && sh_wr_ack && !go) kick_shadowed <= 1'b1;
      if (go) begin
        kick_shadowed <= 1'b0;
        err_set[3] <= rsv_err;
        err_set[4] <= bad;
        case (idx)
          `SPIGPU_REG_COLOR: color <= d;
          `SPIGPU_REG_TEXCOORD: texcoord <= d;
          `SPIGPU_REG_PRIM: begin
            prim_type <= d[1:0];
            vcount <= 2'd0;
          end
          `SPIGPU_REG_VERTEX: begin
            if (vcount == 2'd0) begin
              stored0 <= vertex;
              vcount <= 2'd1;
            end else if (vcount == 2'd1) begin
              stored1 <= vertex;
              vcount <= 2'd2;
            end else if (prim_type == 2'd1) begin        // STRIP: (v1, v) become the stored pair
              stored0 <= stored1;
              stored1 <= vertex;
            end else if (prim_type == 2'd2) begin        // FAN: the first vertex stays
              stored1 <= vertex;
            end else begin                               // LIST
              vcount <= 2'd0;
            end
          end
          `SPIGPU_REG_TRI_MODE: tri_mode <= d[31:0];
          `SPIGPU_REG_TEX_BASE: tex_base <= d[31:4];
          `SPIGPU_REG_TEX_FMT: tex_fmt <= d[17:0];
          `SPIGPU_REG_SCISSOR: scissor <= {d[58:48], d[42:32], d[26:16], d[10:0]};
          `SPIGPU_REG_FB_DRAW: fb_draw <= base_sat(d[31:4]);
          `SPIGPU_REG_FB_Z: fb_z <= base_sat(d[31:4]);
          `SPIGPU_REG_FB_FORMAT: begin
            fb_format <= d[33:32];
            fb_width <= WB'(d[10:0]);
            fb_height <= HB'(d[26:16]);
          end
          `SPIGPU_REG_CLEAR_COLOR: clear_color <= d[31:0];
          `SPIGPU_REG_CLEAR_DEPTH: clear_depth <= d[23:0];
          default: ;
        endcase
      end
    end
  end

endmodule
