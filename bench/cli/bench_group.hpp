#pragma once
// The `gpubridge bench` command group. Each bench lives in its own bench/cli/cmd_bench_*.cpp and
// attaches its subcommand to the group returned here (`bench accuracy`, `bench daemon`, `bench usb`, ...); the
// group is created by whichever command registers first.
#include <CLI/CLI.hpp>

namespace gpubridge::cli {

inline CLI::App* bench_group(CLI::App& app) {
  for (CLI::App* sub : app.get_subcommands([](CLI::App* s) { return s->get_name() == "bench"; })) return sub;
  CLI::App* group = app.add_subcommand("bench", "benchmarks: simulator speed and accuracy, daemon, USB links");
  group->require_subcommand(1);
  return group;
}

}  // namespace gpubridge::cli
