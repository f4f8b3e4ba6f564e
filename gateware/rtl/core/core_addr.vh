// Byte address arithmetic of the core, shared by the stages (included inside a module that has
// the parameter ADDR_W: the byte address bits the profile computes exactly). An address at or
// beyond 2^ADDR_W is beyond every VRAM the profile has (up5k: 128 KiB, ecp5: its SDRAM): it
// becomes the word address 0x3FFFFFFF, which the soc's arbiter drops (writes) or reads as 0, with
// ERR_MEM_RANGE, as docs/protocol.md section 6 asks.
localparam integer BA_W = (ADDR_W > 24) ? ADDR_W : 24;  // sum bits: base part and 24-bit offsets

// {word address, byte lane} of byte b16 * 16 + off
function [31:0] byte_addr(input [27:0] b16, input [23:0] off);
  reg [BA_W:0] s;
  begin
    s = {{(BA_W + 1 - ADDR_W){1'b0}}, b16[ADDR_W-5:0], 4'b0} + {{(BA_W - 23){1'b0}}, off};
    byte_addr = ((b16 >> (ADDR_W - 4)) != 28'd0 || (s >> ADDR_W) != 0) ? 32'hFFFFFFFF
                                                                       : 32'(s[ADDR_W-1:0]);
  end
endfunction
