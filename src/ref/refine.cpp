// The refine pass's two stages on the CPU (see shaders/comp/refine.comp).
#include "ref/refine.h"

#include <stdexcept>

namespace snell::ref {

void refineOnCpu(const scene::Refinement& refinement, const std::vector<glm::dvec3>& cage,
                 std::vector<glm::dvec3>& positions, std::vector<glm::dvec3>& normals) {
  if (cage.size() != refinement.cageVertices) {
    throw std::invalid_argument("refine: " + std::to_string(cage.size()) + " cage vertices for a cage of " +
                                std::to_string(refinement.cageVertices));
  }
  // The refine stage: each refined vertex over the cage.
  const scene::Stencils& s = refinement.refine;
  std::vector<glm::dvec3> refined(refinement.refinedVertices, glm::dvec3(0.0));
  for (size_t r = 0; r < refined.size(); ++r) {
    for (uint32_t k = s.offsets[r]; k < s.offsets[r + 1]; ++k) refined[r] += double(s.weights[k]) * cage[s.indices[k]];
  }
  // The limit stage: each vertex of the shape.
  const bool limitSurface = refinement.limitSurface;
  const bool limitNormals = refinement.normals == scene::SubdivisionNormals::Limit;
  positions.resize(refinement.vertexOf.size());
  normals.resize(refinement.vertexOf.size());
  for (size_t v = 0; v < refinement.vertexOf.size(); ++v) {
    const uint32_t r = refinement.vertexOf[v];
    glm::dvec3 p = refined[r], n(0.0);
    if (limitSurface || limitNormals) {
      glm::dvec3 limit(0.0), t1(0.0), t2(0.0);
      for (uint32_t k = refinement.limit.offsets[r]; k < refinement.limit.offsets[r + 1]; ++k) {
        const glm::dvec3& q = refined[refinement.limit.indices[k]];
        limit += double(refinement.limitWeights[3 * k]) * q;
        t1 += double(refinement.limitWeights[3 * k + 1]) * q;
        t2 += double(refinement.limitWeights[3 * k + 2]) * q;
      }
      if (limitSurface) p = limit;
      if (limitNormals) n = glm::cross(t1, t2);
    }
    if (!(glm::dot(n, n) > 0.0)) {
      const scene::Stencils& around = refinement.around;
      for (uint32_t k = around.offsets[r]; k < around.offsets[r + 1]; ++k) {
        const uint32_t* c = &refinement.triangleCorners[3 * size_t(around.indices[k])];
        n += glm::cross(refined[c[1]] - refined[c[0]], refined[c[2]] - refined[c[0]]);
      }
    }
    const double length = glm::length(n);
    normals[v] = length > 0.0 ? n / length : glm::dvec3(0.0, 0.0, 1.0);
    positions[v] = p;
  }
}

}  // namespace snell::ref
