// The deform pass, first of every frame: for each drawn shape that is morphed
// or skinned, morph targets then linear blend skinning on the GPU, into
// storage buffers the BVH and raster passes read. Static shapes skip it.
#pragma once

#include "scene/evaluate.h"
#include "scene/scene.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "vk/context.h"

#include <functional>
#include <memory>
#include <vector>

namespace snell::render {

/// A shape's rest pose on the GPU: uploaded once, shared by its instances.
struct DeformInputs {
  uint32_t vertexCount = 0;
  uint32_t targetCount = 0;
  vk::Buffer positions, normals, morphDeltas, joints, skinWeights;
};

/// Where a deforming item's vertices go: a slice of vertex buffers shared
/// with the BVH and raster passes (packed float triples).
struct DeformSlot {
  const vk::Buffer* positions = nullptr;
  const vk::Buffer* normals = nullptr;
  uint32_t firstVertex = 0;
};

/// One deforming draw item: its per-frame weights and joint matrices (host
/// visible, written by record) and where its deformed geometry goes.
struct DeformOutput {
  int item = -1;   ///< index into Pose::items
  int shape = -1;
  uint32_t jointCount = 0;
  vk::Buffer morphWeights, jointMatrices;
  DeformSlot slot;  ///< the caller's buffers, or ownPositions/ownNormals
  vk::Buffer ownPositions, ownNormals;
};

class DeformPass {
 public:
  /// Uploads every shape that some item deforms and allocates an output per
  /// deforming item of `layout` (a pose of `scene` at any time: which items
  /// exist does not depend on time).
  /// `slots` gives the output slice of each deforming item (by pose item
  /// index); without it each item gets buffers of its own.
  DeformPass(vk::Context& context, const scene::Scene& scene, const scene::Pose& layout,
             const std::function<DeformSlot(int item)>& slots = {});

  /// Writes the pose's weights and joint matrices and records one dispatch
  /// per deforming item, then a barrier that makes the outputs visible to
  /// compute and transfer. The host writes shared buffers: the previous
  /// frame's deform must have finished.
  /// Skinned positions come out relative to `origin` (the camera, for the
  /// renderer): the joint matrices are moved there in double, so a character
  /// far from the world's origin keeps float precision where it is.
  void record(vk::Commands& commands, const scene::Pose& pose, const glm::dvec3& origin = glm::dvec3(0.0));

  const std::vector<DeformOutput>& outputs() const { return outputs_; }

 private:
  vk::Context& context_;
  const scene::Scene& scene_;
  std::unique_ptr<vk::ComputeProgram> program_;
  std::vector<std::unique_ptr<DeformInputs>> inputs_;  ///< per shape; null when it never deforms
  std::vector<DeformOutput> outputs_;
  vk::Buffer empty_;  ///< bound where a shape has no morph targets or no skin
};

}  // namespace snell::render
