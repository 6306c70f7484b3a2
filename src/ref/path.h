// Mirrors shaders/common/path.glsl (tracePath, tracePixel): the refraction rules of
// shaders/shared/trace.h walked in double, one pixel at a time, as the GPU's ground truth.
#pragma once

#include "ref/prepared_scene.h"
#include "ref/reference_tracer.h"
#include "ref/shading.h"
#include "shared/trace.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <limits>

namespace snell::ref::detail {

struct PixelResult {
  glm::dvec3 color{0.0};
  double distance = kInfinity;
  int32_t instance = -1, primitive = -1;
  uint32_t interfaces = 0;
  uint32_t outcome = gpu::kOutcomeMiss;
  double energyError = 0.0;
  glm::dvec2 landing{std::numeric_limits<double>::quiet_NaN()};
  double shortestSegment = kInfinity;  ///< as TraceAov::shortestSegment
};

PixelResult trace(const PreparedScene& prepared, const glm::dvec3& origin, const glm::dvec3& d, double width,
                  double spread, const ReferenceSettings& settings);

}  // namespace snell::ref::detail
