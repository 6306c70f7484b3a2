// Exclusive prefix sum over uint32 on the GPU: reduce, scan the block sums
// (recursively), then scan each block with its carry-in. Three dispatches per
// level and no workgroup ever waits on another, so it is portable to any
// Vulkan 1.3 device; the BVH builder and the radix sort both stand on it.
#pragma once

#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "vk/context.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace snell::render {

class PrefixSum {
 public:
  explicit PrefixSum(vk::Context& context);

  /// Its two pipelines on `context`'s device (reduce, scan a block).
  static std::vector<vk::ComputeProgramDesc> programDescs(const vk::Context& context);

  /// Buffers for the block sums of every level a scan of `count` elements needs.
  struct Scratch {
    uint64_t capacity = 0;
    std::vector<vk::Buffer> levels;
  };
  Scratch makeScratch(uint64_t count) const;

  /// Records an in-place exclusive scan of `data[0, count)`. The caller makes
  /// the input visible to compute before, and the output visible after.
  void record(vk::Commands& commands, const vk::Buffer& data, uint64_t count, const Scratch& scratch) const;

  /// Elements one workgroup scans.
  uint32_t tileSize() const { return tile_; }

 private:
  void recordLevel(vk::Commands& commands, const vk::Buffer& data, uint64_t count, const Scratch& scratch,
                   size_t level) const;
  vk::Context& context_;
  uint32_t tile_ = 0;
  std::unique_ptr<vk::ComputeProgram> reduce_;
  std::unique_ptr<vk::ComputeProgram> scanBlock_;
};

/// Picks the widest workgroup up to `preferred` invocations that the device
/// runs as full subgroups.
uint32_t fullSubgroupWorkgroupSize(const vk::DeviceCaps& caps, uint32_t preferred);

}  // namespace snell::render
