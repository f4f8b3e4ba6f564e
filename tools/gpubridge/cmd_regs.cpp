// `gpubridge regs`: the register table from the one description in protocol/ (Markdown or JSON).
#include <cstdio>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "device_option.hpp"
#include "gpubridge/dmc1/command.hpp"
#include "gpubridge/protocol/register_doc.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "gpubridge/common/json_text.hpp"

namespace gpubridge::cli {
namespace {

// The DMC-1's command fields (its "registers" are the fields of one 64-bit command word).
int run_dmc1_fields(const GlobalOptions& g, bool markdown) {
  if (markdown) {
    std::fputs(dmc1::field_table_markdown().c_str(), stdout);
    return 0;
  }
  if (g.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& f : dmc1::fields())
      out.push_back({{"command", dmc1::to_string(f.kind)}, {"field", f.name}, {"lsb", f.lsb}, {"width", f.width},
                     {"signed", f.is_signed}, {"meaning", f.meaning}});
    std::puts(json_text(out, 2).c_str());
    return 0;
  }
  for (const auto& f : dmc1::fields())
    std::printf("%-10s %-15s bits %2u..%-2u %s\n", std::string(dmc1::to_string(f.kind)).c_str(), std::string(f.name).c_str(),
                f.lsb, f.lsb + f.width - 1, std::string(f.meaning).c_str());
  return 0;
}

int run_regs(const GlobalOptions& g, bool markdown, bool verilog, protocol::DeviceKind device) {
  if (device == protocol::DeviceKind::Dmc1) return run_dmc1_fields(g, markdown);
  using namespace protocol;
  if (verilog) {
    std::fputs(register_table_verilog().c_str(), stdout);
    return 0;
  }
  if (markdown) {
    std::fputs(register_table_markdown().c_str(), stdout);
    return 0;
  }
  if (g.json) {
    nlohmann::json out = nlohmann::json::array();
    for (const auto& r : register_table()) {
      nlohmann::json fields = nlohmann::json::array();
      for (const auto& f : r.fields) {
        if (f.width == 0) continue;
        nlohmann::json jf{{"name", f.name}, {"lsb", f.lsb}, {"width", f.width}, {"doc", f.doc}};
        if (!f.values.empty()) {
          for (const auto& v : f.values) jf["values"][std::string(v.name)] = v.value;
        }
        fields.push_back(jf);
      }
      out.push_back({{"index", r.index}, {"name", r.name}, {"reset", r.reset}, {"summary", r.summary}, {"fields", fields}});
    }
    std::puts(json_text(out, 2).c_str());
    return 0;
  }
  for (const auto& r : register_table())
    std::printf("0x%02X  %-12s %s\n", r.index, std::string(r.name).c_str(), std::string(r.summary).c_str());
  return 0;
}

}  // namespace

GPUBRIDGE_COMMAND("regs", 90, [](CLI::App& app, GlobalOptions& g, auto& runners) {
  auto* sub = app.add_subcommand("regs",
                                 "list the spigpu v1 registers (the table docs/protocol.md is generated from), or with "
                                 "--device dmc1 the DMC-1's command fields (docs/dmc1.md)");
  auto markdown = std::make_shared<bool>(false);
  auto verilog = std::make_shared<bool>(false);
  auto device = std::make_shared<protocol::DeviceKind>(protocol::DeviceKind::Spigpu);
  sub->add_flag("--markdown", *markdown, "print the Markdown tables used in docs/protocol.md (docs/dmc1.md for dmc1)");
  sub->add_flag("--verilog", *verilog, "print the Verilog header the gateware includes (gateware/rtl/soc/spigpu_regs.vh)")
      ->excludes(sub->get_option("--markdown"));
  add_device_option(sub, *device);
  runners.emplace_back(sub, [&g, markdown, verilog, device] {
    if (*verilog && *device != protocol::DeviceKind::Spigpu) {
      std::fputs("gpubridge regs: --verilog prints the spigpu register header; the DMC-1 has no gateware here\n", stderr);
      return 1;
    }
    return run_regs(g, *markdown, *verilog, *device);
  });
});

}  // namespace gpubridge::cli
