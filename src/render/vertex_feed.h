// Every way a shape's vertices reach a frame, other than the deform pass's
// skinning and morphs, in the order a frame takes them:
//
// - kept vertices: the host's copy of a scene without host buffers (the
//   embedding API's vertex lists, a DCC's script), in mapped host memory,
//   copied into the scene's buffers for the shapes marked dirty;
// - host copies: a scene of host buffers that has a subdivision surface keeps
//   its refined vertices in snell's buffers, so each other mesh's vertices are
//   copied there from the host's when it is marked dirty (every mesh at the
//   first frame); a scene of host buffers without one is read in place;
// - the refine: each subdivision surface whose cage moved becomes its refined
//   vertices (refine_pass), its cage read from the kept copy or the host's buffers.
//
// Renderer::markDirty calls markDirty once; the head of each frame calls record.
#pragma once

#include "render/deform_pass.h"
#include "render/refine_pass.h"
#include "render/scene_gpu.h"
#include "scene/scene.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/upload_arena.h"

#include <cstdint>
#include <string>
#include <vector>

namespace snell::render {

/// A shape's kept vertices: packed float triples in mapped host memory.
struct KeptVertices {
  float* positions = nullptr;
  float* normals = nullptr;
  uint32_t count = 0;
};

/// What one record() did, for FrameStats.
struct FeedCounts {
  uint32_t shapesCopied = 0;     ///< shapes whose vertices (or cage) were copied in
  uint32_t shapesRefined = 0;    ///< subdivision surfaces refined
  uint32_t verticesRefined = 0;  ///< the vertices those became
};

class VertexFeed {
 public:
  /// With `keep`, the feed keeps every shape's vertices for the host to
  /// rewrite, starting as its rest pose (a subdivision surface's: its cage).
  /// Throws std::invalid_argument where `keep` meets a scene snell deforms or
  /// one of host buffers.
  VertexFeed(vk::Context& context, const scene::Scene& scene, const SceneGpu& gpu, bool keep,
             const std::string& name);

  bool keeps() const { return kept_.size() > 0; }
  /// Shape `shape`'s kept vertices (a part's: its source's); the caller makes
  /// sure no frame in flight reads them.
  KeptVertices kept(int shape);
  /// Shape `shape`'s vertices (kept, or in the host's buffers) changed: the
  /// next record copies or refines them.
  void markDirty(int shape);
  /// Records the copies and refines of the shapes marked dirty since the last
  /// record, with the barriers that let every later pass read them; host
  /// copies run as `deform`'s copy dispatch (the host's buffers may be
  /// storage buffers only, no transfer source).
  FeedCounts record(vk::Commands& commands, vk::UploadArena& arena, DeformPass& deform);

  /// GPU and mapped memory: the kept copy, the refine's tables and cages.
  uint64_t bytes() const { return kept_.size() + refine_.bytes(); }

 private:
  /// Kept shape `shape`'s copy into the scene's buffers, or into the refine's cages.
  void recordKeptCopy(vk::Commands& commands, int shape);
  /// Where a host shape's vertices go in snell's buffers, for each geometry of its.
  std::vector<VertexCopy> hostCopies(int shape) const;

  const scene::Scene& scene_;
  const SceneGpu& gpu_;
  RefinePass refine_;
  vk::Buffer kept_;                  ///< every shape's positions, shape after shape, then their normals
  std::vector<uint32_t> keptFirst_;  ///< per shape: its first vertex in kept_
  uint32_t keptCount_ = 0;           ///< vertices kept
  std::vector<char> dirty_;          ///< per shape: kept or host copies pending
};

}  // namespace snell::render
