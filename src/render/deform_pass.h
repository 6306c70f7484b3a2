// The deform pass, first of every frame: for each drawn shape that is morphed
// or skinned and whose pose changed, morph targets then linear blend skinning
// on the GPU, into storage buffers the BVH and raster passes read. All of a
// frame's items go in one dispatch, whatever their number; static shapes skip it.
#pragma once

#include "scene/evaluate.h"
#include "scene/scene.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "vk/context.h"
#include "vk/upload_arena.h"

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

namespace snell::render {

/// Where a deforming item's vertices go: a slice of vertex buffers shared
/// with the BVH and raster passes (packed float triples). Every item of one
/// pass writes into the same two buffers.
struct DeformSlot {
  const vk::Buffer* positions = nullptr;
  const vk::Buffer* normals = nullptr;
  uint32_t firstVertex = 0;
};

/// Vertices copied from one place of a pair of vertex buffers to another
/// (DeformPass::recordCopies): `count` vertices from vertex `from` to `to`.
struct VertexCopy {
  uint32_t from = 0, to = 0, count = 0;
};

/// One deforming draw item and where its deformed geometry goes.
struct DeformOutput {
  int item = -1;   ///< index into Pose::items
  int shape = -1;
  uint32_t jointCount = 0;
  DeformSlot slot;
  /// Skinned positions of the last record are relative to this world point
  /// (DeformPass::anchorOf); zero for morph-only items, which stay in shape space.
  glm::dvec3 anchor{0.0};
};

class DeformPass {
 public:
  /// Uploads every shape that some item deforms and an output per deforming
  /// item of `pose` (a pose of `scene` at any time: which items exist does
  /// not depend on time). `slots` gives the output slice of each deforming
  /// item (by pose item index); without it the pass owns one pair of buffers.
  DeformPass(vk::Context& context, const scene::Scene& scene, const scene::Pose& pose,
             const std::function<DeformSlot(int item)>& slots = {});

  /// Where a skinned item's deformed positions are measured from: its first
  /// joint's world position, so they keep float precision however far the
  /// character is from the world's origin, and move only when it does.
  static glm::dvec3 anchorOf(const scene::DrawItem& item);
  /// Its pipeline, as every deform pass makes it.
  static vk::ComputeProgramDesc programDesc();

  /// Records one dispatch deforming the outputs listed (indices into
  /// outputs(); every one when `which` is empty) to `pose`, then a barrier
  /// that makes them visible to compute, graphics and transfer. Weights,
  /// joint matrices and the job list go through `arena`.
  void record(vk::Commands& commands, const scene::Pose& pose, vk::UploadArena& arena,
              std::span<const uint32_t> which = {});

  /// Records copies of vertices between vertex buffers, in one dispatch of
  /// the deform program with nothing to morph or skin: a host's buffers,
  /// which may be storage buffers only (no transfer source), into the
  /// scene's. A barrier as record()'s follows.
  void recordCopies(vk::Commands& commands, vk::UploadArena& arena, const vk::Buffer& fromPositions,
                    const vk::Buffer& fromNormals, const vk::Buffer& toPositions, const vk::Buffer& toNormals,
                    std::span<const VertexCopy> copies);

  const std::vector<DeformOutput>& outputs() const { return outputs_; }
  /// GPU memory of the rest poses, morph deltas, skins and per-frame tables.
  uint64_t bytes() const;

 private:
  struct ShapeData {
    uint32_t restFirst = 0, morphFirst = 0, skinFirst = 0, vertexCount = 0, targetCount = 0;
    bool uploaded = false;
  };
  vk::Context& context_;
  const scene::Scene& scene_;
  std::unique_ptr<vk::ComputeProgram> program_;
  std::vector<ShapeData> shapes_;  ///< per scene shape
  std::vector<DeformOutput> outputs_;
  vk::Buffer restPositions_, restNormals_, morphDeltas_, joints_, skinWeights_;
  vk::Buffer jobs_, weights_, jointMatrices_;  ///< device-local, rewritten per record
  vk::Buffer copyJobs_;                        ///< recordCopies' jobs, grown as needed
  vk::Buffer ownPositions_, ownNormals_;       ///< when no slots were given
};

}  // namespace snell::render
