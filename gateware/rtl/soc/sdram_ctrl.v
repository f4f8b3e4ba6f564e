// SDR SDRAM controller for the ecp5 profile: one 16-bit SDRAM (ULX3S / ICEpi Zero: 4 banks x 8192
// rows x 512 columns = 32 MiB) as 8M words of 32 bits.
//   - a 32-bit word is one burst of 2 (BL = 2, CAS latency CL); byte enables become DQM per beat;
//   - word address -> column {a[7:0], 0}, bank a[9:8], row a[22:10]: a row holds 256 consecutive
//     words and consecutive rows rotate through the banks;
//   - every bank's row stays open until another row of that bank or a refresh needs it; one command
//     per clock; a READ or WRITE can issue every 2 clocks (2 bytes per clock at best);
//   - req_ready is a function of registers only (issue 19): init_done, a refresh due, the served slot
//     empty, or `issue_next`, registered a clock ahead, which says the request in the slot will issue
//     its READ or WRITE in this clock (it stays, is a row hit, and its timers reach 0), so the bank
//     state and timers do not reach the arbiter and the render core's stall logic in the same clock.
//     It is exact except for a request that issues in the clock after it was taken (an idle
//     controller): the next request is then taken a clock later than it was;
//   - auto refresh every T_REFI (all banks precharged first); the JEDEC power-up sequence at reset.
// All timing is in nanoseconds and converted with the clock frequency (CLK_KHZ: the ULX3S's 52.083 MHz
// is 52,084 kHz, rounded up so that every minimum spacing in clocks is at least the chip's, while the
// refresh interval is rounded down), so the behavioural model (gateware/sim/sdram_model.v), which
// checks every constraint, runs with the same numbers.
// Read capture (issue 19): the boards send the chip the core clock inverted (ULX3S: a DDR output
// cell), so the chip takes a command on the falling edge after the one that registered it and drives
// each read beat from tAC after a falling edge until tOH after the next. With the ECP5's I/O delays the
// beats change around the core's rising edges (docs/gateware.md "SDRAM"), so CAPTURE_FALL = 1 samples
// DQ on the falling edge, where the chip itself would (the middle of the beat), in an input register
// meant for the I/O cell, and hands it to the rising edge half a clock later: a beat is in the core
// CL + 1 clocks after the READ left its register, as with a chip clocked in phase and CAPTURE_FALL = 0
// (rising-edge sampling of DQ straight from the pin), so the read latency in core clocks is the same.
module sdram_ctrl #(
  parameter CLK_MHZ   = 50,
  parameter CLK_KHZ   = CLK_MHZ * 1000,   // the clock the timings are converted with
  parameter CL        = 2,
  parameter CAPTURE_FALL = 1,   // 1: chip clock = core clock inverted (the boards); 0: chip clock in phase
  // the slowest of the ULX3S's SDRAM parts checked (Alliance AS4C32M16SB-7TCN, datasheet table 16;
  // Micron MT48LC16M16A2-6A is 18/18/42/60/12/12/60); both take CL 2 at tCK >= 10 ns (100 MHz)
  parameter T_RP_NS   = 21,
  parameter T_RCD_NS  = 21,
  parameter T_RAS_NS  = 42,
  parameter T_RC_NS   = 63,
  parameter T_RRD_NS  = 14,
  parameter T_WR_NS   = 14,
  parameter T_RFC_NS  = 63,
  parameter T_REFI_NS = 7800,
  parameter INIT_US   = 100
) (
  input  wire        clk,
  input  wire        rst,
  input  wire        req_valid,
  output wire        req_ready,
  input  wire        req_we,
  input  wire [22:0] req_addr,
  input  wire [31:0] req_wdata,
  input  wire [3:0]  req_be,
  output reg         rsp_valid,
  output reg  [31:0] rsp_rdata,
  output wire        sd_cke,
  output wire        sd_cs_n,
  output wire        sd_ras_n,
  output wire        sd_cas_n,
  output wire        sd_we_n,
  output reg  [1:0]  sd_ba,
  output reg  [12:0] sd_a,
  output reg  [1:0]  sd_dqm,
  output reg  [15:0] sd_dq_o,
  output reg         sd_dq_oe,
  input  wire [15:0] sd_dq_i,
  output reg         init_done,
  output wire        refresh         // one clock per auto refresh issued
);
  function integer cycles(input integer ns);
    begin
      cycles = (ns * CLK_KHZ + 999999) / 1000000;
      if (cycles < 1) cycles = 1;
    end
  endfunction
  // timers hold (spacing - 1): a command may issue in the cycle its timer reads 0
  localparam integer RP_I = cycles(T_RP_NS) - 1, RCD_I = cycles(T_RCD_NS) - 1, RAS_I = cycles(T_RAS_NS) - 1,
                     RC_I = cycles(T_RC_NS) - 1, RRD_I = cycles(T_RRD_NS) - 1, RFC_I = cycles(T_RFC_NS) - 1,
                     WR_I = cycles(T_WR_NS), TURN_I = CL + 1,
                     REFI_I = T_REFI_NS * CLK_KHZ / 1000000;   // at most tREFI (the others at least theirs)
  localparam [7:0] RP  = RP_I[7:0];
  localparam [7:0] RCD = RCD_I[7:0];
  localparam [7:0] RAS = RAS_I[7:0];
  localparam [7:0] RC  = RC_I[7:0];
  localparam [7:0] RRD = RRD_I[7:0];
  localparam [7:0] WR  = WR_I[7:0];         // WRITE -> PRE: last data beat + tWR
  localparam [7:0] RFC = RFC_I[7:0];
  localparam [7:0] TURN = TURN_I[7:0];      // READ -> WRITE: read data off the bus
  localparam [15:0] REFI = REFI_I[15:0];
  localparam integer INIT_I = (INIT_US * CLK_KHZ + 999) / 1000;
  localparam [17:0] INIT = INIT_I[17:0];
  localparam [2:0]  CL3 = CL;

  localparam [3:0] C_NOP = 4'b0111, C_ACT = 4'b0011, C_READ = 4'b0101, C_WRITE = 4'b0100,
                   C_PRE = 4'b0010, C_REF = 4'b0001, C_MRS = 4'b0000;
  reg [3:0] cmd;
  // NOP while in reset (also before the first clock edge: the register may hold anything)
  assign {sd_cs_n, sd_ras_n, sd_cas_n, sd_we_n} = rst ? C_NOP : cmd;
  assign sd_cke = 1'b1;

  // --- bank state and timers ---
  reg [3:0]  open;
  reg [12:0] row0, row1, row2, row3;
  reg [7:0]  t_rcd0, t_rcd1, t_rcd2, t_rcd3;   // ACT -> READ/WRITE
  reg [7:0]  t_pre0, t_pre1, t_pre2, t_pre3;   // -> PRE (tRAS, tWR, read burst)
  reg [7:0]  t_act0, t_act1, t_act2, t_act3;   // -> ACT (tRC, tRP, tRFC)
  reg [7:0]  t_rrd, t_rw, t_turn;
  reg [15:0] refi;
  reg        ref_due;

  // --- the request being served ---
  reg        cur_valid, cur_we;
  reg [1:0]  cur_bank;
  reg [12:0] cur_row;
  reg [7:0]  cur_col;
  reg [31:0] cur_wdata;
  reg [3:0]  cur_be;

  reg [12:0] brow;
  reg [7:0]  b_rcd, b_pre, b_act;
  always @* begin
    case (cur_bank)
      2'd0: begin brow = row0; b_rcd = t_rcd0; b_pre = t_pre0; b_act = t_act0; end
      2'd1: begin brow = row1; b_rcd = t_rcd1; b_pre = t_pre1; b_act = t_act1; end
      2'd2: begin brow = row2; b_rcd = t_rcd2; b_pre = t_pre2; b_act = t_act2; end
      default: begin brow = row3; b_rcd = t_rcd3; b_pre = t_pre3; b_act = t_act3; end
    endcase
  end
  wire all_pre_ok = (!open[0] || t_pre0 == 8'd0) && (!open[1] || t_pre1 == 8'd0) &&
                    (!open[2] || t_pre2 == 8'd0) && (!open[3] || t_pre3 == 8'd0);
  wire all_act_ok = t_act0 == 8'd0 && t_act1 == 8'd0 && t_act2 == 8'd0 && t_act3 == 8'd0;

  // what to do this cycle
  wire hit      = open[cur_bank] && brow == cur_row;
  wire do_rw    = init_done && !ref_due && cur_valid && hit && b_rcd == 8'd0 && t_rw == 8'd0 &&
                  (!cur_we || t_turn == 8'd0);
  wire do_pre   = init_done && !ref_due && cur_valid && open[cur_bank] && !hit && b_pre == 8'd0;
  wire do_act   = init_done && !ref_due && cur_valid && !open[cur_bank] && b_act == 8'd0 && t_rrd == 8'd0;
  wire do_prea  = init_done && ref_due && open != 4'd0 && all_pre_ok;
  wire do_ref   = init_done && ref_due && open == 4'd0 && all_act_ok;
  // issue_next: do_rw will hold in the next clock. The request stays (no do_rw now), its row is open
  // and stays so (hit excludes this bank's PRECHARGE and ACTIVE; no refresh is or becomes due, so no
  // PRECHARGE all), and every timer do_rw waits for is at most 1 now, so 0 then
  reg    issue_next;
  wire   issue_next_d = cur_valid && !do_rw && hit && !ref_due && refi != 16'd1 && b_rcd <= 8'd1 &&
                        t_rw <= 8'd1 && (!cur_we || t_turn <= 8'd1);
  assign req_ready = init_done && !ref_due && (!cur_valid || issue_next);
  assign refresh   = do_ref;

  // read data capture: rd_pipe[k] is set k clocks after a READ was registered
  reg [CL+1:0] rd_pipe;
  // DQ sampled on the falling edge; syn_useioff asks nextpnr-ecp5 to put it in the pin's I/O register
  // (yosys synth_ecp5 copies the attribute to the flip-flop), so no fabric routing sits before it
  (* syn_useioff *) reg [15:0] dq_fall;
  always @(negedge clk) dq_fall <= sd_dq_i;
  wire [15:0]  dq_cap = CAPTURE_FALL != 0 ? dq_fall : sd_dq_i;
  reg [15:0]   beat0;
  reg          wr_beat1;
  reg [15:0]   wr_lo;
  reg [1:0]    wr_dqm_lo;

  // --- initialisation ---
  localparam I_WAIT = 3'd0, I_PREA = 3'd1, I_REF1 = 3'd2, I_REF2 = 3'd3, I_MRS = 3'd4, I_DONE = 3'd5;
  reg [2:0]  istate;
  reg [17:0] icount;

  function [7:0] dec(input [7:0] t);
    dec = t == 8'd0 ? 8'd0 : t - 8'd1;
  endfunction
  function [7:0] atleast(input [7:0] t, input [7:0] v);
    atleast = dec(t) > v ? dec(t) : v;
  endfunction

  always @(posedge clk) begin
    cmd <= C_NOP;
    rsp_valid <= 1'b0;
    rd_pipe <= {rd_pipe[CL:0], 1'b0};
    sd_dq_oe <= 1'b0;
    sd_dqm <= 2'b00;
    if (rst) begin
      init_done <= 1'b0;
      istate <= I_WAIT;
      icount <= INIT;
      open <= 4'd0;
      cur_valid <= 1'b0;
      issue_next <= 1'b0;
      ref_due <= 1'b0;
      refi <= REFI;
      rd_pipe <= {(CL + 2){1'b0}};
      wr_beat1 <= 1'b0;
      {t_rcd0, t_rcd1, t_rcd2, t_rcd3} <= 32'd0;
      {t_pre0, t_pre1, t_pre2, t_pre3} <= 32'd0;
      {t_act0, t_act1, t_act2, t_act3} <= 32'd0;
      {t_rrd, t_rw, t_turn} <= 24'd0;
    end else begin
      t_rcd0 <= dec(t_rcd0); t_rcd1 <= dec(t_rcd1); t_rcd2 <= dec(t_rcd2); t_rcd3 <= dec(t_rcd3);
      t_pre0 <= dec(t_pre0); t_pre1 <= dec(t_pre1); t_pre2 <= dec(t_pre2); t_pre3 <= dec(t_pre3);
      t_act0 <= dec(t_act0); t_act1 <= dec(t_act1); t_act2 <= dec(t_act2); t_act3 <= dec(t_act3);
      t_rrd <= dec(t_rrd);
      t_rw <= dec(t_rw);
      t_turn <= dec(t_turn);

      // power-up: 100 us of NOPs, precharge all, two auto refreshes, mode register
      if (!init_done) begin
        if (icount != 18'd0) icount <= icount - 18'd1;
        else begin
          case (istate)
            I_WAIT: begin cmd <= C_PRE; sd_a <= 13'h400; istate <= I_PREA; icount <= {10'd0, RP}; end
            I_PREA: begin cmd <= C_REF; istate <= I_REF1; icount <= {10'd0, RFC}; end
            I_REF1: begin cmd <= C_REF; istate <= I_REF2; icount <= {10'd0, RFC}; end
            I_REF2: begin
              // burst length 2, sequential, CAS latency CL, burst writes
              cmd <= C_MRS; sd_ba <= 2'd0; sd_a <= {6'd0, CL3, 1'b0, 3'b001};
              istate <= I_MRS; icount <= 18'd2;
            end
            default: begin istate <= I_DONE; init_done <= 1'b1; end
          endcase
        end
      end else begin
        issue_next <= issue_next_d;
        // refresh timer
        if (refi == 16'd1) begin
          refi <= REFI;
          ref_due <= 1'b1;
        end else begin
          refi <= refi - 16'd1;
        end
        if (req_valid && req_ready) begin
          cur_valid <= 1'b1;
          cur_we <= req_we;
          cur_bank <= req_addr[9:8];
          cur_row <= req_addr[22:10];
          cur_col <= req_addr[7:0];
          cur_wdata <= req_wdata;
          cur_be <= req_be;
        end else if (do_rw) begin
          cur_valid <= 1'b0;
        end
        if (do_prea) begin
          cmd <= C_PRE;
          sd_a <= 13'h400;
          open <= 4'd0;
          t_act0 <= atleast(t_act0, RP); t_act1 <= atleast(t_act1, RP);
          t_act2 <= atleast(t_act2, RP); t_act3 <= atleast(t_act3, RP);
        end else if (do_ref) begin
          cmd <= C_REF;
          ref_due <= 1'b0;
          t_act0 <= RFC; t_act1 <= RFC; t_act2 <= RFC; t_act3 <= RFC;
        end else if (do_rw) begin
          cmd <= cur_we ? C_WRITE : C_READ;
          sd_ba <= cur_bank;
          sd_a <= {4'b0000, cur_col, 1'b0};       // A10 = 0: no auto precharge
          t_rw <= 8'd1;                           // BL = 2
          if (cur_we) begin
            sd_dq_o <= cur_wdata[31:16];
            sd_dq_oe <= 1'b1;
            sd_dqm <= ~cur_be[3:2];
            wr_beat1 <= 1'b1;
            wr_lo <= cur_wdata[15:0];
            wr_dqm_lo <= ~cur_be[1:0];
            case (cur_bank)
              2'd0: t_pre0 <= atleast(t_pre0, WR);
              2'd1: t_pre1 <= atleast(t_pre1, WR);
              2'd2: t_pre2 <= atleast(t_pre2, WR);
              default: t_pre3 <= atleast(t_pre3, WR);
            endcase
          end else begin
            rd_pipe[0] <= 1'b1;
            t_turn <= TURN;
            case (cur_bank)
              2'd0: t_pre0 <= atleast(t_pre0, 8'd1);
              2'd1: t_pre1 <= atleast(t_pre1, 8'd1);
              2'd2: t_pre2 <= atleast(t_pre2, 8'd1);
              default: t_pre3 <= atleast(t_pre3, 8'd1);
            endcase
          end
        end else if (do_pre) begin
          cmd <= C_PRE;
          sd_ba <= cur_bank;
          sd_a <= 13'h000;
          open[cur_bank] <= 1'b0;
          case (cur_bank)
            2'd0: t_act0 <= atleast(t_act0, RP);
            2'd1: t_act1 <= atleast(t_act1, RP);
            2'd2: t_act2 <= atleast(t_act2, RP);
            default: t_act3 <= atleast(t_act3, RP);
          endcase
        end else if (do_act) begin
          cmd <= C_ACT;
          sd_ba <= cur_bank;
          sd_a <= cur_row;
          open[cur_bank] <= 1'b1;
          t_rrd <= RRD;
          case (cur_bank)
            2'd0: begin row0 <= cur_row; t_rcd0 <= RCD; t_pre0 <= RAS; t_act0 <= RC; end
            2'd1: begin row1 <= cur_row; t_rcd1 <= RCD; t_pre1 <= RAS; t_act1 <= RC; end
            2'd2: begin row2 <= cur_row; t_rcd2 <= RCD; t_pre2 <= RAS; t_act2 <= RC; end
            default: begin row3 <= cur_row; t_rcd3 <= RCD; t_pre3 <= RAS; t_act3 <= RC; end
          endcase
        end
      end
      // second write beat
      if (wr_beat1) begin
        wr_beat1 <= 1'b0;
        sd_dq_o <= wr_lo;
        sd_dq_oe <= 1'b1;
        sd_dqm <= wr_dqm_lo;
      end
      // read data
      if (rd_pipe[CL]) beat0 <= dq_cap;
      if (rd_pipe[CL+1]) begin
        rsp_valid <= 1'b1;
        rsp_rdata <= {beat0, dq_cap};
      end
    end
  end
endmodule
