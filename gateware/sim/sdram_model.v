// Behavioural model of a 16-bit SDR SDRAM (ISSI IS42S16160-class: 4 banks x 8192 rows x 512
// columns, as on the ULX3S) for the co-simulation. It stores data, answers reads after the CAS
// latency, honours DQM, and checks the controller against the part's timing: every command is
// checked for the bank state and tRCD, tRAS, tRP, tRC, tRRD, tWR, tRFC, tMRD; refresh intervals
// against 8 x tREFI (the JEDEC postponement limit) while running; the power-up sequence; data bus
// contention. Each violation is counted (the co-simulation fails on any) and printed once per kind.
// Supported: BL = 2 (sequential), CL 2 or 3, no auto precharge, no burst terminate.
//
// Clock phase and read data timing (issue 19): the chip runs on its own clock, which on the ULX3S is
// the controller's clock inverted (CLK_INVERTED = 1: an ODDRX1F sends 0 then 1), so it takes commands
// and write data on the controller's falling edges and drives each read beat from tAC after one of
// its edges until tOH after the next (tLZ / tHZ: off the bus). The model keeps time in picoseconds,
// runs on both edges of the controller's clock and puts on dq_out, half a clock ahead, what the
// controller's input register would see at its next edge: a beat inside its valid window, a value
// that is neither beat (~ the newest beat) where the bus is driven but changing, nothing (dq_out_oe
// = 0) where the chip does not drive. A controller sampling at the wrong edge reads garbage.
// The delays between the FPGA and the chip are parameters (the ECP5 -6 figures of docs/gateware.md
// "SDRAM"); the board traces are neglected, and commands are taken as set up and held (they change
// on the rising edge and the chip samples half a clock later).
module sdram_model #(
  parameter CLK_MHZ   = 50,
  parameter CL        = 2,
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
  parameter T_MRD     = 2,
  parameter INIT_US   = 100,
  parameter CLK_INVERTED = 1,
  // DQ out (Alliance AS4C32M16SB-7, table 16): access tAC 6.0 ns at CL 2, 5.4 at CL 3, hold tOH 2.5,
  // low impedance tLZ 0, high impedance tHZ 5.4
  parameter T_AC_PS   = CL == 3 ? 5400 : 6000,
  parameter T_OH_PS   = 2500,
  parameter T_LZ_PS   = 0,
  parameter T_HZ_PS   = 5400,
  // the board (ECP5 -6): the chip's clock leaves the FPGA this much after the core clock's edge
  // (ODDRX1F 0.99 ns + LVCMOS33 output 2.67), DQ reaches the controller's input register this much
  // after the chip's pin (LVCMOS33 input 1.14 + about 1 ns), and the controller's DQ reaches the pin
  // this much after its rising edge (about 1 ns of routing + LVCMOS33 output 2.67)
  parameter T_CLK_OUT_PS = 3660,
  parameter T_DQ_IN_PS   = 2140,
  parameter T_DQ_OUT_PS  = 3670
) (
  input  wire        clk,
  input  wire        cke,
  input  wire        cs_n,
  input  wire        ras_n,
  input  wire        cas_n,
  input  wire        we_n,
  input  wire [1:0]  ba,
  input  wire [12:0] a,
  input  wire [1:0]  dqm,
  input  wire [15:0] dq_in,      // from the controller
  input  wire        dq_in_oe,
  output reg  [15:0] dq_out,     // to the controller
  output reg         dq_out_oe,
  output reg  [31:0] violations,
  output reg  [31:0] reads,
  output reg  [31:0] writes,
  output reg  [31:0] activates
);
  function integer cycles(input integer ns);
    begin
      cycles = (ns * CLK_MHZ + 999) / 1000;
      if (cycles < 1) cycles = 1;
    end
  endfunction
  localparam integer RP = cycles(T_RP_NS), RCD = cycles(T_RCD_NS), RAS = cycles(T_RAS_NS),
                     RC = cycles(T_RC_NS), RRD = cycles(T_RRD_NS), WRC = cycles(T_WR_NS),
                     RFC = cycles(T_RFC_NS), REFI = cycles(T_REFI_NS), INIT = INIT_US * CLK_MHZ;

  reg [15:0] mem [0:(1 << 24) - 1] /* verilator public_flat_rw */;   // {bank, row, column}

  reg [31:0] now;
  reg [3:0]  active;
  reg [12:0] open_row [0:3];
  reg [31:0] t_act [0:3];
  reg [31:0] t_pre [0:3];
  reg [31:0] t_wr_end [0:3];
  reg [31:0] t_last_act, t_ref, t_mrs;
  reg [1:0]  refs_at_init;
  reg        mode_set;
  reg [63:0] seen;               // kinds of violation already printed (bit per kind)
  // read pipeline: rd_pipe[k] = a READ was sampled k chip clocks ago; its first beat is put out
  // after the chip's edge CL - 1 clocks after the command (valid tAC later, held until tOH after the
  // next edge, where a controller sampling in the chip's phase takes it), the second one clock later
  reg [CL:0]  rd_pipe;
  reg [23:0]  rd_addr [0:CL];
  // the beats put out: [0] after the chip's latest edge, [1] the edge before, [2] before that
  localparam integer HALF_I = 500000 / CLK_MHZ, LZ_IN_I = T_LZ_PS + T_DQ_IN_PS, AC_IN_I = T_AC_PS + T_DQ_IN_PS,
                     HZ_IN_I = 2 * HALF_I + T_HZ_PS + T_DQ_IN_PS, OH_IN_I = 2 * HALF_I + T_OH_PS + T_DQ_IN_PS,
                     HZ_I = 2 * HALF_I + T_HZ_PS, PERIOD_I = 2 * HALF_I;
  // a beat is valid at the controller's register from AC_IN to OH_IN after the edge it follows, and
  // the bus driven from LZ_IN to HZ_IN (HZ at the pins)
  localparam [63:0] HALF = {32'd0, HALF_I[31:0]}, PERIOD = {32'd0, PERIOD_I[31:0]}, LZ_IN = {32'd0, LZ_IN_I[31:0]},
                    AC_IN = {32'd0, AC_IN_I[31:0]}, HZ_IN = {32'd0, HZ_IN_I[31:0]}, OH_IN = {32'd0, OH_IN_I[31:0]},
                    LZ = T_LZ_PS, HZ = {32'd0, HZ_I[31:0]}, CLK_OUT = T_CLK_OUT_PS, DQ_OUT = T_DQ_OUT_PS;
  reg [63:0]  t_ps;              // the controller's current clock edge
  reg         beat_on [0:2];
  reg [15:0]  beat_data [0:2];
  reg [63:0]  beat_t [0:2];      // the chip's clock edge (at its pin) the beat follows
  reg         bus_drv;
  reg [15:0]  bus_val;
  integer     k;
  // write beat 1 comes one clock after the WRITE
  reg         wr_beat1;
  reg [23:0]  wr_addr1;

  wire [3:0] cmd = {cs_n, ras_n, cas_n, we_n};
  localparam [3:0] C_ACT = 4'b0011, C_READ = 4'b0101, C_WRITE = 4'b0100, C_PRE = 4'b0010,
                   C_REF = 4'b0001, C_MRS = 4'b0000;

  task automatic violate(input [5:0] kind, input [8*48-1:0] what);
    begin
      violations = violations + 32'd1;
      if (!seen[kind]) begin
        seen[kind] = 1'b1;
        $display("sdram_model: timing violation at cycle %0d: %0s", now, what);
      end
    end
  endtask

  function [15:0] merge(input [15:0] old, input [15:0] d, input [1:0] m);
    merge = {m[1] ? old[15:8] : d[15:8], m[0] ? old[7:0] : d[7:0]};
  endfunction

  // what the controller's input register sees at time t: a beat in its window, else the bus changing
  // (the newest beat inverted: neither beat), else not driven
  task automatic bus_at(input [63:0] t, output drv, output [15:0] val);
    integer i;
    reg     got;
    begin
      drv = 1'b0;
      got = 1'b0;
      val = 16'hFFFF;
      for (i = 2; i >= 0; i = i - 1) begin
        if (beat_on[i]) begin
          if (t >= beat_t[i] + LZ_IN && t <= beat_t[i] + HZ_IN) begin
            drv = 1'b1;
            if (!got) val = ~beat_data[i];
          end
          if (t >= beat_t[i] + AC_IN && t <= beat_t[i] + OH_IN) begin
            got = 1'b1;
            val = beat_data[i];
          end
        end
      end
    end
  endtask

  integer b;
  initial begin
    t_ps = 64'd0;
    for (b = 0; b < 3; b = b + 1) begin
      beat_on[b] = 1'b0;
      beat_data[b] = 16'd0;
      beat_t[b] = 64'd0;
    end
    now = 32'd0;
    active = 4'd0;
    violations = 32'd0;
    reads = 32'd0;
    writes = 32'd0;
    activates = 32'd0;
    seen = 64'd0;
    refs_at_init = 2'd0;
    mode_set = 1'b0;
    t_last_act = 32'd0;
    t_ref = 32'd0;
    t_mrs = 32'd0;
    rd_pipe = {(CL + 1){1'b0}};
    wr_beat1 = 1'b0;
    dq_out_oe = 1'b0;
    dq_out = 16'd0;
    for (b = 0; b < 4; b = b + 1) begin
      t_act[b] = 32'd0;
      t_pre[b] = 32'd0;
      t_wr_end[b] = 32'd0;
      open_row[b] = 13'd0;
    end
  end

  // both edges of the controller's clock: the chip's own edge (commands, data) is one of them
  always @(posedge clk or negedge clk) begin
    t_ps = t_ps + HALF;
    if (clk == (CLK_INVERTED == 0)) chip_edge();
    // bus contention: the controller drove DQ from its last rising edge (+ its output delay) for a
    // clock while a read's data was on the bus (tLZ after the edge starting it to tHZ after its end)
    if (clk && dq_in_oe) begin
      for (k = 0; k < 3; k = k + 1)
        if (beat_on[k] && beat_t[k] + LZ < t_ps + DQ_OUT && t_ps + DQ_OUT < beat_t[k] + PERIOD + HZ)
          violate(0, "controller drives DQ during read data");
    end
    bus_at(t_ps + HALF, bus_drv, bus_val);
    dq_out <= bus_val;
    dq_out_oe <= bus_drv;
  end

  task automatic chip_edge;
    begin
    now = now + 32'd1;
    // second write beat
    if (wr_beat1) begin
      mem[wr_addr1] <= merge(mem[wr_addr1], dq_in, dqm);
      if (!dq_in_oe) violate(1, "write beat 2 without data");
      wr_beat1 = 1'b0;
    end
    // read data out: the beat that follows this edge
    rd_pipe = {rd_pipe[CL-1:0], 1'b0};
    for (b = CL; b > 0; b = b - 1) rd_addr[b] = rd_addr[b - 1];
    for (b = 2; b > 0; b = b - 1) begin
      beat_on[b] = beat_on[b - 1];
      beat_data[b] = beat_data[b - 1];
      beat_t[b] = beat_t[b - 1];
    end
    beat_on[0] = rd_pipe[CL - 1] || rd_pipe[CL];
    beat_data[0] = rd_pipe[CL] ? mem[rd_addr[CL] | 24'd1] : mem[rd_addr[CL - 1]];
    beat_t[0] = t_ps + CLK_OUT;
    // refresh interval (checked once the part is in service)
    if (mode_set && now - t_ref > 32'd8 * REFI + RFC) violate(2, "refresh interval above 8 x tREFI");
    if (!cke) violate(3, "CKE low (not supported)");
    else if (cmd[3] == 1'b0 && cmd != 4'b0111) begin   // a command other than NOP
      if (now - t_mrs < T_MRD && mode_set) violate(4, "command within tMRD of MRS");
      if (now - t_ref < RFC) violate(5, "command within tRFC of REFRESH");
      case (cmd)
        C_ACT: begin
          if (!mode_set) violate(6, "ACTIVE before initialisation");
          if (active[ba]) violate(7, "ACTIVE to an open bank");
          if (now - t_pre[ba] < RP) violate(8, "ACTIVE within tRP of PRECHARGE");
          if (now - t_act[ba] < RC) violate(9, "ACTIVE within tRC of ACTIVE");
          if (now - t_last_act < RRD && activates != 0) violate(10, "ACTIVE within tRRD");
          active[ba] = 1'b1;
          open_row[ba] = a;
          t_act[ba] = now;
          t_last_act = now;
          activates = activates + 32'd1;
        end
        C_READ, C_WRITE: begin
          if (!active[ba]) violate(11, "READ/WRITE to a closed bank");
          if (now - t_act[ba] < RCD) violate(12, "READ/WRITE within tRCD");
          if (a[10]) violate(13, "auto precharge (not supported)");
          if (cmd == C_READ) begin
            rd_pipe[0] = 1'b1;
            rd_addr[0] = {ba, open_row[ba], a[8:1], 1'b0};
            reads = reads + 32'd1;
          end else begin
            if (!dq_in_oe) violate(14, "WRITE without data");
            mem[{ba, open_row[ba], a[8:1], 1'b0}] <= merge(mem[{ba, open_row[ba], a[8:1], 1'b0}], dq_in, dqm);
            wr_beat1 = 1'b1;
            wr_addr1 = {ba, open_row[ba], a[8:1], 1'b1};
            t_wr_end[ba] = now + 32'd1;
            writes = writes + 32'd1;
          end
        end
        C_PRE: begin
          for (b = 0; b < 4; b = b + 1) begin
            if (a[10] || ba == b[1:0]) begin
              if (active[b] && now - t_act[b] < RAS) violate(15, "PRECHARGE within tRAS");
              if (active[b] && now - t_wr_end[b] < WRC) violate(16, "PRECHARGE within tWR");
              if (active[b]) t_pre[b] = now;
              active[b] = 1'b0;
            end
          end
        end
        C_REF: begin
          if (active != 4'd0) violate(17, "REFRESH with an open bank");
          for (b = 0; b < 4; b = b + 1) if (now - t_pre[b] < RP) violate(18, "REFRESH within tRP");
          if (!mode_set) begin
            if (now < INIT) violate(19, "REFRESH before the 100 us power-up wait");
            refs_at_init = refs_at_init == 2'd2 ? 2'd2 : refs_at_init + 2'd1;
          end
          t_ref = now;
        end
        C_MRS: begin
          if (active != 4'd0) violate(20, "MODE REGISTER SET with an open bank");
          if (refs_at_init != 2'd2) violate(21, "MODE REGISTER SET before two REFRESHes");
          if (a[2:0] != 3'b001 || a[3] || a[6:4] != CL) violate(22, "mode register: not BL2 sequential at this CL");
          mode_set = 1'b1;
          t_mrs = now;
        end
        default: ;
      endcase
    end
    end
  endtask
endmodule
