// What the Renderer knows about where the scene is, kept on the host between
// frames: a bounding sphere per draw item (for culling glass out of a view),
// the frame origin everything on the GPU is relative to, and the trees whose
// refits have spoiled them, waiting for a rebuild.
#pragma once

#include "render/frame_settings.h"
#include "scene/evaluate.h"
#include "scene/scene.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <deque>
#include <vector>

namespace snell::render {

/// Bounding spheres of the shapes at rest and of the items as a pose places them.
class SceneBounds {
 public:
  explicit SceneBounds(const scene::Scene& scene);

  /// A shape's vertices now lie in this box (its space): a host's promise, or
  /// what a refit measured; an empty box says nothing, and the shape is never culled.
  void setShapeBox(int shape, const glm::dvec3& lo, const glm::dvec3& hi);
  /// Places every item's sphere at the pose (morph weights widen a shape's, skins move it).
  void place(const scene::Pose& pose);
  /// Whether any item marked in `refractive` may be in the view's frustum
  /// (conservative; true before the first place()).
  bool anyInView(const FrameSettings& settings, const std::vector<char>& refractive) const;
  /// The box around every item's sphere as the last place() left them; empty
  /// (lo > hi) before it, with no items, or where a host shape promised no box.
  void box(glm::dvec3& lo, glm::dvec3& hi) const;
  /// The distance from `eye` to the nearest item's sphere, and to the farthest sphere's far side.
  void reach(const glm::dvec3& eye, double& nearest, double& farthest) const;

 private:
  struct Sphere {
    glm::dvec3 centre{0.0};
    double radius = 0.0;
  };
  /// The sphere around a box; a host shape's empty box (no promise) is never culled.
  static Sphere around(const glm::dvec3& lo, const glm::dvec3& hi, bool host);

  std::vector<Sphere> shapes_;                  ///< per shape, at rest
  std::vector<std::vector<double>> morphReach_;  ///< per shape, per target: its largest displacement
  std::vector<Sphere> items_;                   ///< per item, as the last place() left them
};

/// The frame origin: it follows the first view's camera, but only once the
/// camera is farther from it than from the nearest item, so coordinates near
/// the camera lose at most a bit to it and orbiting mostly moves no tree.
class FrameOrigin {
 public:
  /// Moves the origin to `eye` if it has to; returns whether it moved (after the first frame).
  bool follow(const glm::dvec3& eye, const SceneBounds& bounds);
  const glm::dvec3& origin() const { return origin_; }

 private:
  bool set_ = false;
  glm::dvec3 origin_{0.0};
};

/// Tree quality: the SAH cost of each bottom-level group right after its
/// build, and the rebuilds due where a refit has grown it past `growth`.
class RebuildQueue {
 public:
  RebuildQueue(size_t groups, double growth) : baseline_(groups, 0.0), queued_(groups, 0), growth_(growth) {}

  /// Forgets every rebuild due (every tree is being built anyway).
  void clear();
  /// The groups to rebuild this frame: in order, within `budget` triangles
  /// (at least one), `triangles` giving each group's count.
  std::vector<uint32_t> take(uint64_t budget, const std::vector<uint32_t>& triangles);
  /// A refit measured group `group`'s cost: a fresh build's is its baseline,
  /// a refit past growth x baseline queues a rebuild. Returns cost / baseline (1 for a build).
  double noteBottom(uint32_t group, double cost, bool built);
  /// The same for the top level; takeTopRebuild() says (once) when a rebuild is due.
  void noteTop(double cost, bool built);
  bool takeTopRebuild();

 private:
  std::vector<double> baseline_;
  std::vector<char> queued_;
  std::deque<uint32_t> queue_;
  double topBaseline_ = 0.0;
  bool topDue_ = false;
  double growth_;
};

}  // namespace snell::render
