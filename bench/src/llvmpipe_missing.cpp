// Built when libEGL/libOpenGL are missing: the bench reports why the llvmpipe rows are absent.
#include "llvmpipe_runner.hpp"

namespace gpubridge::bench {

Result<LlvmpipeResult> run_llvmpipe(const std::vector<Scene>&, const std::vector<ReferenceFrame>&, unsigned,
                                    const FrameBudget&, bool) {
  return make_error("llvmpipe peer not built: libEGL/libOpenGL development files were missing at configure time "
                    "(install libegl-dev libopengl-dev libgl1-mesa-dri and reconfigure)");
}

}  // namespace gpubridge::bench
