// MEM_ADDR / MEM_DATA (docs/protocol.md section 2.4): the memory pointer, the 64-bit prefetch
// buffer and STATUS.MEM_READY.
//   - MEM_ADDR (queued) sets the pointer and loads the prefetch buffer;
//   - MEM_DATA write (queued) stores 8 bytes, advances the pointer by 8 and reloads;
//   - a MEM_DATA read reaching bit 64 returns the buffer (register file), raises ERR_MEM_RANGE if
//     those bytes lay beyond VRAM, advances the pointer, clears MEM_READY and reloads. Reloads have
//     the highest memory priority and complete within a few clocks (SPRAM: 3; SDRAM: a refresh and a
//     row miss at worst), long before the next frame's bit 64 at any SCK the SPI slave allows.
// Accesses beyond VRAM never reach the memory: writes are dropped (ERR_MEM_RANGE), loads give 0.
// The executor offers an operation with its data (the head of the command FIFO) until op_ack; a
// read is taken first. A reload started while another is in flight discards the older responses.
module mem_access #(
  parameter        UNITS_L2 = 14,           // VRAM size / 8 bytes = 2^UNITS_L2
  parameter        ICE40 = 0                // 1: the pointer's next value in one logic cell a bit (up5k)
) (
  input  wire        clk,
  input  wire        rst,          // power-on
  input  wire        soft_reset,   // RESET: pointer 0, buffer 0, MEM_READY 0 (the beyond flag stays, as in the simulator)
  // executor
  input  wire        set_addr,
  input  wire        set_addr_head,// ICE40: the head is a MEM_ADDR (set_addr without its readiness terms)
  input  wire        write,
  input  wire [63:0] op_data,
  output wire        op_ack,
  output wire        ex_idle,      // no executor operation (write or its reload) in progress
  // SPI: a MEM_DATA read reached bit 64
  input  wire        read_strobe,
  // state
  output reg  [28:0] addr,
  output reg  [63:0] prefetch,
  output reg         mem_ready,
  output reg         err_range,
  // memory port (arbiter)
  output wire        req_valid,
  input  wire        req_ready,
  output wire        req_we,
  output wire [29:0] req_addr,
  output wire [31:0] req_wdata,
  input  wire        rsp_valid,
  input  wire [31:0] rsp_rdata
);
  localparam IDLE = 3'd0, WR0 = 3'd1, WR1 = 3'd2, RD0 = 3'd3, RD1 = 3'd4, WAIT = 3'd5;
  reg  [2:0]  phase;
  reg         pend_read;
  reg         owner_ex;     // the access in progress belongs to an executor operation
  reg         beyond;       // the buffer holds bytes from beyond VRAM
  reg  [1:0]  outstanding;  // reads issued, responses not yet seen
  reg  [1:0]  discard;      // responses of a superseded load still to come
  reg         got_first;

  assign req_valid = phase == WR0 || phase == WR1 || phase == RD0 || phase == RD1;
  assign req_we    = phase == WR0 || phase == WR1;
  // The unit being accessed is the pointer itself: a write is to `addr` (advanced when it is done),
  // a reload to the new `addr`, and every change of the pointer while an access is in progress
  // starts a new one (or ends it, beyond VRAM), so no copy of it is kept.
  assign req_addr  = {addr, phase == WR1 || phase == RD1};
  assign req_wdata = phase == WR0 ? op_data[63:32] : op_data[31:0];
  assign ex_idle   = !(phase != IDLE && owner_ex);

  wire issued   = req_valid && req_ready;
  wire reading  = issued && !req_we;
  wire writing  = phase == WR0 || phase == WR1;
  // VRAM is a power of two: "below it" is a test of the pointer's upper bits, no comparator
  wire in_vram  = addr[28:UNITS_L2] == 0;
  wire [1:0] outstanding_next = outstanding + {1'b0, reading} - {1'b0, rsp_valid};
  wire [1:0] discard_next = discard - {1'b0, rsp_valid && discard != 2'd0};

  // One event per clock, never in the middle of a write: a read, else an executor operation.
  wire do_read  = !writing && pend_read;
  wire do_set   = !writing && !pend_read && set_addr && ex_idle;
  wire do_write = !writing && !pend_read && !set_addr && write && ex_idle;
  wire wr_done  = phase == WR1 && issued;
  assign op_ack = do_set || (do_write && !in_vram) || wr_done;
  wire        do_load   = do_read || do_set || (do_write && !in_vram) || wr_done;
  wire [28:0] load_addr;
  wire        load_in_vram;
  generate
    if (ICE40 != 0) begin : g_next
      // ice40_load_step: the increment and the choice in one cell a bit. Its choice `ld` drives all 29
      // carries, so it is an early signal that equals do_set whenever the pointer loads (do_load):
      // no write in progress, no read pending and a MEM_ADDR at the FIFO's head (a read's or a write's
      // reload has one of the first two or a MEM_DATA at the head). Whether the next unit is in VRAM
      // comes from the pointer's flip-flops, not from the sum (whose cells then feed only the pointer
      // and pack with its flip-flops): addr + 1 is below 2^UNITS_L2 when addr is and its low bits are
      // not all ones, or when the whole pointer is all ones (it wraps)
      wire        ld_early = !writing && !pend_read && set_addr_head;
      wire [28:0] co;
      wire        low_ones = &addr[UNITS_L2-1:0];
      ice40_load_step #(.W(29), .DOWN(0)) u_next (.ld(ld_early), .d(op_data[31:3]), .q(addr), .q_next(load_addr), .co(co));
      assign load_in_vram = do_set ? op_data[31:3+UNITS_L2] == 0 : (in_vram && !low_ones) || (low_ones && &addr[28:UNITS_L2]);
      wire unused_co = &{1'b0, co};
    end else begin : g_next
      assign load_addr = do_set ? op_data[31:3] : addr + 29'd1;
      assign load_in_vram = load_addr[28:UNITS_L2] == 0;
      wire unused_head = &{1'b0, set_addr_head};
    end
  endgenerate
  // the prefetch buffer: zeroed at reset and by a load beyond VRAM, else each half taken from its
  // response (a load's own zero wins over a response in the same clock); one enable and one reset
  // per half, the data straight from the memory
  wire        take = rsp_valid && discard == 2'd0;
  always @(posedge clk) begin
    if (rst || soft_reset || (do_load && !load_in_vram)) begin
      prefetch <= 64'd0;
    end else begin
      if (take && !got_first) prefetch[63:32] <= rsp_rdata;
      if (take && got_first) prefetch[31:0] <= rsp_rdata;
    end
  end

  always @(posedge clk) begin
    err_range <= 1'b0;
    if (rst || soft_reset) begin
      addr <= 29'd0;
      mem_ready <= 1'b0;
      phase <= IDLE;
      pend_read <= 1'b0;
      owner_ex <= 1'b0;
      got_first <= 1'b0;
      // reads still in flight answer after a RESET; their data must not be taken
      outstanding <= rst ? 2'd0 : outstanding_next;
      discard <= rst ? 2'd0 : outstanding_next;
      if (rst) beyond <= 1'b0;
    end else begin
      outstanding <= outstanding_next;
      discard <= discard_next;
      if (read_strobe) pend_read <= 1'b1;
      // responses of the current load
      if (take) begin
        got_first <= !got_first;
        if (got_first) begin
          mem_ready <= 1'b1;
          phase <= IDLE;
        end
      end
      case (phase)
        WR0: if (issued) phase <= WR1;
        RD0: if (issued) phase <= RD1;
        RD1: if (issued) phase <= WAIT;
        default: ;
      endcase
      if (do_read) begin
        pend_read <= 1'b0;
        if (beyond) err_range <= 1'b1;
      end
      if (do_write) begin
        if (in_vram) begin
          phase <= WR0;
          owner_ex <= 1'b1;
        end else begin
          err_range <= 1'b1;
        end
      end
      if (do_load) begin
        addr <= load_addr;
        mem_ready <= 1'b0;
        got_first <= 1'b0;
        discard <= outstanding_next;
        owner_ex <= !do_read;   // a read's reload supersedes an executor reload
        if (load_in_vram) begin
          phase <= RD0;
          beyond <= 1'b0;
        end else begin
          beyond <= 1'b1;
          mem_ready <= 1'b1;
          phase <= IDLE;
        end
      end
    end
  end
endmodule
