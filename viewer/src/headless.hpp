#pragma once
// --offscreen without any display: no GL at all. Takes the N-th frame from the source, saves its
// pixels, prints the summary. Returns the process exit code.
#include "gpubridge/viewer/frame_source.hpp"
#include "gpubridge/viewer/options.hpp"

namespace gpubridge::viewer {

int run_headless(const Options& options, FrameSource& source);

// Shared by both runners: the message for a source that failed, one line.
std::string failure_message(const SourceStatus& s);

}  // namespace gpubridge::viewer
