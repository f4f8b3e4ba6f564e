#pragma once
// The demo scenes of issue 7, one per seed, all procedural. Each example draws frames through the
// drawing API, so the same code renders on the in-process simulator or streams to a daemon.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "gpubridge/common/result.hpp"
#include "gpubridge/draw/context.hpp"
#include "gpubridge/examples/fit.hpp"

namespace gpubridge::examples {

struct ExampleInfo {
  std::string name;         // command-line name ("tetrahedron")
  std::string seed;         // the seed it illustrates ("DMC-1")
  std::string description;  // one line
};

class Example {
 public:
  virtual ~Example() = default;
  virtual ExampleInfo info() const = 0;
  // What the example would like from a device that has `features` (fit.hpp: kBlend, ...), and
  // what it holds on to longest when video memory is short.
  virtual Wants wants(std::uint16_t features) const = 0;
  // The configuration setup() and frame() follow: the one configure() chose, or, until then, the
  // large one (everything the example wants, on the default simulator).
  const Fit& config() const;
  void configure(Fit fit) { fit_ = std::move(fit); }
  // Framebuffer size/format and buffers of the configuration.
  draw::ContextOptions options() const { return config().context; }
  // Once per context: textures and meshes (calling it again starts over, for a new context).
  virtual Result<void> setup(draw::Context& ctx) = 0;
  // Draws frame `n` (clears included), without swapping. Frame n is a pure function of n.
  virtual Result<void> frame(draw::Context& ctx, unsigned n) = 0;
  // The frames with golden images, ascending; kGoldenFrame first (examples that change from frame
  // to frame by design, like the temporal dither, add the following ones).
  virtual std::vector<unsigned> golden_frames() const;

 private:
  mutable std::optional<Fit> fit_;
};

// Parameters of the examples that take one (gpubridge-demo --cordic-iterations).
struct ExampleParams {
  unsigned cordic_iterations = 8;  // torus-cordic: shift-and-add steps per rotation, 4..16
};

// Fits the example to `device` (honouring `request`) and configures it with the result.
Result<Fit> configure(Example& ex, const DeviceCaps& device, const FitRequest& request = {});

// Every example, in presentation order.
std::vector<std::unique_ptr<Example>> make_examples(const ExampleParams& params = {});
// nullptr for an unknown name.
std::unique_ptr<Example> make_example(std::string_view name, const ExampleParams& params = {});
std::vector<std::string> example_names();

// The frame each example's golden image shows.
inline constexpr unsigned kGoldenFrame = 12;

// setup, then frames first..first+count-1, swapping after each and calling after_swap(n).
Result<void> run_frames(Example& ex, draw::Context& ctx, unsigned first, unsigned count,
                        const std::function<Result<void>(unsigned)>& after_swap = {});

}  // namespace gpubridge::examples
