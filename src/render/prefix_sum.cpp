// Host side of the prefix sum (shaders/comp/scan_reduce.comp, scan_block.comp).
#include "render/prefix_sum.h"

#include "shared/prefix_sum.h"
#include "vk/error.h"

#include "scan_block.spv.h"
#include "scan_reduce.spv.h"

#include <algorithm>

namespace snell::render {

namespace {
constexpr uint32_t kItemsPerThread = 8;
}

uint32_t fullSubgroupWorkgroupSize(const vk::DeviceCaps& caps, uint32_t preferred) {
  uint32_t size = std::min(preferred, caps.maxComputeWorkgroupInvocations);
  while (size > caps.maxSubgroupSize && size % caps.maxSubgroupSize != 0) --size;
  if (size < caps.maxSubgroupSize || size % caps.maxSubgroupSize != 0) {
    throw vk::VulkanError("no workgroup size up to " + std::to_string(preferred) + " holds whole subgroups of " +
                          std::to_string(caps.maxSubgroupSize));
  }
  return size;
}

std::vector<vk::ComputeProgramDesc> PrefixSum::programDescs(const vk::Context& context) {
  const vk::DeviceCaps& caps = context.caps();
  uint32_t workgroup = fullSubgroupWorkgroupSize(caps, 256);
  std::vector<vk::SpecConstant> spec = {
      {gpu::kScanSpecWorkgroupSize, workgroup},
      {gpu::kScanSpecItemsPerThread, kItemsPerThread},
      {gpu::kScanSpecMaxSubgroups, workgroup / caps.minSubgroupSize},
  };
  return {vk::ComputeProgramDesc{"scan_reduce", kSpvScanReduce, spec, true},
          vk::ComputeProgramDesc{"scan_block", kSpvScanBlock, spec, true}};
}

PrefixSum::PrefixSum(vk::Context& context) : context_(context) {
  tile_ = fullSubgroupWorkgroupSize(context.caps(), 256) * kItemsPerThread;
  std::vector<vk::ComputeProgramDesc> descs = programDescs(context);
  reduce_ = std::make_unique<vk::ComputeProgram>(context, descs[0]);
  scanBlock_ = std::make_unique<vk::ComputeProgram>(context, descs[1]);
}

PrefixSum::Scratch PrefixSum::makeScratch(uint64_t count) const {
  Scratch scratch;
  scratch.capacity = count;
  uint64_t n = count;
  while (n > tile_) {
    n = (n + tile_ - 1) / tile_;
    scratch.levels.emplace_back(context_, vk::BufferDesc{n * sizeof(uint32_t), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                                         vk::MemoryDomain::Device,
                                                         "scan partials " + std::to_string(scratch.levels.size())});
  }
  return scratch;
}

void PrefixSum::record(vk::Commands& commands, const vk::Buffer& data, uint64_t count, const Scratch& scratch) const {
  if (count > scratch.capacity) {
    throw vk::VulkanError("prefix sum of " + std::to_string(count) + " elements given scratch for " +
                          std::to_string(scratch.capacity));
  }
  if (count > UINT32_MAX) throw vk::VulkanError("prefix sum of more than 2^32 - 1 elements");
  if (count == 0) return;
  recordLevel(commands, data, count, scratch, 0);
}

void PrefixSum::recordLevel(vk::Commands& commands, const vk::Buffer& data, uint64_t count, const Scratch& scratch,
                            size_t level) const {
  uint32_t blocks = static_cast<uint32_t>((count + tile_ - 1) / tile_);
  gpu::ScanPush push{static_cast<uint32_t>(count), blocks, 0, 0};
  if (blocks == 1) {
    // Nothing to carry in; the partials slot still needs a valid buffer.
    scanBlock_->dispatchGroups(commands, {{gpu::kScanBindingData, &data}, {gpu::kScanBindingPartials, &data}}, push, 1);
    return;
  }
  const vk::Buffer& partials = scratch.levels.at(level);
  reduce_->dispatchGroups(commands, {{gpu::kScanBindingData, &data}, {gpu::kScanBindingPartials, &partials}}, push, blocks);
  commands.computeToCompute();
  recordLevel(commands, partials, blocks, scratch, level + 1);
  commands.computeToCompute();
  push.addPartials = 1;
  scanBlock_->dispatchGroups(commands, {{gpu::kScanBindingData, &data}, {gpu::kScanBindingPartials, &partials}}, push, blocks);
}

}  // namespace snell::render
