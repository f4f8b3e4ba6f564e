#pragma once
// Renders the register table as Markdown for docs/protocol.md (`gpubridge regs --markdown`).
#include <string>

namespace gpubridge::protocol {
std::string register_table_markdown();
}
