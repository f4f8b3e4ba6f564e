#pragma once
// Renders the register table as Markdown for docs/protocol.md (`gpubridge regs --markdown`) and as
// the Verilog header the gateware's register file includes (`gpubridge regs --verilog`, written to
// gateware/rtl/soc/spigpu_regs.vh), so the device, the docs and the host share one table.
#include <string>

namespace gpubridge::protocol {
std::string register_table_markdown();
std::string register_table_verilog();
}
