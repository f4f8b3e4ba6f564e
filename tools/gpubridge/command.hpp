#pragma once
// Subcommands of the `gpubridge` CLI. Each cmd_*.cpp defines one command group and registers it
// with GPUBRIDGE_COMMAND; main.cpp only parses and dispatches. Commands return the process exit
// code (0 ok, 1 failure, 2 usage error) and print errors as one line naming what and what to do.
#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace gpubridge::cli {

struct GlobalOptions {
  bool json = false;          // --json: machine-readable output on stdout
  std::string log_level = "warn";
  std::string connect;        // --connect unix:PATH|tcp:HOST:PORT (commands that talk to gpubridged)
  std::string token;          // --token (else $GPUBRIDGE_TOKEN)
  // The subcommands --connect and --token apply to (registered by add_client_options); given
  // with any other command they are a usage error rather than silently ignored.
  std::vector<const CLI::App*> daemon_commands;
};

// A command's setup adds its subcommand(s) to the app and stores a runner in *run that is
// invoked when that subcommand was selected.
using Runner = std::function<int()>;
struct CommandSpec {
  std::string name;
  int order;  // position in --help
  std::function<void(CLI::App& app, GlobalOptions& global, std::vector<std::pair<CLI::App*, Runner>>& runners)> setup;
};

std::vector<CommandSpec>& command_registry();

struct CommandRegistrar {
  explicit CommandRegistrar(CommandSpec spec) { command_registry().push_back(std::move(spec)); }
};

#define GPUBRIDGE_CONCAT_INNER(a, b) a##b
#define GPUBRIDGE_CONCAT(a, b) GPUBRIDGE_CONCAT_INNER(a, b)
#define GPUBRIDGE_COMMAND(...) \
  static ::gpubridge::cli::CommandRegistrar GPUBRIDGE_CONCAT(gpubridge_cmd_, __LINE__){::gpubridge::cli::CommandSpec{__VA_ARGS__}}

}  // namespace gpubridge::cli
