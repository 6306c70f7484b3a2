// Bounding boxes and the surface area heuristic on the CPU, in double: the
// yardstick a GPU-built BVH is measured against (binned SAH, Wald 2007).
#pragma once

#include <glm/glm.hpp>

#include <array>
#include <limits>
#include <vector>

namespace snell::ref {

/// An axis-aligned box; the default one is empty (lo > hi) and grows by extend().
struct Aabb {
  glm::dvec3 lo{std::numeric_limits<double>::infinity()};
  glm::dvec3 hi{-std::numeric_limits<double>::infinity()};

  void extend(const glm::dvec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void extend(const Aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  /// Neither empty nor holding a NaN or infinite corner.
  bool valid() const;
  glm::dvec3 centroid() const { return 0.5 * (lo + hi); }
};

/// 2 (xy + yz + zx); 0 for an empty box.
double surfaceArea(const Aabb& box);

/// Sum of SA(internal) / SA(root) over the internal boxes (the root's own
/// box among them, adding 1) plus the same over the leaf boxes: the SAH cost with Ct = 1 per internal node and Ci = 1 per
/// primitive, for trees with one primitive per leaf. A GPU tree downloaded
/// node by node is priced with the same formula as binnedSahCost's own tree.
/// A root of zero area (every box flat on a line or a point) costs 0.
double sahCost(const std::vector<Aabb>& internalBoxes, const std::vector<Aabb>& leafBoxes, const Aabb& root);

/// The same for a tree brought back from the GPU: boxes as six floats (lo
/// xyz, hi xyz), the root's box first among the internal ones.
double sahCost(const std::vector<std::array<float, 6>>& internalBoxes,
               const std::vector<std::array<float, 6>>& leafBoxes);

/// Builds a binary tree top-down by binned SAH (`bins` centroid bins per
/// axis, every axis with a centroid extent tried, the cheapest plane by
/// SA(left) N(left) + SA(right) N(right) taken; a range whose centroids all
/// coincide is cut in the middle of its index range) down to one primitive
/// per leaf, and returns sahCost of that tree. Invalid boxes are left out;
/// no valid box costs 0. Throws std::invalid_argument when bins < 2.
double binnedSahCost(const std::vector<Aabb>& primitiveBoxes, int bins = 32);

}  // namespace snell::ref
