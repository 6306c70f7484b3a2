// GPU bounding volume hierarchies, all in compute, with a fixed number of
// dispatches whatever the number of trees. One Bvh is a forest: its
// primitives are split into contiguous groups and each group gets its own
// binary tree, one primitive per leaf. The bottom level is one forest whose
// groups are shapes (triangles in shape space); the top level is a forest of
// one group whose leaves are instances.
//
// build (any subset of groups): primitive boxes and centroid bounds ->
// Morton keys -> radix sort -> H-PLOC (shaders/comp/bvh/bvh_hploc.comp), and
// optionally rounds of treelet restructuring, on exact boxes; then the
// nodes' quantisation (bvh_quantise.comp). refit (any subset): one
// dispatch from the leaves up, which also prices each tree by the surface
// area heuristic, so a caller can rebuild trees that deformation has spoiled.
// Both are deterministic: the same input gives the same nodes in the same
// slots, bit for bit, whatever order the GPU runs them in (shared/bvh.h).
#pragma once

#include "render/radix_sort.h"
#include "shared/bvh.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "vk/context.h"
#include "vk/upload_arena.h"

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace snell::render {

enum class BvhLeaves {
  Triangles,  ///< bottom level
  Instances,  ///< top level
};

/// What a forest keeps of each node's two children's boxes for the trace (shared/bvh.h).
enum class BvhChildBoxes {
  Exact,      ///< their exact boxes in float beside the node (48 bytes more a node): no decode in a child test
  Quantised,  ///< only the node's own 8-bit steps (40 bytes a node in all): compact trees
};

/// One forest's trees, which live as long as it does. Group g owns
/// primitives [first[g], + groupSizes[g]) and node slots [first[g], + groupSizes[g] - 1).
struct Bvh {
  BvhLeaves leaves = BvhLeaves::Triangles;
  BvhChildBoxes childBoxes = BvhChildBoxes::Exact;
  bool wide = false;  ///< hasWideRecords()
  std::string name;
  std::vector<uint32_t> groupSizes, first;
  uint32_t primitiveCount = 0;
  vk::Buffer nodes;    ///< gpu::BvhNode per primitive (one slot per group unused)
  vk::Buffer groups;   ///< gpu::BvhGroup per group
  vk::Buffer stats;    ///< uvec4 per group: its last refit's SAH (BvhBuilder::sahCost reads it)
  vk::Buffer dropped;  ///< uint: non-finite triangles the box passes met since the caller last zeroed it
  vk::Buffer buildEntries, refitEntries;  ///< this forest's lists, copied in per build or refit
  vk::Buffer exactBoxes;  ///< float[6] per node slot: a build's or refit's exact boxes on their way up
  vk::Buffer exactChildBoxes;  ///< float[12] per node slot with BvhChildBoxes::Exact (else 16 unused bytes)
  vk::Buffer wideRecords;      ///< gpu::BvhWideEntry[4] per node slot where hasWideRecords() (else 16 unused bytes)

  uint32_t groupCount() const { return static_cast<uint32_t>(groupSizes.size()); }
  /// Whether builds and refits keep 4-wide records (shared/bvh.h, BvhWideEntry), which the trace then
  /// walks 4 wide: keepsWideRecords at makeBvh.
  bool hasWideRecords() const { return wide; }
  /// Memory of the trees the trace reads: nodes, their exact child boxes, 4-wide records and group records.
  uint64_t treeBytes() const;
  /// Memory builds and refits work in besides the trees (exact boxes), and the per-group tables and lists.
  uint64_t workBytes() const;
};

/// Whether a forest keeps 4-wide records: a bottom level with exact child
/// boxes whose records (128 bytes a node) fit one storage buffer the device
/// binds. Vulkan promises 128 MiB, a million triangles, and lavapipe gives no
/// more; NVIDIA's and AMD's drivers bind 4 GiB. A larger forest keeps the
/// binary walk.
bool keepsWideRecords(const vk::Context& context, BvhLeaves leaves, BvhChildBoxes childBoxes, uint64_t primitives);

/// A box as six floats: lo xyz, hi xyz.
using BoxFloats = std::array<float, 6>;

/// A forest brought back to the host, for tests and the quality benchmark.
struct BvhSnapshot {
  /// Group g's boxes: the root's first, then every internal node's, and every
  /// leaf's (what the SAH prices): as the trace tests them (storedChildBox), or,
  /// given each primitive's box, the exact boxes of the tree's topology (what
  /// the build chose).
  struct TreeBoxes {
    std::vector<BoxFloats> internal, leaves;
  };
  TreeBoxes treeBoxes(uint32_t group) const;
  TreeBoxes exactTreeBoxes(uint32_t group, const std::function<BoxFloats(uint32_t prim)>& primitiveBox) const;
  /// Child c's box as `node` stores it, decoded as the trace decodes it.
  static BoxFloats childBox(const gpu::BvhNode& node, int c);
  /// Child c's box of node slot `node` as the trace tests it: its exact box
  /// where the forest keeps them (whose nodes then hold no quantised boxes),
  /// else the node's own, decoded. An empty child has lo above hi.
  BoxFloats storedChildBox(uint32_t node, int c) const;

  std::vector<gpu::BvhNode> nodes;
  /// With BvhChildBoxes::Exact, each node's children's exact boxes as the
  /// trace reads them (child 0's at 2 n, child 1's at 2 n + 1); else empty.
  std::vector<BoxFloats> exactChildBoxes;
  /// Where the forest keeps them, each node's 4-wide record (entries 4 n to 4 n + 3); else empty.
  std::vector<gpu::BvhWideEntry> wideRecords;
  std::vector<gpu::BvhGroup> groups;
  std::vector<double> sah;  ///< per group: SAH cost its last refit measured (a multiple of the root's area)
};

/// What the leaves are boxed from: triangles (positions, indices), or instances
/// of a bottom level (gpu::GpuInstance[] and that forest).
struct BvhInputs {
  const vk::Buffer* positions = nullptr;
  const vk::Buffer* indices = nullptr;
  const vk::Buffer* instances = nullptr;
  const Bvh* blas = nullptr;
};

/// Rounds of treelet restructuring after H-PLOC (bvh_restructure.comp): each
/// round costs one bottom-up pass. Off by default: see bench/results for when it pays.
inline constexpr uint32_t kDefaultRestructureRounds = 0;

/// Workgroup shapes of the build and refit; zero fields are chosen from the device.
struct BvhTuning {
  uint32_t hplocWorkgroup = 0;  ///< H-PLOC invocations per workgroup (a multiple of the subgroup size)
  uint32_t refitWorkgroup = 0;
};

class BvhBuilder {
 public:
  explicit BvhBuilder(vk::Context& context, BvhTuning tuning = {});
  ~BvhBuilder();

  /// Its pipelines on `context`'s device, in build order (build boxes,
  /// Morton codes, H-PLOC, refit, restructure, quantise); the sorts are RadixSort's.
  static std::vector<vk::ComputeProgramDesc> programDescs(const vk::Context& context, BvhTuning tuning = {});

  /// Allocates a forest whose group g holds primitives [sum of earlier sizes, + groupSizes[g]).
  Bvh makeBvh(const std::vector<uint32_t>& groupSizes, BvhLeaves leaves, const std::string& name,
              BvhChildBoxes childBoxes = BvhChildBoxes::Exact) const;

  /// Records a build of the listed groups (every group when `groups` is
  /// empty; empty groups are skipped). The inputs must be visible to compute;
  /// the trees are visible to compute and transfer after.
  void recordBuild(vk::Commands& commands, Bvh& bvh, const BvhInputs& inputs, std::span<const uint32_t> groups,
                   vk::UploadArena& arena, uint32_t restructureRounds = kDefaultRestructureRounds);
  /// Records a refit of the listed groups (every group when empty): new boxes,
  /// the same topology, and each tree's SAH in Bvh::stats.
  void recordRefit(vk::Commands& commands, Bvh& bvh, const BvhInputs& inputs, std::span<const uint32_t> groups,
                   vk::UploadArena& arena);

  /// Each build step opens its own timed pass (render/pass_names.h: kBvh*),
  /// for a breakdown; off, a caller's own pass around the build times it whole.
  void setStepTiming(bool on) { stepTiming_ = on; }

  /// Reads a forest back (waits for the GPU).
  BvhSnapshot download(const Bvh& bvh) const;

  /// Frees the build scratch (sort buffers, primitive boxes): builds allocate it again.
  void releaseScratch();
  uint64_t scratchBytes() const;

  /// The SAH cost (a multiple of the root's area) a refit measured, from its
  /// entry in Bvh::stats: 0 for a group it did not refit.
  static double sahCost(const glm::uvec4& stats);

 private:
  struct Scratch;
  void ensureScratch(vk::Commands& commands, uint64_t primitives);
  void recordRestructure(vk::Commands& commands, Bvh& bvh, uint32_t entryCount, uint32_t primitives);

  vk::Context& context_;
  RadixSort sort32_, sort64_;
  std::shared_ptr<Scratch> scratch_;
  vk::Buffer placeholder_;
  std::unique_ptr<vk::ComputeProgram> boxes_, morton_, hploc_, refit_, restructure_, quantise_;
  bool stepTiming_ = false;
};

}  // namespace snell::render
