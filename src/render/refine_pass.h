// The refine pass: each subdivision surface whose cage moved this frame
// becomes its refined vertices on the GPU (shaders/comp/refine.comp), after
// the cage's copy and before the trees' refit, into the scene's vertex
// buffers that the trees, the trace and the raster pass read. Every shape of
// a frame goes in one dispatch per stage; a shape whose cage did not move
// refines nothing.
#pragma once

#include "render/scene_gpu.h"
#include "scene/scene.h"
#include "shared/refine.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "vk/context.h"
#include "vk/upload_arena.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace snell::render {

class RefinePass {
 public:
  /// Uploads the tables of every subdivision surface `gpu` draws. Their cages
  /// are read from cageBuffer(), at cageFirst(shape): the pass's own, which
  /// the caller fills (kept vertices), or the host's (a scene of host buffers).
  RefinePass(vk::Context& context, const scene::Scene& scene, const SceneGpu& gpu);
  /// Its two pipelines (refine, then limit positions and normals).
  static std::vector<vk::ComputeProgramDesc> programDescs();

  /// No shape of the scene is a subdivision surface.
  bool empty() const { return shapes_.empty(); }
  /// Where shape `shape`'s cage vertices go, and their first vertex there.
  const vk::Buffer& cageBuffer() const { return *cage_; }
  uint32_t cageFirst(int shape) const;
  /// Whether shape `shape` is a subdivision surface the scene draws.
  bool refines(int shape) const { return shape >= 0 && size_t(shape) < tablesOf_.size() && tablesOf_[size_t(shape)] >= 0; }
  /// The cage of shape `shape` moved (it is a subdivision surface, else nothing happens).
  void markDirty(int shape);
  /// Some cage is marked dirty, for the next record().
  bool pending() const;
  /// Records the refinement of the cages marked dirty (both stages and the
  /// barriers after them) into the scene's buffers; returns the shapes it refined.
  std::vector<int> record(vk::Commands& commands, const SceneGpu& gpu, vk::UploadArena& arena);

  /// GPU memory of the tables, the cages and the refined vertices.
  uint64_t bytes() const;

 private:
  struct ShapeTables {
    int shape = -1;
    gpu::RefineJob job{};  ///< its tables' places; bases filled per record
    bool dirty = false;
  };
  vk::Context& context_;
  std::unique_ptr<vk::ComputeProgram> refine_, limit_;
  std::vector<ShapeTables> shapes_;
  std::vector<int> tablesOf_;  ///< per scene shape: its index in shapes_, or -1
  vk::Buffer words_, weights_, refined_, jobs_, ownCage_;
  const vk::Buffer* cage_ = nullptr;
};

}  // namespace snell::render
