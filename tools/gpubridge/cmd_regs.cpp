// `gpubridge regs`: the register table from the one description in protocol/ (Markdown or JSON).
#include <cstdio>

#include <nlohmann/json.hpp>

#include "command.hpp"
#include "gpubridge/protocol/register_doc.hpp"
#include "gpubridge/protocol/registers.hpp"
#include "gpubridge/common/json_text.hpp"

namespace gpubridge::cli {
namespace {

int run_regs(const GlobalOptions& g, bool markdown) {
  using namespace protocol;
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
  auto* sub = app.add_subcommand("regs", "list the spigpu v1 registers (the table docs/protocol.md is generated from)");
  auto markdown = std::make_shared<bool>(false);
  sub->add_flag("--markdown", *markdown, "print the Markdown tables used in docs/protocol.md");
  runners.emplace_back(sub, [&g, markdown] { return run_regs(g, *markdown); });
});

}  // namespace gpubridge::cli
