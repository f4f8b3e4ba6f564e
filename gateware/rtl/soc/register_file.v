// Register file front end (docs/protocol.md sections 3, 5 and 13): what happens when a frame
// completes or a read reaches bit 64.
//   - writes: undefined / read-only index -> ERR_BAD_REGISTER; immediate registers (ERR_CLEAR,
//     LINK_CTRL, LINK_CHECK, HOST_TAG, RESET) act at once after their validation; queued writes go
//     to the command FIFO (dropped while the link is DISCARDING, ERR_OVERFLOW when full), and are
//     validated when they execute (command_exec);
//   - reads: live registers (STATUS, FRAME_CRC, LINK_STATUS, MEM_ADDR, MEM_DATA) from a small
//     multiplexer in the bit-64 cycle; every other read-write register from a 64 x 64 shadow RAM
//     that holds the last validated value (written by the executor and the immediate writes), and
//     the constants CAPS2, CAPS and ID (initial contents), one cycle later; write-only registers read 0;
//   - the sticky error flags and ERR_CLEAR; RESET's soft reset pulse and the sequencer that writes
//     0 into the shadow RAM's read-write entries (32 cycles; the next frame cannot complete sooner);
//     the registers whose reset value is not 0 read it from a second entry until they are written.
// A RESET while the render core is still busy lets the core finish (the simulator finishes every
// executed command too) but drops the memory-range errors it raises after the reset; the executor
// starts no new core command until the core is idle again (core_drain).
module register_file #(
  parameter [63:0] CAPS = 64'h0,
  parameter [63:0] CAPS2 = 64'h0,
  parameter [63:0] ID = 64'h0,
  parameter [7:0]  FEATURES = 8'h3F,
  parameter        EX_READ = 0        // 1: the executor reads the shadow RAM while SPI reads do not (up5k)
) (
  input  wire        clk,
  input  wire        rst,
  // frames from the SPI slave
  input  wire        frame_valid,
  input  wire        frame_rw,
  input  wire [6:0]  frame_idx,
  input  wire [63:0] frame_data,
  input  wire        frame_abort,
  input  wire        rd_strobe,
  input  wire [6:0]  rd_idx,
  output reg  [63:0] rd_live,
  output wire        rd_from_ram,
  output wire [63:0] rd_ram,
  output wire [5:0]  status_flags,
  // command FIFO
  output wire        fifo_push,
  output wire        fifo_push_held,
  output wire [70:0] fifo_entry,
  input  wire        fifo_full,
  input  wire        fifo_nearly_full,
  input  wire [10:0] fifo_level,
  input  wire        fifo_held,
  // link integrity
  input  wire        link_strict,
  input  wire        link_discarding,
  input  wire [63:0] link_status,
  input  wire        err_link_crc,
  output wire        drop_overflow,
  output wire        link_check_strobe,
  output wire [31:0] link_check_crc,
  output wire        link_ctrl_strobe,
  output wire        link_ctrl_strict,
  // soft reset (RESET with its magic value), one cycle
  output wire        soft_reset,
  // executor: shadow RAM writes of validated read-write registers, error flags
  input  wire        ex_wr_req,
  input  wire [4:0]  ex_wr_idx,
  input  wire [63:0] ex_wr_data,
  output wire        ex_wr_ack,
  // executor reads (EX_READ = 1): the shadow RAM's read port is the SPI side's only in the bit-64
  // cycle of a read of a shadowed register; in every other clock it reads ex_rd_idx, and
  // ex_rd_valid says the clock before was such a clock (ex_rd_data is then that entry)
  input  wire [4:0]  ex_rd_idx,
  output wire [63:0] ex_rd_data,
  output wire        ex_rd_valid,
  input  wire [6:0]  err_set,        // flags raised elsewhere (executor, memory, scanout)
  input  wire        core_range_err, // the core's access fell beyond VRAM
  input  wire        core_idle,
  output reg         core_drain,     // after a RESET: wait for the core before new commands
  // live state
  input  wire        busy,
  input  wire        vblank,
  input  wire        swap_pending,
  input  wire [15:0] frame_count,
  input  wire [47:0] frame_crc,
  input  wire        mem_ready,
  input  wire [28:0] mem_addr,
  input  wire [63:0] prefetch,
  output wire        mem_read_strobe, // a MEM_DATA read reached bit 64
  output reg  [6:0]  errors
);
`include "spigpu_regs.vh"

  localparam ERR_FRAMING = 0, ERR_OVERFLOW = 1, ERR_LINK_CRC = 2, ERR_RESERVED = 3, ERR_BAD_VALUE = 4,
             ERR_BAD_REGISTER = 5, ERR_MEM_RANGE = 6;
  localparam [63:0] RESET_MAGIC = 64'h0000005245534554;
  localparam [31:0] CLEAR_KEY   = 32'h6F666621;   // LINK_CTRL.CLEAR_KEY, "off!" (protocol 1.3)

  // --- writes arriving ---
  wire [1:0]  wclass   = reg_class(frame_idx);
  wire        wr       = frame_valid && !frame_rw;
  wire        wr_bad   = wr && (wclass == 2'd0 || wclass == 2'd1);
  wire        wr_queue = wr && wclass == 2'd2;
  wire        wr_imm   = wr && wclass == 2'd3;
  wire is_err_clear = frame_idx == `SPIGPU_REG_ERR_CLEAR;
  wire is_link_ctrl = frame_idx == `SPIGPU_REG_LINK_CTRL;
  wire is_check     = frame_idx == `SPIGPU_REG_LINK_CHECK;
  wire is_host_tag  = frame_idx == `SPIGPU_REG_HOST_TAG;
  wire is_reset     = frame_idx == `SPIGPU_REG_RESET;
  // reserved bits: only immediate writes are checked here (queued ones when they execute), so
  // the table's masks of the immediate registers are enough
  localparam [63:0] RSV_ERR_CLEAR = reg_reserved(`SPIGPU_REG_ERR_CLEAR);
  localparam [63:0] RSV_LINK_CTRL = reg_reserved(`SPIGPU_REG_LINK_CTRL);
  localparam [63:0] RSV_CHECK     = reg_reserved(`SPIGPU_REG_LINK_CHECK);
  localparam [63:0] RSV_HOST_TAG  = reg_reserved(`SPIGPU_REG_HOST_TAG);
  localparam [63:0] RSV_RESET     = reg_reserved(`SPIGPU_REG_RESET);
  wire [63:0] rsv_mask = is_err_clear ? RSV_ERR_CLEAR : is_link_ctrl ? RSV_LINK_CTRL : is_check ? RSV_CHECK
                       : is_host_tag ? RSV_HOST_TAG : is_reset ? RSV_RESET : 64'h0;
  wire        imm_rsv  = wr_imm && (frame_data & rsv_mask) != 64'h0;
  // The immediate writes' values are used only under their own index's test, on bits that index
  // does not reserve (ERR_CLEAR 6:0, LINK_CTRL 0 and 63:32, LINK_CHECK 31:0), so they take the
  // frame's data as received: masking it with the index-dependent reserved mask gave each of those
  // bits a decode term (an assumption on the generated table, spigpu_regs.vh: should one of those
  // bits ever become reserved, its mask has to come back here)

  wire strict_refused = is_link_ctrl && frame_data[0] && !FEATURES[3];
  // leaving strict mode takes the key, so no single bit error can switch the protection off:
  // without it the write is refused whole (no restart, no discard, the value stays)
  wire clear_refused  = is_link_ctrl && link_strict && !frame_data[0] && frame_data[63:32] != CLEAR_KEY;
  wire reset_ok       = wr_imm && is_reset && frame_data == RESET_MAGIC;
  wire imm_bad_value  = wr_imm && ((is_reset && frame_data != RESET_MAGIC) || strict_refused || clear_refused);

  assign fifo_push      = wr_queue && !link_discarding && !fifo_full;
  assign fifo_push_held = link_strict;
  assign fifo_entry     = {frame_idx, frame_data};
  assign drop_overflow  = wr_queue && !link_discarding && fifo_full;
  assign link_check_strobe = wr_imm && is_check;
  assign link_check_crc    = frame_data[31:0];   // read only with link_check_strobe
  assign link_ctrl_strobe  = wr_imm && is_link_ctrl && !clear_refused;
  assign link_ctrl_strict  = frame_data[0] && FEATURES[3];
  assign soft_reset        = reset_ok;

  // --- shadow RAM of the read-write registers (indices 0x00..0x1F) ---
  // Entries 0..31 hold the read-write registers; entries 32 + (index & 0x1F) of CAPS2, CAPS and ID
  // hold those constants from configuration (no port writes there, a soft reset leaves them), so
  // their reads come from the RAM like a read-write register's and the live multiplexer has no
  // constant terms. The RAM is 64 bits wide, so its block RAMs are 256 deep anyway: no RAM added.
  // Entries 32 + index of the read-write registers whose reset value is not 0 (COLOR, TEX_FMT,
  // SCISSOR, CLEAR_COLOR, CLEAR_DEPTH, FB_FORMAT: RESET_NZ) hold that value, never written either;
  // such a register reads from there from a reset until its first write (`at_reset`), so the reset
  // sequencer writes 0 to every entry and its write data needs no table of reset values (77 LUT4:
  // COLOR's all-ones alone put a fifth input on every bit of the write multiplexer).
  function automatic [31:0] nonzero_resets(input [5:0] n);
    integer k;
    begin
      nonzero_resets = 32'd0;
      for (k = 0; k < n; k = k + 1)
        nonzero_resets[k] = reg_is_rw(7'(k)) && reg_reset(7'(k)) != 64'h0;
    end
  endfunction
  localparam [31:0] RESET_NZ = nonzero_resets(6'd32);
  (* no_rw_check *) reg [63:0] shadow [0:63];   // a read in the clock of a write may return the old value
  integer init_k;
  initial begin
    for (init_k = 0; init_k < 32; init_k = init_k + 1)
      if (RESET_NZ[init_k]) shadow[32 + init_k] = reg_reset(7'(init_k));
    shadow[{1'b1, 5'(`SPIGPU_REG_CAPS2)}] = CAPS2;
    shadow[{1'b1, 5'(`SPIGPU_REG_CAPS)}]  = CAPS;
    shadow[{1'b1, 5'(`SPIGPU_REG_ID)}]    = ID;
  end
  reg  [63:0] shadow_q;
  reg         seq_active;
  reg  [4:0]  seq_idx;
  // The immediate writes reach the RAM a clock after their frame (imm_wr): their decode (LINK_CTRL's
  // CLEAR_KEY compare on the frame's data) then no longer lies in the executor's clock through
  // ex_wr_ack, which gated `go` and from there the swap request and the FIFO's pop (docs/gateware.md
  // fmax-soc11). The frame's index and data are the SPI slave's shift register, which holds them until
  // the next SCK rising edge: at least two clocks after frame_valid (the synchronisers and T/2 > Tc),
  // so they are unchanged in that clock. No host sees the clock: a read of HOST_TAG or LINK_CTRL
  // reaches the RAM at bit 64 of a later frame, and the error flags and the link's own state
  // (link_ctrl_strobe) still act in the frame's clock.
  wire        imm_wr_now = wr_imm && (is_host_tag || link_ctrl_strobe);
  reg         imm_wr;
  always @(posedge clk) imm_wr <= imm_wr_now && !rst;
  wire        sh_we  = seq_active || imm_wr || ex_wr_req;
  wire [4:0]  sh_wa  = seq_active ? seq_idx : imm_wr ? frame_idx[4:0] : ex_wr_idx;
  // The immediate writes that reach the RAM are HOST_TAG's (no reserved bits: its data as received,
  // with the table's mask, a constant) and LINK_CTRL's (STRICT alone), so the write data takes no
  // mask that depends on the index; written as one-hot selects and an AND-OR (the sequencer's 0:
  // none of them)
  wire        sel_tag = !seq_active && imm_wr && !is_link_ctrl;
  wire        sel_lc  = !seq_active && imm_wr && is_link_ctrl;
  wire        sel_ex  = !seq_active && !imm_wr;
  wire [63:0] sh_wd  = ({64{sel_tag}} & frame_data & ~RSV_HOST_TAG)
                     | {63'd0, sel_lc && link_ctrl_strict} | ({64{sel_ex}} & ex_wr_data);
  assign ex_wr_ack = ex_wr_req && !seq_active && !imm_wr;
  // at_reset[i]: register i (in RESET_NZ) has not been written since the last reset, so its value is
  // entry 32 + i. A read in the clock of the first write still sees the reset value there, the old
  // value, as a read of entry i would; the sequencer's zeros do not count as writes
  reg  [31:0] at_reset_q;
  always @(posedge clk) begin
    if (rst || reset_ok) at_reset_q <= RESET_NZ;
    else if (sh_we && !seq_active) at_reset_q <= at_reset_q & ~(32'd1 << sh_wa);
  end
  wire [31:0] at_reset = at_reset_q & RESET_NZ;   // the other flags are constant 0 (no flip-flops)

  wire        spi_reads = !EX_READ || (rd_strobe && rd_from_ram);
  reg         ex_rd_q;
  always @(posedge clk) begin
    if (sh_we) shadow[{1'b0, sh_wa}] <= sh_wd;
    shadow_q <= shadow[spi_reads ? {rd_idx[6] || at_reset[rd_idx[4:0]], rd_idx[4:0]} : {at_reset[ex_rd_idx], ex_rd_idx}];
    ex_rd_q <= !spi_reads;
  end
  assign ex_rd_data  = shadow_q;
  assign ex_rd_valid = ex_rd_q;
  always @(posedge clk) begin
    if (rst || reset_ok) begin
      seq_active <= 1'b1;
      seq_idx <= 5'd0;
    end else if (seq_active) begin
      seq_idx <= seq_idx + 5'd1;
      if (seq_idx == 5'd31) seq_active <= 1'b0;
    end
  end

  // --- reads at bit 64 ---
  wire [1:0] rclass   = reg_class(rd_idx);
  wire   rd_const    = rd_idx == `SPIGPU_REG_CAPS2 || rd_idx == `SPIGPU_REG_CAPS || rd_idx == `SPIGPU_REG_ID;
  assign rd_from_ram = (rd_idx[6:5] == 2'b00 && reg_is_rw(rd_idx)) || rd_const;
  assign rd_ram      = shadow_q;
  assign mem_read_strobe = rd_strobe && rd_idx == `SPIGPU_REG_MEM_DATA;
  wire   link_pending = link_strict && fifo_held;
  wire   [63:0] status_value = {9'd0, errors, frame_count, 11'd0, link_pending, swap_pending, mem_ready, vblank, busy,
                                5'd0, fifo_level};
  always @* begin
    case (rd_idx)
      `SPIGPU_REG_STATUS:      rd_live = status_value;
      `SPIGPU_REG_FRAME_CRC:   rd_live = {16'd0, frame_crc};
      `SPIGPU_REG_LINK_STATUS: rd_live = link_status;
      `SPIGPU_REG_MEM_ADDR:    rd_live = {32'd0, mem_addr, 3'd0};
      `SPIGPU_REG_MEM_DATA:    rd_live = prefetch;
      default:                 rd_live = 64'h0;
    endcase
  end
  wire rd_undefined = rd_strobe && rclass == 2'd0;

  assign status_flags = {fifo_nearly_full, errors != 7'd0, busy, vblank, swap_pending, mem_ready};

  // --- sticky errors ---
  reg [6:0] set_now;
  always @* begin
    set_now = err_set;
    if (frame_abort) set_now[ERR_FRAMING] = 1'b1;
    if (drop_overflow) set_now[ERR_OVERFLOW] = 1'b1;
    if (err_link_crc) set_now[ERR_LINK_CRC] = 1'b1;
    if (imm_rsv) set_now[ERR_RESERVED] = 1'b1;
    if (imm_bad_value) set_now[ERR_BAD_VALUE] = 1'b1;
    if (wr_bad || rd_undefined) set_now[ERR_BAD_REGISTER] = 1'b1;
    if (core_range_err && !core_drain) set_now[ERR_MEM_RANGE] = 1'b1;
  end

  always @(posedge clk) begin
    if (rst) begin
      errors <= 7'd0;
      core_drain <= 1'b0;
    end else if (reset_ok) begin
      errors <= 7'd0;
      core_drain <= !core_idle;
    end else begin
      if (core_idle) core_drain <= 1'b0;
      if (wr_imm && is_err_clear) errors <= (errors & ~frame_data[6:0]) | set_now;
      else errors <= errors | set_now;
    end
  end
endmodule
