// Mirrors shaders/common/scene.glsl's reads and the BVH traversal of shaders/comp/trace.comp and
// shaders/comp/bvh/bvh_node.glsl: world-space triangles in double and a median-split BVH, built apart
// from the GPU's so that a wrong upload or traversal shows as a difference.
#pragma once

#include "ref/sah_bvh.h"
#include "ref/shading.h"
#include "scene/evaluate.h"
#include "scene/scene.h"
#include "scene/view.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace snell::ref::detail {

inline double maxAbs(const glm::dvec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

/// The unit vector along v, or zero when v has no usable length.
inline glm::dvec3 unitOrZero(const glm::dvec3& v) {
  double length = glm::length(v);
  return length > 0.0 && std::isfinite(length) ? v / length : glm::dvec3(0.0);
}

/// What shading needs of a triangle; intersection reads the compact Corners.
struct TriangleData {
  glm::dvec3 v[3];
  glm::dvec3 n[3];   // world, unit, or zero where the shape has none
  glm::dvec2 uv[2][3];  // TEXCOORD_0 and _1, (0, 0) where missing
  glm::dvec3 ng;     // unit geometric normal
  double density[2] = {0.0, 0.0};  // 0.5 log2(UV area / world area) per UV set (trace.h: Textures)
  double curvature = 0.0;          // signed: the mean turn of the unit vertex normals along its edges, > 0 bulging to ng's side
  int32_t item = -1, primitive = -1;
  int material = -1;
  bool singleSided = false;  // its back is never hit: a single-sided material that is not glass
};

// The corners exactly as every triangle sharing them sees them: the
// watertight test needs a shared vertex to be bit-for-bit the same in each.
struct Corners {
  glm::dvec3 v[3];
  bool singleSided = false;  // rays pass its back (TriangleData::singleSided)
};

struct BvhNode {
  Aabb box;
  uint32_t first = 0;  // leaf: first triangle; internal: first of two adjacent children
  uint32_t count = 0;  // triangles in a leaf; 0 for an internal node
};

struct Hit {
  double t = kInfinity;
  uint32_t triangle = std::numeric_limits<uint32_t>::max();
  double b1 = 0.0, b2 = 0.0;
  bool found() const { return triangle != std::numeric_limits<uint32_t>::max(); }
};

class PreparedScene {
 public:
  PreparedScene(const scene::Scene& scene, const scene::Pose& pose, const scene::View& view);

  /// The closest triangle with tMin < t, other than `excluded`. Equal
  /// distances go to the triangle stored first, so that the answer does not
  /// depend on the traversal order (nor on the thread count). Single-sided
  /// faces seen from behind are passed, by every ray.
  Hit intersect(const glm::dvec3& origin, const glm::dvec3& direction, double tMin, uint32_t excluded) const;

  const TriangleData& triangle(uint32_t i) const { return data_[i]; }
  const ResolvedMaterial& material(int index) const {
    return index >= 0 && size_t(index) < materials_.size() ? materials_[size_t(index)] : defaultMaterial_;
  }
  const std::vector<ResolvedLight>& lights() const { return lights_; }
  double size() const { return size_; }

 private:
  void addItem(const scene::Scene& scene, const scene::DrawItem& item, int32_t itemIndex);
  void buildBvh();

  std::vector<TriangleData> data_;
  std::vector<Corners> corners_;
  std::vector<BvhNode> nodes_;
  std::vector<LinearTexture> textures_;
  std::vector<ResolvedMaterial> materials_;
  ResolvedMaterial defaultMaterial_;  // white, opaque
  std::vector<ResolvedLight> lights_;
  double size_ = 0.0;  // the largest extent of the geometry's bounds
};

}  // namespace snell::ref::detail
