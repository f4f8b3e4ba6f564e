#pragma once
// Umbrella header of the host geometry library (gpubridge_geometry).
#include "gpubridge/geometry/clip.hpp"
#include "gpubridge/geometry/convert.hpp"
#include "gpubridge/geometry/encode.hpp"
#include "gpubridge/geometry/math.hpp"
#include "gpubridge/geometry/pipeline.hpp"
