// Per-pixel hits as depth, normals and ids (see pixel_aovs.h).
#include "render/pixel_aovs.h"

#include <algorithm>
#include <cmath>

namespace snell::render {

std::vector<PixelHit> pixelHits(const std::vector<gpu::TraceAov>& aov) {
  std::vector<PixelHit> hits(aov.size());
  for (size_t p = 0; p < aov.size(); ++p) {
    const gpu::TraceAov& a = aov[p];
    hits[p] = {a.instance == gpu::kNoHit ? -1.0 : double(a.distance), a.instance, a.primitive, a.interfaces,
               a.nodeVisits};
  }
  return hits;
}

// The trace's distance is along each pixel's unit ray (trace.h: Rays); depth
// is its part along the view's axis.
double cameraDepth(const scene::View& view, uint32_t width, uint32_t height, size_t pixel, double distance) {
  if (view.orthographic) return distance;
  double w = width, h = height;
  double x = double(pixel % width), y = double(pixel / width);
  double sx = (2.0 * (x + 0.5) / w - 1.0) * view.halfHeight * w / h + view.shift.x;
  double sy = (1.0 - 2.0 * (y + 0.5) / h) * view.halfHeight + view.shift.y;
  return distance / std::sqrt(1.0 + sx * sx + sy * sy);
}

FaceNormals::FaceNormals(const scene::Scene& scene, const scene::Pose& pose, HostPositions hostPositions)
    : scene_(scene), pose_(pose), hostPositions_(std::move(hostPositions)) {}

glm::vec3 FaceNormals::of(uint32_t item, uint32_t triangle) {
  if (item >= pose_.items.size()) return glm::vec3(0.0f);
  const scene::DrawItem& drawn = pose_.items[item];
  const scene::Shape& shape = scene_.shapes[size_t(drawn.shape)];
  auto [at, fresh] = items_.try_emplace(item);
  Deformed& d = at->second;
  if (fresh) {
    const float* xyz = hostPositions_ ? hostPositions_(drawn.shape) : nullptr;
    if (xyz || shape.host) {
      for (size_t v = 0; xyz && v < shape.vertexCount(); ++v) {
        d.positions.emplace_back(xyz[3 * v], xyz[3 * v + 1], xyz[3 * v + 2]);
      }
    } else {
      std::vector<glm::dvec3> normals;
      scene::deformOnCpu(drawn, d.positions, normals);
    }
    d.normalToWorld = glm::transpose(glm::inverse(glm::dmat3(drawn.world)));
  }
  const std::vector<uint32_t>& indices = shape.indices;
  const std::vector<glm::dvec3>& p = d.positions;
  if (3 * size_t(triangle) + 2 >= indices.size()) return glm::vec3(0.0f);
  uint32_t i0 = indices[3 * triangle], i1 = indices[3 * triangle + 1], i2 = indices[3 * triangle + 2];
  if (std::max({i0, i1, i2}) >= p.size()) return glm::vec3(0.0f);
  glm::dvec3 n = d.normalToWorld * glm::cross(p[i1] - p[i0], p[i2] - p[i0]);
  double length = glm::length(n);
  return length > 0.0 && std::isfinite(length) ? glm::vec3(n / length) : glm::vec3(0.0f);
}

}  // namespace snell::render
