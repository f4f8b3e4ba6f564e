#pragma once
// Executes a typed command stream (a parsed trace or a built scene) on a Device in-process:
// register frames as link frames, uploads/readbacks through the memory fast path (same effect as
// MEM_ADDR/MEM_DATA), fences as "everything before has executed", register reads as read frames.
#include "gpubridge/common/result.hpp"
#include "gpubridge/protocol/command_stream.hpp"
#include "gpubridge/sim/device.hpp"

namespace gpubridge::sim {

// Errors name the command number and what was wrong (an upload beyond VRAM, ...); commands before
// it have executed.
Result<void> run_stream(Device& device, const protocol::CommandStream& stream);

}  // namespace gpubridge::sim
