// Binned SAH build (Wald 2007, "On fast construction of SAH-based bounding
// volume hierarchies") kept only for its cost: no nodes are stored.
#include "ref/sah_bvh.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <utility>

namespace snell::ref {

bool Aabb::valid() const {
  for (int a = 0; a < 3; ++a) {
    if (!std::isfinite(lo[a]) || !std::isfinite(hi[a]) || lo[a] > hi[a]) return false;
  }
  return true;
}

double surfaceArea(const Aabb& box) {
  if (!(box.lo.x <= box.hi.x && box.lo.y <= box.hi.y && box.lo.z <= box.hi.z)) return 0.0;
  glm::dvec3 e = box.hi - box.lo;
  return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

double sahCost(const std::vector<std::array<float, 6>>& internalBoxes,
               const std::vector<std::array<float, 6>>& leafBoxes) {
  auto toAabb = [](const std::array<float, 6>& b) {
    Aabb a;
    a.lo = {b[0], b[1], b[2]};
    a.hi = {b[3], b[4], b[5]};
    return a;
  };
  std::vector<Aabb> internal, leaves;
  for (const auto& b : internalBoxes) internal.push_back(toAabb(b));
  for (const auto& b : leafBoxes) leaves.push_back(toAabb(b));
  return internal.empty() ? 0.0 : sahCost(internal, leaves, internal.front());
}

double sahCost(const std::vector<Aabb>& internalBoxes, const std::vector<Aabb>& leafBoxes, const Aabb& root) {
  double rootArea = surfaceArea(root);
  if (!(rootArea > 0.0)) return 0.0;
  double sum = 0.0;
  for (const Aabb& b : internalBoxes) sum += surfaceArea(b);
  for (const Aabb& b : leafBoxes) sum += surfaceArea(b);
  return sum / rootArea;
}

double binnedSahCost(const std::vector<Aabb>& primitiveBoxes, int bins) {
  if (bins < 2) throw std::invalid_argument("binnedSahCost needs at least 2 bins");
  struct Prim {
    Aabb box;
    glm::dvec3 centroid;
  };
  std::vector<Prim> prims;
  prims.reserve(primitiveBoxes.size());
  for (const Aabb& b : primitiveBoxes) {
    if (b.valid()) prims.push_back({b, b.centroid()});
  }
  if (prims.empty()) return 0.0;

  Aabb root;
  for (const Prim& p : prims) root.extend(p.box);
  const double rootArea = surfaceArea(root);
  if (!(rootArea > 0.0)) return 0.0;

  const size_t binCount = size_t(bins);
  struct Bin {
    Aabb box;
    size_t count = 0;
  };
  std::vector<Bin> binned(binCount);
  std::vector<double> rightArea(binCount);
  std::vector<size_t> rightCount(binCount);

  // The summed areas of every node built; divided by the root's at the end.
  double areaSum = 0.0;
  // Ranges still to split; a stack, so degenerate inputs cannot overflow the call stack.
  std::vector<std::pair<size_t, size_t>> work{{0, prims.size()}};
  while (!work.empty()) {
    auto [begin, end] = work.back();
    work.pop_back();
    Aabb box, centroids;
    for (size_t i = begin; i < end; ++i) {
      box.extend(prims[i].box);
      centroids.extend(prims[i].centroid);
    }
    areaSum += surfaceArea(box);
    if (end - begin == 1) continue;  // a leaf

    int bestAxis = -1;
    size_t bestBin = 0;
    double bestCost = std::numeric_limits<double>::infinity();
    glm::dvec3 extent = centroids.hi - centroids.lo;
    auto binOf = [&](const glm::dvec3& c, int axis) {
      double x = (c[axis] - centroids.lo[axis]) / extent[axis] * double(bins);
      return std::min(binCount - 1, size_t(std::max(0.0, x)));
    };
    for (int axis = 0; axis < 3; ++axis) {
      if (!(extent[axis] > 0.0)) continue;
      std::fill(binned.begin(), binned.end(), Bin{});
      for (size_t i = begin; i < end; ++i) {
        Bin& b = binned[binOf(prims[i].centroid, axis)];
        b.box.extend(prims[i].box);
        ++b.count;
      }
      // Sweep from the right once to know, for each plane, what lies beyond it.
      Aabb right;
      size_t count = 0;
      for (size_t b = binCount - 1; b > 0; --b) {
        right.extend(binned[b].box);
        count += binned[b].count;
        rightArea[b] = surfaceArea(right);
        rightCount[b] = count;
      }
      Aabb left;
      size_t leftCount = 0;
      for (size_t b = 0; b + 1 < binCount; ++b) {
        left.extend(binned[b].box);
        leftCount += binned[b].count;
        if (leftCount == 0 || rightCount[b + 1] == 0) continue;
        double cost = surfaceArea(left) * double(leftCount) + rightArea[b + 1] * double(rightCount[b + 1]);
        if (cost < bestCost) {
          bestCost = cost;
          bestAxis = axis;
          bestBin = b;
        }
      }
    }

    size_t middle;
    if (bestAxis < 0) {
      middle = begin + (end - begin) / 2;  // every centroid in one point: no plane separates them
    } else {
      auto split = std::partition(prims.begin() + std::ptrdiff_t(begin), prims.begin() + std::ptrdiff_t(end),
                                  [&](const Prim& p) { return binOf(p.centroid, bestAxis) <= bestBin; });
      middle = size_t(split - prims.begin());
    }
    work.push_back({middle, end});
    work.push_back({begin, middle});
  }
  return areaSum / rootArea;
}

}  // namespace snell::ref
