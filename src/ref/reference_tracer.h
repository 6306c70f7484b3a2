// The CPU reference tracer: shaders/shared/trace.h's contract in double
// precision, written apart from the GPU tracer so that golden images and
// GPU-versus-CPU tests have an independent ground truth.
#pragma once

#include "scene/evaluate.h"
#include "scene/optics.h"
#include "scene/scene.h"
#include "scene/view.h"
#include "shared/trace.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace snell::ref {

struct ReferenceSettings {
  uint32_t width = 0, height = 0;  ///< pixels
  scene::View view;                ///< taken as given: rays come from it exactly as trace.h says
  glm::dvec3 background{scene::kDefaultBackground};  ///< linear RGB a miss sees
  uint32_t maxInterfaces = gpu::kDefaultMaxInterfaces;  ///< refractive faces one ray may cross
  uint32_t maxBends = gpu::kAllBends;  ///< boundaries that bend; later ones are crossed straight
  unsigned threads = 0;  ///< 0: std::thread::hardware_concurrency()
  /// When not empty: width * height primary rays, pixel i (row-major) tracing rays[i].
  std::vector<scene::Ray> rays;
  scene::Optics optics;  ///< Fresnel, reflections and their environment, as the GPU frame takes them
};

/// Per-pixel results, row-major, row 0 the top of the picture.
struct ReferenceImage {
  uint32_t width = 0, height = 0;
  std::vector<glm::dvec3> color;    ///< linear RGB
  std::vector<double> distance;     ///< the primary ray's first hit t (unit direction); +inf on a miss
  std::vector<int32_t> instance;    ///< index into Pose::items of the first hit; -1 on a miss
  std::vector<int32_t> primitive;   ///< triangle index within that item's shape; -1 on a miss
  std::vector<uint32_t> interfaces; ///< refractive faces crossed (refraction and TIR alike)
  std::vector<uint32_t> outcome;    ///< gpu::kOutcomeMiss, kOutcomeOpaque or kOutcomeInterfaceLimit
  /// The largest |R + T - 1| over the pixel's refracting boundaries, with T from
  /// the Fresnel transmission amplitudes (not 1 - R): energy bookkeeping's check.
  std::vector<double> energyError;
  /// Where a path that crossed glass ended on an opaque face with a base
  /// colour texture: that texture's UV (transformed); NaN otherwise.
  std::vector<glm::dvec2> landing;
  /// As TraceAov::shortestSegment: the shortest segment after leaving a surface; +inf where none.
  std::vector<double> shortestSegment;

  size_t index(uint32_t x, uint32_t y) const { return size_t(y) * width + x; }
};

/// Traces one ray through the centre of every pixel of the scene at `pose`.
/// Geometry is every pose item's triangles in world space (deforming items
/// through scene::deformOnCpu); triangles with a non-finite vertex or no area
/// are left out. Lights are the nodes that carry one; with none, a headlight
/// along the view's forward axis.
ReferenceImage renderReference(const scene::Scene& scene, const scene::Pose& pose, const ReferenceSettings& settings);

}  // namespace snell::ref
