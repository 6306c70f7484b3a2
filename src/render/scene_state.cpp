#include "render/scene_state.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace snell::render {

namespace {

double maxScale(const glm::dmat4& m) {
  return std::max({glm::length(glm::dvec3(m[0])), glm::length(glm::dvec3(m[1])), glm::length(glm::dvec3(m[2]))});
}

}  // namespace

// ---------------------------------------------------------------- SceneBounds

SceneBounds::Sphere SceneBounds::around(const glm::dvec3& lo, const glm::dvec3& hi, bool host) {
  Sphere sphere;
  if (lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z) sphere = {0.5 * (lo + hi), 0.5 * glm::length(hi - lo)};
  if (host && !(lo.x <= hi.x)) sphere.radius = INFINITY;  // no promise: never culled
  return sphere;
}

SceneBounds::SceneBounds(const scene::Scene& scene) {
  // Rest-pose spheres per shape, and how far each morph target can move a vertex.
  for (const scene::Shape& shape : scene.shapes) {
    glm::dvec3 lo(INFINITY), hi(-INFINITY);
    for (const glm::vec3& p : shape.positions) {
      lo = glm::min(lo, glm::dvec3(p));
      hi = glm::max(hi, glm::dvec3(p));
    }
    if (shape.host) lo = glm::dvec3(shape.host->lo), hi = glm::dvec3(shape.host->hi);
    shapes_.push_back(around(lo, hi, shape.host.has_value()));
    std::vector<double> reach;
    for (const scene::MorphTarget& target : shape.targets) {
      double most = 0.0;
      for (const glm::vec3& d : target.positions) most = std::max(most, double(glm::length(d)));
      reach.push_back(most);
    }
    morphReach_.push_back(std::move(reach));
  }
}

void SceneBounds::setShapeBox(int shape, const glm::dvec3& lo, const glm::dvec3& hi) {
  if (shape < 0 || size_t(shape) >= shapes_.size()) {
    throw std::invalid_argument("renderer: no shape " + std::to_string(shape) + " to bound");
  }
  shapes_[size_t(shape)] = around(lo, hi, true);
}

void SceneBounds::place(const scene::Pose& pose) {
  items_.resize(pose.items.size());
  for (size_t i = 0; i < pose.items.size(); ++i) {
    const scene::DrawItem& item = pose.items[i];
    glm::dvec3 centre = shapes_[size_t(item.shape)].centre;
    double radius = shapes_[size_t(item.shape)].radius;
    const std::vector<double>& reach = morphReach_[size_t(item.shape)];
    for (size_t k = 0; k < reach.size() && k < item.weights.size(); ++k) radius += std::abs(item.weights[k]) * reach[k];
    if (item.skinned && !item.jointMatrices.empty()) {
      // Skinned vertices are convex blends of joint-moved rest positions, so
      // the joint-moved rest spheres hold them all.
      glm::dvec3 mean(0.0);
      for (const glm::dmat4& m : item.jointMatrices) mean += glm::dvec3(m * glm::dvec4(centre, 1.0));
      mean /= double(item.jointMatrices.size());
      double farthest = 0.0;
      for (const glm::dmat4& m : item.jointMatrices) {
        farthest = std::max(farthest, glm::length(glm::dvec3(m * glm::dvec4(centre, 1.0)) - mean) + radius * maxScale(m));
      }
      items_[i] = {mean, farthest};
    } else {
      items_[i] = {glm::dvec3(item.world * glm::dvec4(centre, 1.0)), radius * maxScale(item.world)};
    }
  }
}

// A bounding sphere per refractive item against the view's frustum: no glass
// in the frustum, no trace. Conservative: a sphere that may touch it counts.
bool SceneBounds::anyInView(const FrameSettings& settings, const std::vector<char>& refractive) const {
  if (items_.size() != refractive.size()) return true;  // no frame placed the items yet
  const scene::View& v = settings.view;
  double aspect = double(settings.width) / double(std::max(settings.height, 1u));
  double sx = v.halfHeight * aspect, sy = v.halfHeight;
  for (size_t i = 0; i < refractive.size(); ++i) {
    if (!refractive[i]) continue;
    const Sphere& s = items_[i];
    glm::dvec3 d = s.centre - v.eye;
    double x = glm::dot(d, v.right), y = glm::dot(d, v.up), z = glm::dot(d, v.forward);
    if (v.orthographic) {
      if (std::abs(x - v.shift.x) <= sx + s.radius && std::abs(y - v.shift.y) <= sy + s.radius) return true;
      continue;
    }
    if (z < -s.radius) continue;
    // Distance to each side plane of the window [shift - s, shift + s] in slope space.
    auto inside = [&](double a, double slopeLo, double slopeHi) {
      double hiDist = (a - slopeHi * z) / std::sqrt(1.0 + slopeHi * slopeHi);
      double loDist = (slopeLo * z - a) / std::sqrt(1.0 + slopeLo * slopeLo);
      return hiDist <= s.radius && loDist <= s.radius;
    };
    if (inside(x, v.shift.x - sx, v.shift.x + sx) && inside(y, v.shift.y - sy, v.shift.y + sy)) return true;
  }
  return false;
}

void SceneBounds::box(glm::dvec3& lo, glm::dvec3& hi) const {
  lo = glm::dvec3(INFINITY), hi = glm::dvec3(-INFINITY);
  for (const Sphere& s : items_) {
    if (!std::isfinite(s.radius)) {
      lo = glm::dvec3(INFINITY), hi = glm::dvec3(-INFINITY);
      return;
    }
    lo = glm::min(lo, s.centre - s.radius);
    hi = glm::max(hi, s.centre + s.radius);
  }
}

void SceneBounds::reach(const glm::dvec3& eye, double& nearest, double& farthest) const {
  nearest = INFINITY, farthest = 0.0;
  for (const Sphere& s : items_) {
    nearest = std::min(nearest, std::max(0.0, glm::length(s.centre - eye) - s.radius));
    farthest = std::max(farthest, glm::length(s.centre - eye) + s.radius);
  }
}

// ---------------------------------------------------------------- FrameOrigin

bool FrameOrigin::follow(const glm::dvec3& eye, const SceneBounds& bounds) {
  double nearest = INFINITY, extent = 0.0;
  bounds.reach(eye, nearest, extent);
  if (set_ && glm::length(eye - origin_) <= std::max(nearest, 1e-9 * extent)) return false;
  bool moved = set_;
  origin_ = eye;
  set_ = true;
  return moved;
}

// ---------------------------------------------------------------- RebuildQueue

void RebuildQueue::clear() {
  queue_.clear();
  std::fill(queued_.begin(), queued_.end(), 0);
}

std::vector<uint32_t> RebuildQueue::take(uint64_t budget, const std::vector<uint32_t>& triangles) {
  std::vector<uint32_t> groups;
  uint64_t taken = 0;
  while (!queue_.empty()) {
    uint32_t g = queue_.front();
    if (!groups.empty() && taken + triangles[g] > budget) break;
    queue_.pop_front();
    queued_[g] = 0;
    taken += triangles[g];
    groups.push_back(g);
  }
  return groups;
}

double RebuildQueue::noteBottom(uint32_t group, double cost, bool built) {
  if (built || baseline_[group] <= 0.0) {
    baseline_[group] = cost;
    return 1.0;
  }
  if (cost > growth_ * baseline_[group] && !queued_[group]) {
    queued_[group] = 1;
    queue_.push_back(group);
  }
  return cost / baseline_[group];
}

void RebuildQueue::noteTop(double cost, bool built) {
  if (built || topBaseline_ <= 0.0) {
    topBaseline_ = cost;
  } else if (cost > growth_ * topBaseline_) {
    topDue_ = true;
  }
}

bool RebuildQueue::takeTopRebuild() { return std::exchange(topDue_, false); }

}  // namespace snell::render
