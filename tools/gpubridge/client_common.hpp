#pragma once
// Helpers shared by the daemon-client commands (cmd_client.cpp, cmd_bench_daemon.cpp):
// connecting with the global --connect/--token options, progress bars, number parsing.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "command.hpp"
#include "gpubridge/client/client.hpp"

namespace gpubridge::cli {

struct ClientOptions {
  unsigned timeout_ms = 10000;
};

// Marks a subcommand as one that talks to the daemon (the global --connect and --token apply to
// it) and adds its --timeout.
void add_client_options(CLI::App* sub, GlobalOptions& g, ClientOptions& o);
// Connects and handshakes; errors already name the address and what to do.
Result<client::Client> open_client(const GlobalOptions& g, const ClientOptions& o, const std::string& name);
// Prints "gpubridge CMD: message" on stderr and returns 1.
int fail(const char* command, const std::string& message);
// Parses decimal or 0x-hex unsigned numbers; nullopt on anything else.
std::optional<std::uint64_t> parse_number(const std::string& text);

// A progress bar on stderr, drawn only when stderr is a terminal and JSON output is off.
class ProgressBar {
 public:
  ProgressBar(std::string label, bool enabled);
  ~ProgressBar();
  void update(std::uint64_t done, std::uint64_t total);

 private:
  std::string label_;
  bool enabled_;
  int last_percent_ = -1;
};

}  // namespace gpubridge::cli
