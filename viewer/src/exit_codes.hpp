#pragma once
// gpubridge-view's exit status, stable for scripts.
namespace gpubridge::viewer {
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;      // runtime failure (no frame in time, cannot save, no GL)
inline constexpr int kExitUsage = 2;        // bad command line
inline constexpr int kExitUnreachable = 3;  // wrong address, daemon not running, token refused
}  // namespace gpubridge::viewer
