// Link integrity (docs/protocol.md section 4): the CRC-32 of every complete frame's 9 MOSI bytes
// since the last LINK_CHECK / LINK_CTRL write (frames to index 0x13 and 0x14 excluded), the
// LINK_STATUS counters and the strict-mode group state that holds, releases or discards queued
// writes in the command FIFO.
//
// The CRC is the reflected zlib CRC-32, folded one bit per clock: a byte takes 8 core clocks and
// bytes arrive at most every 8 SCK periods, so the engine keeps up at any core/SCK ratio >= 1.
// Bytes of an aborted frame are folded too; that is invisible because a group with an aborted frame
// fails its check whatever its CRC (section 4).
module link_integrity #(
  parameter DSP = 0             // 1: the LINK_STATUS counters in two SB_MAC16s (dsp_counter)
) (
  input  wire        clk,
  input  wire        rst,          // power-on or RESET: counters 0, STRICT 0
  // MOSI bytes from the SPI slave
  input  wire        byte_valid,
  input  wire        byte_first,
  input  wire [7:0]  byte_data,
  input  wire        frame_valid,  // a frame completed (its index is frame_idx)
  input  wire [6:0]  frame_idx,
  input  wire        frame_abort,  // a frame was aborted: the group fails
  input  wire        drop_overflow,// a queued write was dropped for overflow: the group fails
  // validated immediate writes
  input  wire        check_strobe, // LINK_CHECK with the host's CRC
  input  wire [31:0] check_crc,
  input  wire        ctrl_strobe,  // LINK_CTRL with STRICT (already refused when the profile lacks it)
  input  wire        ctrl_strict,
  // to the command FIFO and the error flags
  output reg         strict,
  output reg         discarding,
  output reg         release_held, // one cycle: a check matched, held writes may execute
  output reg         discard_held, // one cycle: held writes are dropped
  output reg         err_link_crc, // one cycle: a check failed
  output wire [63:0] link_status
);
  reg [31:0] crc;          // running register (the host's value is its complement)
  reg [7:0]  byte_sh;      // byte being folded, LSB first
  reg [3:0]  fold;         // bits left to fold
  reg        skip;         // the current frame is a LINK_CHECK / LINK_CTRL frame
  wire [23:0] frames;
  wire [15:0] groups_ok, groups_bad;
  reg        group_failed;

  wire first_excluded = byte_data[6:0] == 7'h13 || byte_data[6:0] == 7'h14;
  wire frame_excluded = frame_idx == 7'h13 || frame_idx == 7'h14;
  wire crc_fb = crc[0] ^ byte_sh[0];
  wire match = ~crc == check_crc && !group_failed;

  assign link_status = {groups_bad, groups_ok, 7'd0, discarding, frames};

  // the counters (dsp_counter: clear wins over count): FRAMES since the last LINK_CHECK / LINK_CTRL,
  // GROUPS_OK / GROUPS_BAD since power-on or RESET
  wire checked   = check_strobe && !discarding && !ctrl_strobe;
  wire restarted = rst || ctrl_strobe || checked;
  wire [15:0] frames_hi;
  dsp_counter #(.DSP(DSP), .WIDE(1)) u_frames (
    .clk(clk), .ld_top(1'b0), .d_top(16'd0), .inc_top(1'b0), .ld_bot(restarted), .d_bot(16'd0),
    .inc_bot(frame_valid && !frame_excluded),
    .q_top(frames_hi), .q_bot(frames[15:0]));
  assign frames[23:16] = frames_hi[7:0];
  dsp_counter #(.DSP(DSP), .WIDE(0)) u_groups (
    .clk(clk), .ld_top(rst), .d_top(16'd0), .inc_top(checked && !match), .ld_bot(rst), .d_bot(16'd0),
    .inc_bot(checked && match),
    .q_top(groups_bad), .q_bot(groups_ok));
  wire unused_hi = &{1'b0, frames_hi[15:8]};

  always @(posedge clk) begin
    release_held <= 1'b0;
    discard_held <= 1'b0;
    err_link_crc <= 1'b0;
    if (rst) begin
      crc <= 32'hFFFFFFFF;
      fold <= 4'd0;
      byte_sh <= 8'd0;
      skip <= 1'b0;
      group_failed <= 1'b0;
      strict <= 1'b0;
      discarding <= 1'b0;
    end else begin
      if (fold != 4'd0) begin
        crc <= {1'b0, crc[31:1]} ^ (crc_fb ? 32'hEDB88320 : 32'h0);
        byte_sh <= {1'b0, byte_sh[7:1]};
        fold <= fold - 4'd1;
      end
      if (byte_valid) begin
        if (byte_first) skip <= first_excluded;
        if (!(byte_first ? first_excluded : skip)) begin
          byte_sh <= byte_data;
          fold <= 4'd8;
        end
      end
      if (frame_abort || drop_overflow) group_failed <= 1'b1;
      if (ctrl_strobe) begin
        strict <= ctrl_strict;
        discarding <= 1'b0;
        discard_held <= 1'b1;
        crc <= 32'hFFFFFFFF;
        fold <= 4'd0;
        group_failed <= 1'b0;
      end else if (check_strobe && !discarding) begin
        if (match) begin
          release_held <= 1'b1;
        end else begin
          err_link_crc <= 1'b1;
          if (strict) begin
            discard_held <= 1'b1;
            discarding <= 1'b1;
          end
        end
        crc <= 32'hFFFFFFFF;
        fold <= 4'd0;
        group_failed <= 1'b0;
      end
    end
  end
endmodule
