// The host's copy of a scene's vertices, for a caller that rewrites them
// between frames (the embedding API's scenes without host buffers): kept in
// mapped host memory, and copied into the scene's buffers at the head of the
// next frame, for the shapes marked dirty. A subdivision surface keeps its
// cage, which goes to the refine pass instead.
#pragma once

#include "render/refine_pass.h"
#include "render/scene_gpu.h"
#include "scene/scene.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"

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

class KeptVertexCopy {
 public:
  /// Starts as every shape's rest pose, drawn or not. Throws
  /// std::invalid_argument for a scene snell deforms (its GPU vertices are the deform pass's).
  KeptVertexCopy(vk::Context& context, const scene::Scene& scene, const std::string& name);

  /// Shape `shape`'s vertices; the caller makes sure no frame in flight reads them.
  KeptVertices shape(int shape);
  /// The shape's kept vertices changed: the next recordCopies copies them.
  void markDirty(int shape) { dirty_.at(size_t(shape)) = 1; }
  /// Records the copies of the shapes marked dirty into every geometry of
  /// theirs in `gpu`'s buffers, and a subdivision surface's cage into
  /// `refine`'s (marking it dirty there); returns how many shapes were copied.
  uint32_t recordCopies(vk::Commands& commands, const SceneGpu& gpu, RefinePass& refine);
  uint64_t bytes() const { return buffer_.size(); }

 private:
  const scene::Scene& scene_;
  vk::Buffer buffer_;            ///< every shape's positions, shape after shape, then their normals
  std::vector<uint32_t> first_;  ///< per shape: its first vertex in buffer_
  uint32_t count_ = 0;           ///< vertices kept
  std::vector<char> dirty_;      ///< per shape
};

}  // namespace snell::render
