// The executor's decode of a FIFO entry's index into the classes its `go` tests (command_exec.v),
// made when the entry is pushed and stored with it in the command FIFO (docs/gateware.md
// fmax-soc13): `go` then starts at the FIFO's output bits instead of a decode of the index behind
// the block RAM's clock-to-out. The 71-bit entry already takes five 256 x 16 block RAMs on the
// UP5K (80 bits), so the 7 bits ride in the spare 9. Include after spigpu_regs.vh.
localparam integer CLS_W = 7;
localparam integer CLS_VERTEX = 0, CLS_CLEAR = 1, CLS_DISPLAY = 2, CLS_FENCE = 3, CLS_MEMADDR = 4,
                   CLS_MEMDATA = 5, CLS_SHADOW = 6;
// clear_z: CLEAR_Z counts as a core command (the profile has a depth buffer); without one it is
// refused when it executes and is a plain entry
function automatic [CLS_W-1:0] cmd_class(input [6:0] idx, input clear_z);
  cmd_class[CLS_VERTEX]  = idx == `SPIGPU_REG_VERTEX;
  cmd_class[CLS_CLEAR]   = idx == `SPIGPU_REG_CLEAR || (clear_z && idx == `SPIGPU_REG_CLEAR_Z);
  cmd_class[CLS_DISPLAY] = idx == `SPIGPU_REG_FB_DISPLAY;
  cmd_class[CLS_FENCE]   = idx == `SPIGPU_REG_FENCE;
  cmd_class[CLS_MEMADDR] = idx == `SPIGPU_REG_MEM_ADDR;
  cmd_class[CLS_MEMDATA] = idx == `SPIGPU_REG_MEM_DATA;
  cmd_class[CLS_SHADOW]  = idx[6:5] == 2'b00 && reg_is_rw(idx);
endfunction
