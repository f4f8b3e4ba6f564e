#pragma once
// gpubridge-demo's shared pieces: choosing examples, the fitting options of the command line, how
// a choice is printed, and the `fit` command (each example on each board profile, with the
// predicted frame rate).
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gpubridge/common/result.hpp"
#include "gpubridge/examples/example.hpp"

namespace gpubridge::demo {

// Prints "gpubridge-demo: MSG" on stderr and returns `code`.
int fail(const std::string& msg, int code = 1);

// The named examples (all for none or "all"); an unknown name is an error listing the known ones.
Result<std::vector<std::unique_ptr<examples::Example>>> select(const std::vector<std::string>& names,
                                                               const examples::ExampleParams& params = {});

// --size, --format, --no-depth, --without as given.
struct FitOptions {
  std::string size, format;
  bool no_depth = false;
  std::vector<std::string> without;
  Result<examples::FitRequest> request() const;
};

// The device of a board profile in configs/boards (or $GPUBRIDGE_CONFIG_DIR/boards), as its
// emulation presents it.
Result<examples::DeviceCaps> board_device(const std::string& name);

nlohmann::json fit_json(const examples::Fit& fit);
// "tetrahedron: 320x240 ..." and a "gave up:" line per item.
void print_fit(const std::string& example, const examples::Fit& fit);

int run_fit(const std::vector<std::string>& names, const std::vector<std::string>& boards, const FitOptions& options,
            bool timing, bool markdown, bool json);

}  // namespace gpubridge::demo
