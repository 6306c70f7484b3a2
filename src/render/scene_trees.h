// The scene's trees over the frames: which bottom-level trees a frame
// builds, refits or leaves alone (all built once; then refitted where
// positions changed, and rebuilt where the surface area heuristic says
// refits have spoiled them, within a triangle budget per frame), when the
// top level follows, and what the GPU reports back of each frame: every
// refitted tree's SAH, the triangles dropped as non-finite, and the boxes of
// shapes whose vertices the host rewrote.
#pragma once

#include "render/bvh.h"
#include "render/frame_request.h"
#include "render/scene_gpu.h"
#include "render/scene_state.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/upload_arena.h"

#include <glm/glm.hpp>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace snell::render {

/// A shape's box (its space) as a refit measured it.
struct ShapeBox {
  int shape = 0;
  glm::dvec3 lo{0.0}, hi{0.0};
};

class SceneTrees {
 public:
  /// Makes nothing on the GPU until the first frame that needs trees plans.
  SceneTrees(vk::Context& context, const SceneGpu& gpu, std::string name, double rebuildGrowth, uint64_t rebuildBudget,
             BvhChildBoxes childBoxes = BvhChildBoxes::Exact);
  ~SceneTrees();

  /// Bottom-level group `group`'s positions changed: the next frame with trees refits it.
  void noteMoved(uint32_t group) { moved_.at(group) = 1; }
  /// Shape `shape`'s vertices were rewritten: the next refit of its tree
  /// measures its box (one measured before a later rewrite does not count).
  void measure(int shape);
  /// Instances moved in a frame that updated no tree: the next one refits the top level.
  void noteTopStale() { topDirty_ = true; }

  /// One frame's work on the trees.
  struct Work {
    std::vector<uint32_t> build, refit;  ///< bottom-level groups (refit lists the built ones too, for their SAH)
    bool buildTop = false, refitTop = false;
    struct Measure {
      uint32_t group = 0;
      int shape = 0;
      uint64_t edit = 0;  ///< the shape's rewrites when the frame was planned
    };
    std::vector<Measure> measures;
  };
  /// Plans a frame's work and counts it in `stats`. `fresh`: every tree
  /// built afresh (RendererOptions::independentFrames).
  Work plan(bool instancesChanged, bool fresh, FrameStats& stats);
  void record(vk::Commands& commands, const Work& work, const vk::Buffer& instances, vk::UploadArena& arena);

  /// Bytes the frame's statistics of `work` take in a readback.
  VkDeviceSize statisticsBytes(const Work& work) const;
  /// Records the copies of those statistics into `buffer` from `at`.
  void recordStatistics(vk::Commands& commands, const Work& work, const vk::Buffer& buffer, VkDeviceSize at) const;
  /// Reads them once the frame is done: the rebuild queue hears each tree's
  /// SAH, `stats` gets the dropped triangles and the SAH growth, and the
  /// shapes measured come back with their boxes.
  std::vector<ShapeBox> collect(const Work& work, const std::byte* statistics, FrameStats& stats);

  const Bvh* blas() const { return blas_.get(); }
  const Bvh* tlas() const { return tlas_.get(); }
  BvhBuilder* builder() { return builder_.get(); }
  /// GPU memory of both levels, their work tables and the build scratch.
  uint64_t bytes() const;
  /// Bytes of tree memory (both levels) per bottom-level triangle, build scratch apart.
  double treeBytesPerTriangle() const;

 private:
  void prepare();

  vk::Context& context_;
  const SceneGpu& gpu_;
  std::string name_;
  uint64_t rebuildBudget_;
  BvhChildBoxes childBoxes_;
  std::unique_ptr<BvhBuilder> builder_;
  std::unique_ptr<Bvh> blas_, tlas_;
  RebuildQueue rebuilds_;
  std::vector<char> moved_;  ///< per bottom-level group: positions changed since its tree last saw them
  bool built_ = false, topBuilt_ = false, topDirty_ = true;
  std::vector<uint64_t> shapeEdits_;      ///< per shape: rewrites so far
  std::vector<char> shapeUnmeasured_;     ///< per shape: its box waits for a refit
};

}  // namespace snell::render
