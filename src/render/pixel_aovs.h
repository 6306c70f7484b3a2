// What a traced pixel found, beside its colour, in the forms a compositor
// reads: the hit's camera depth and face normal, its ids, the interfaces it
// crossed and what it cost. The CLI's EXR layers and the public API's
// Renderer::readAovs both come from here, from the GPU's per-pixel TraceAov
// or the reference tracer's hits.
#pragma once

#include "scene/evaluate.h"
#include "scene/scene.h"
#include "scene/view.h"
#include "shared/trace.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <functional>
#include <map>
#include <vector>

namespace snell::render {

/// What one pixel's trace found.
struct PixelHit {
  double distance;  ///< along the pixel's unit primary ray; < 0: missed
  uint32_t instance, primitive, interfaces, cost;
};

/// The GPU's per-pixel records as hits.
std::vector<PixelHit> pixelHits(const std::vector<gpu::TraceAov>& aov);

/// Camera-space depth along the view's axis of a hit `distance` along the
/// primary ray of pixel `pixel` (row-major) of a width x height view.
double cameraDepth(const scene::View& view, uint32_t width, uint32_t height, size_t pixel, double distance);

/// The unit world-space face normal of the triangles pixels hit, from each
/// draw item's vertices at a pose (deformed once per item, in double).
class FaceNormals {
 public:
  /// Positions of a shape as the host last wrote them (in its own buffers,
  /// scene::Shape::host, or kept ones): packed float triples, or null where
  /// the host wrote none (then a host shape's are unknown, and another's are
  /// its rest pose as snell deforms it).
  using HostPositions = std::function<const float*(int shape)>;

  FaceNormals(const scene::Scene& scene, const scene::Pose& pose, HostPositions hostPositions = {});
  /// Zero where the item, triangle or its vertices are unknown, or the face is degenerate.
  glm::vec3 of(uint32_t item, uint32_t triangle);

 private:
  struct Deformed {
    std::vector<glm::dvec3> positions;
    glm::dmat3 normalToWorld{1.0};
  };
  const scene::Scene& scene_;
  const scene::Pose& pose_;
  HostPositions hostPositions_;
  std::map<uint32_t, Deformed> items_;
};

}  // namespace snell::render
