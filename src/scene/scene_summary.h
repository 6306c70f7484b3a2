// Counts and a GPU memory estimate for a scene: what `snell info scene.glb`
// prints, and what tests check against known models.
#pragma once

#include "scene/scene.h"

#include <cstdint>
#include <string>

namespace snell::scene {

struct SceneSummary {
  size_t nodes = 0, shapes = 0, instances = 0;
  uint64_t triangles = 0, vertices = 0;  ///< drawn: summed over instances
  size_t refractiveMaterials = 0, morphedShapes = 0, skinnedShapes = 0;
  size_t subdividedShapes = 0;  ///< subdivision surfaces, refined on the GPU when their cage moves
  /// Bytes on the GPU for one frame at `width` x `height`, by kind.
  uint64_t geometryBytes = 0, deformBytes = 0, refineBytes = 0, bvhBytes = 0, textureBytes = 0, imageBytes = 0;
  uint64_t totalBytes() const {
    return geometryBytes + deformBytes + refineBytes + bvhBytes + textureBytes + imageBytes;
  }
};

SceneSummary summarize(const Scene& scene, uint32_t width = 1920, uint32_t height = 1080);

/// The human-readable report of `snell info`.
std::string describe(const Scene& scene, uint32_t width = 1920, uint32_t height = 1080);

}  // namespace snell::scene
