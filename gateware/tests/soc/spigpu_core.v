// TEMPORARY (gw-soc branch only, until gw-core's render core is merged): a render core that accepts
// every command and draws nothing, so the SoC can be co-simulated with streams that need no rendering.
/* verilator lint_off UNUSEDPARAM */
module spigpu_core #(
  parameter PROFILE = 0,
  parameter [7:0] FEATURES = 8'h3F,
  parameter MAX_WIDTH = 1024,
  parameter MAX_HEIGHT = 1024
) (
  input  wire         clk,
  input  wire         rst,
  input  wire         cmd_valid,
  output wire         cmd_ready,
  input  wire [1:0]   cmd_op,
  input  wire [31:0]  cmd_tri_mode,
  input  wire [27:0]  cmd_tex_base,
  input  wire [17:0]  cmd_tex_fmt,
  input  wire [43:0]  cmd_scissor,
  input  wire [27:0]  cmd_fb_draw,
  input  wire [27:0]  cmd_fb_z,
  input  wire [1:0]   cmd_fb_format,
  input  wire [10:0]  cmd_fb_width,
  input  wire [10:0]  cmd_fb_height,
  input  wire [31:0]  cmd_clear_color,
  input  wire [23:0]  cmd_clear_depth,
  input  wire [183:0] cmd_v0,
  input  wire [183:0] cmd_v1,
  input  wire [183:0] cmd_v2,
  output wire         core_idle,
  output wire         mem_req_valid,
  input  wire         mem_req_ready,
  output wire         mem_req_we,
  output wire [29:0]  mem_req_addr,
  output wire [31:0]  mem_req_wdata,
  output wire [3:0]   mem_req_be,
  input  wire         mem_rsp_valid,
  input  wire [31:0]  mem_rsp_rdata,
  output wire [31:0]  perf_busy_cycles
);
  assign cmd_ready = 1'b1;
  assign core_idle = 1'b1;
  assign mem_req_valid = 1'b0;
  assign mem_req_we = 1'b0;
  assign mem_req_addr = 30'd0;
  assign mem_req_wdata = 32'd0;
  assign mem_req_be = 4'd0;
  assign perf_busy_cycles = 32'd0;
  wire unused_ok = &{1'b0, clk, rst, cmd_valid, cmd_op, cmd_tri_mode, cmd_tex_base, cmd_tex_fmt, cmd_scissor,
                     cmd_fb_draw, cmd_fb_z, cmd_fb_format, cmd_fb_width, cmd_fb_height, cmd_clear_color,
                     cmd_clear_depth, cmd_v0, cmd_v1, cmd_v2, mem_req_ready, mem_rsp_valid, mem_rsp_rdata};
endmodule
/* verilator lint_on UNUSEDPARAM */
