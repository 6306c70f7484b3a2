// GPU bounding volume hierarchies, LBVH-style (Karras 2012), all in compute.
// One Bvh is a forest: its primitives are split into contiguous groups and
// each group gets its own binary tree, one primitive per leaf. The bottom
// level is one forest whose groups are shapes (triangles in shape space); the
// top level is a forest of one group whose primitives are instances.
//
// build: per-primitive boxes -> centroid bounds -> Morton keys -> radix sort ->
// hierarchy -> boxes bottom-up. refit: per-primitive boxes -> boxes bottom-up,
// for the groups whose positions changed. Both are deterministic: the sort is
// stable and every box is a min/max, whatever order the GPU runs them in.
#pragma once

#include "render/radix_sort.h"
#include "shared/bvh.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "vk/context.h"

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

namespace snell::render {

/// The buffers of one forest. Primitive boxes are written by the caller's
/// box pass (BvhBuilder::recordTriangleBoxes / recordInstanceBoxes).
struct Bvh {
  uint32_t primitiveCount = 0;
  std::vector<uint32_t> groupSizes;
  vk::Buffer primBoxes, primGroups, groups, groupsInitial, keys, leafPrims, nodes, leafParents, counters;
  vk::Buffer dropped;  ///< uint: non-finite triangles the box passes met since the caller last zeroed it
  RadixSort::Scratch sortScratch;
  uint32_t groupCount() const { return static_cast<uint32_t>(groupSizes.size()); }
  uint32_t firstPrimitive(uint32_t group) const;
};

/// A box as six floats: lo xyz, hi xyz.
using BoxFloats = std::array<float, 6>;

/// A tree brought back to the host, for tests and the quality benchmark.
struct BvhSnapshot {
  /// Group g's boxes: the root's first, then every internal node's, and every
  /// leaf's, as the parents' child slots hold them (what the SAH prices).
  struct TreeBoxes {
    std::vector<BoxFloats> internal, leaves;
  };
  TreeBoxes treeBoxes(uint32_t group) const;

  std::vector<gpu::BvhNode> nodes;
  std::vector<gpu::BvhGroup> groups;
  std::vector<uint32_t> leafPrims;
  std::vector<uint32_t> leafParents;  // by primitive
};

/// Rounds of treelet restructuring after the LBVH (bvh_restructure.comp):
/// each round costs one bottom-up pass. Three, as in the paper; on lavapipe,
/// treelets of 7 took TransmissionRoughnessTest's SAH ratio from 1.69 (LBVH)
/// to 1.21 in two rounds and 1.16 in three.
inline constexpr uint32_t kDefaultRestructureRounds = 3;

class BvhBuilder {
 public:
  explicit BvhBuilder(vk::Context& context);
  ~BvhBuilder();

  /// Allocates a forest whose group g holds primitives [sum of earlier sizes, + groupSizes[g]).
  Bvh makeBvh(const std::vector<uint32_t>& groupSizes, const std::string& name) const;

  /// Boxes of triangles [first, first + count) of the forest (absolute indices into `positions`).
  void recordTriangleBoxes(vk::Commands& commands, const Bvh& bvh, const vk::Buffer& positions,
                           const vk::Buffer& indices, uint32_t first, uint32_t count) const;
  /// World boxes of `bvh`'s primitives as instances (gpu::GpuInstance) of `blas`'s groups.
  void recordInstanceBoxes(vk::Commands& commands, const Bvh& bvh, const vk::Buffer& instances,
                           const Bvh& blas) const;
  /// Builds every group's tree from the primitive boxes (made visible to compute before):
  /// the LBVH, then `restructureRounds` rounds of treelet restructuring.
  void recordBuild(vk::Commands& commands, const Bvh& bvh,
                   uint32_t restructureRounds = kDefaultRestructureRounds) const;
  /// Recomputes the boxes of group `group`'s tree; topology is kept.
  void recordRefit(vk::Commands& commands, const Bvh& bvh, uint32_t group) const;

  /// Reads a forest back (waits for the GPU).
  BvhSnapshot download(const Bvh& bvh) const;

 private:
  void recordFit(vk::Commands& commands, const Bvh& bvh, uint32_t first, uint32_t count) const;
  void recordRestructure(vk::Commands& commands, const Bvh& bvh) const;

  vk::Context& context_;
  RadixSort sort_;
  std::unique_ptr<vk::ComputeProgram> triangleBoxes_, instanceBoxes_, centroidBounds_, morton_, hierarchy_, fit_, restructure_;
};

}  // namespace snell::render
