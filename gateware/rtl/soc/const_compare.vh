// x >= c for a constant c (included inside a module): gates from c's bits, lowest first. yosys maps a
// magnitude comparison to a carry chain, a logic cell per bit on the iCE40 even when c is constant;
// this form leaves ABC a few LUTs (docs/gateware.md, fit-soc4). x up to 16 bits, c below 2^16.
function automatic ge_const(input [15:0] x, input integer c);
  integer i;
  reg r;
  begin
    r = 1'b1;
    for (i = 0; i < 16; i = i + 1) r = c[i] ? (x[i] && r) : (x[i] || r);
    ge_const = r;
  end
endfunction
