// The scene at a time t on the CPU: animation sampled, transforms composed,
// morph weights and skin joint matrices computed, and each drawn shape listed.
// It is the reference the GPU deform pass is tested against.
#pragma once

#include "scene/scene.h"

#include <glm/glm.hpp>

#include <vector>

namespace snell::scene {

/// One shape as drawn: which node placed it, with what transform and weights.
struct DrawItem {
  int shape = -1;
  int node = -1;
  /// Object to world, in double: a float matrix would round a child's offset
  /// against a parent's large translation (1 mm lost at 10 km). Identity for
  /// skinned items: their joints place them.
  glm::dmat4 world{1.0};
  bool skinned = false;  ///< deformed by the node's skin
  bool deforms() const;  ///< skinned or morphed: the deform pass runs for it
  std::vector<float> weights;          ///< morph weights (the node's, or the mesh's defaults)
  std::vector<glm::dmat4> jointMatrices;  ///< jointWorld * inverseBind, per skin joint
  const Scene* scene = nullptr;
};

/// Node transforms and everything drawn, at one time.
struct Pose {
  double time = 0.0;
  std::vector<glm::dmat4> world;  ///< per node, in double (see DrawItem::world)
  std::vector<DrawItem> items;
};

/// Evaluates every animation clip at `time` seconds (each clamped to its own
/// keys; looping is the caller's choice).
Pose evaluate(const Scene& scene, double time);

/// The longest clip, in seconds; 0 for a static scene.
double animationDuration(const Scene& scene);

/// The item's deformed positions and normals in double precision: morph
/// targets, then linear blend skinning (normals by the cofactor matrix), in
/// the space `DrawItem::world` maps to world.
void deformOnCpu(const DrawItem& item, std::vector<glm::dvec3>& positions, std::vector<glm::dvec3>& normals);

}  // namespace snell::scene
