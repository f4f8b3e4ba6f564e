#pragma once
// A bench scene on the simulator device, written as a client would write it (register frames):
// what `gpubridge bench accuracy`'s throughput rows time and bench/sim/scene_throughput replays.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "gpubridge/bench/scenes.hpp"
#include "gpubridge/common/result.hpp"
#include "gpubridge/sim/device.hpp"
#include "gpubridge/sim/options.hpp"

namespace gpubridge::bench {

// A device (16 MiB of VRAM) with the scene's colour and depth buffers and, for textured scenes,
// the probe texture and its registers set up.
Result<std::unique_ptr<sim::Device>> make_scene_device(const Scene& s, const sim::AccuracyKnobs& knobs,
                                                       unsigned threads);
// CLEAR + CLEAR_Z + `st` + triangles [0, count) of the scene as one batch of wire frames.
std::vector<std::uint8_t> scene_frame_bytes(const Scene& s, const geometry::RenderState& st, std::size_t count);

}  // namespace gpubridge::bench
