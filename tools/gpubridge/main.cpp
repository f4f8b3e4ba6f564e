// gpubridge: the command-line tool (render, compare, traces, daemon client, board bring-up).
#include <algorithm>
#include <cstdio>
#include <iostream>

#include "command.hpp"
#include "gpubridge/common/log.hpp"
#include "gpubridge/version.hpp"

namespace gpubridge::cli {
std::vector<CommandSpec>& command_registry() {
  static std::vector<CommandSpec> registry;
  return registry;
}
}  // namespace gpubridge::cli

int main(int argc, char** argv) {
  using namespace gpubridge::cli;
  CLI::App app{"gpubridge: drive spigpu FPGA GPUs and the gpubridge simulator"};
  app.set_version_flag("--version", std::string("gpubridge ") + gpubridge::kVersion);
  app.require_subcommand(1);
  GlobalOptions global;
  app.add_flag("--json", global.json, "machine-readable JSON output")->configurable();
  app.add_option("--log-level", global.log_level, gpubridge::log_levels_text())
      ->check(CLI::IsMember(std::vector<std::string>(gpubridge::kLogLevels.begin(), gpubridge::kLogLevels.end())))
      ->capture_default_str();
  app.add_option("--connect", global.connect,
                 "the daemon the commands that talk to gpubridged use: unix:PATH or tcp:HOST:PORT (default: "
                 "unix:$XDG_RUNTIME_DIR/gpubridge/gpubridge.sock)");
  app.add_option("--token", global.token, "access token for a daemon that requires one (default: $GPUBRIDGE_TOKEN)");

  auto& registry = command_registry();
  std::sort(registry.begin(), registry.end(), [](const auto& a, const auto& b) { return a.order < b.order; });
  std::vector<std::pair<CLI::App*, Runner>> runners;
  for (auto& spec : registry) spec.setup(app, global, runners);
  // Global options may also follow the subcommand, at any depth (`gpubridge regs --json`,
  // `gpubridge reg read STATUS --connect unix:/tmp/gb.sock`).
  const auto fall_through = [](auto& self, CLI::App& parent) -> void {
    for (auto* sub : parent.get_subcommands([](CLI::App*) { return true; })) {
      sub->fallthrough();
      self(self, *sub);
    }
  };
  fall_through(fall_through, app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  gpubridge::init_logging(global.log_level);
  for (auto& [sub, run] : runners) {
    if (sub->parsed()) {
      const auto& daemon = global.daemon_commands;
      if ((app.count("--connect") || app.count("--token")) &&
          std::find(daemon.begin(), daemon.end(), sub) == daemon.end()) {
        std::string names;
        for (const auto* d : daemon)
          names += (names.empty() ? "" : ", ") + (d->get_parent() == &app ? "" : d->get_parent()->get_name() + " ") +
                   d->get_name();
        std::fprintf(stderr, "gpubridge %s: --connect and --token only apply to the commands that talk to gpubridged (%s)\n",
                     sub->get_name().c_str(), names.c_str());
        return 2;
      }
      try {
        return run();
      } catch (const std::exception& e) {
        std::fprintf(stderr, "gpubridge %s: %s\n", sub->get_name().c_str(), e.what());
        return 1;
      }
    }
  }
  std::fprintf(stderr, "gpubridge: no command given; see gpubridge --help\n");
  return 2;
}
