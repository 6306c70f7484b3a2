// Host side of the BVH passes (shaders/comp/bvh/*.comp).
#include "render/bvh.h"

#include "vk/error.h"

#include "bvh_centroid_bounds.spv.h"
#include "bvh_fit.spv.h"
#include "bvh_hierarchy.spv.h"
#include "bvh_instance_boxes.spv.h"
#include "bvh_morton.spv.h"
#include "bvh_restructure.spv.h"
#include "bvh_triangle_boxes.spv.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <numeric>

namespace snell::render {

namespace {

constexpr uint32_t kWorkgroupSize = 64;

std::unique_ptr<vk::ComputeProgram> program(vk::Context& context, const char* name, std::span<const uint32_t> spirv) {
  return std::make_unique<vk::ComputeProgram>(
      context, vk::ComputeProgramDesc{name, spirv, {{gpu::kBvhSpecWorkgroupSize, kWorkgroupSize}}, false});
}

vk::Buffer deviceBuffer(vk::Context& context, VkDeviceSize bytes, const std::string& name) {
  return vk::Buffer(context, {std::max<VkDeviceSize>(bytes, 16),
                              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                  VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                              vk::MemoryDomain::Device, name});
}

}  // namespace

uint32_t Bvh::firstPrimitive(uint32_t group) const {
  return std::accumulate(groupSizes.begin(), groupSizes.begin() + group, 0u);
}

BvhBuilder::BvhBuilder(vk::Context& context) : context_(context), sort_(context, KeyWidth::Bits64) {
  triangleBoxes_ = program(context, "bvh triangle boxes", kSpvBvhTriangleBoxes);
  instanceBoxes_ = program(context, "bvh instance boxes", kSpvBvhInstanceBoxes);
  centroidBounds_ = program(context, "bvh centroid bounds", kSpvBvhCentroidBounds);
  morton_ = program(context, "bvh morton", kSpvBvhMorton);
  hierarchy_ = program(context, "bvh hierarchy", kSpvBvhHierarchy);
  // One subgroup per workgroup: lavapipe (Mesa 22.3) dropped boxes handed
  // between subgroups of one workgroup through the arrival counters, though
  // the same exchange between workgroups, or within a subgroup, held.
  fit_ = std::make_unique<vk::ComputeProgram>(
      context, vk::ComputeProgramDesc{"bvh fit", kSpvBvhFit,
                                      {{gpu::kBvhSpecWorkgroupSize, context.caps().maxSubgroupSize}}, false});
  // The same walk as the fit, so the same workgroup shape.
  restructure_ = std::make_unique<vk::ComputeProgram>(
      context, vk::ComputeProgramDesc{"bvh restructure", kSpvBvhRestructure,
                                      {{gpu::kBvhSpecWorkgroupSize, context.caps().maxSubgroupSize}}, false});
}

BvhBuilder::~BvhBuilder() = default;

Bvh BvhBuilder::makeBvh(const std::vector<uint32_t>& groupSizes, const std::string& name) const {
  Bvh bvh;
  bvh.groupSizes = groupSizes;
  uint64_t total = std::accumulate(groupSizes.begin(), groupSizes.end(), uint64_t(0));
  if (total >= gpu::kBvhLeafBit || total > sort_.maxCount()) {
    throw vk::VulkanError(name + ": " + std::to_string(total) + " primitives are more than one BVH can hold on this device (" +
                          std::to_string(std::min<uint64_t>(gpu::kBvhLeafBit - 1, sort_.maxCount())) + ")");
  }
  bvh.primitiveCount = static_cast<uint32_t>(total);
  uint64_t n = std::max<uint64_t>(total, 1);
  bvh.primBoxes = deviceBuffer(context_, n * 24, name + " primitive boxes");
  bvh.keys = deviceBuffer(context_, n * 8, name + " keys");
  bvh.leafPrims = deviceBuffer(context_, n * 4, name + " leaf primitives");
  bvh.leafParents = deviceBuffer(context_, n * 4, name + " leaf parents");
  bvh.nodes = deviceBuffer(context_, n * sizeof(gpu::BvhNode), name + " nodes");
  bvh.counters = deviceBuffer(context_, n * 4, name + " counters");
  bvh.dropped = deviceBuffer(context_, 4, name + " dropped triangles");
  bvh.sortScratch = sort_.makeScratch(n);

  std::vector<uint32_t> primGroups;
  std::vector<gpu::BvhGroup> groups(std::max<size_t>(groupSizes.size(), 1));
  uint32_t first = 0;
  for (size_t g = 0; g < groups.size(); ++g) {
    gpu::BvhGroup& group = groups[g];
    std::fill(std::begin(group.centroidLo), std::end(group.centroidLo), 0xffffffffu);
    std::fill(std::begin(group.centroidHi), std::end(group.centroidHi), 0xffffffffu);
    group.root = gpu::kBvhNone;
    group.first = first;
    group.count = g < groupSizes.size() ? groupSizes[g] : 0;
    std::fill(std::begin(group.boxLo), std::end(group.boxLo), INFINITY);
    std::fill(std::begin(group.boxHi), std::end(group.boxHi), -INFINITY);
    primGroups.insert(primGroups.end(), group.count, static_cast<uint32_t>(g));
    first += group.count;
  }
  VkDeviceSize groupBytes = groups.size() * sizeof(gpu::BvhGroup);
  bvh.groups = deviceBuffer(context_, groupBytes, name + " groups");
  bvh.groupsInitial = vk::Buffer(context_, {groupBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryDomain::Upload,
                                            name + " groups (initial)"});
  std::memcpy(bvh.groupsInitial.mapped().data(), groups.data(), groupBytes);
  bvh.primGroups = deviceBuffer(context_, primGroups.size() * 4, name + " primitive groups");
  if (!primGroups.empty()) vk::upload(context_, bvh.primGroups, primGroups.data(), primGroups.size() * 4);

  vk::Commands commands(context_, name + " setup");
  commands.begin();
  // Nodes above the group roots are never fitted; zeroed, they read the same every time.
  commands.fillBuffer(bvh.nodes, 0);
  commands.fillBuffer(bvh.dropped, 0);
  commands.copyBuffer(bvh.groupsInitial, bvh.groups, groupBytes);
  commands.transferToCompute();
  commands.submitAndWait();
  return bvh;
}

void BvhBuilder::recordTriangleBoxes(vk::Commands& commands, const Bvh& bvh, const vk::Buffer& positions,
                                     const vk::Buffer& indices, uint32_t first, uint32_t count) const {
  gpu::BvhPush push{count, first, bvh.groupCount(), bvh.primitiveCount};
  triangleBoxes_->dispatchThreads(commands,
                                  {{gpu::kBvhBindingPositions, &positions},
                                   {gpu::kBvhBindingIndices, &indices},
                                   {gpu::kBvhBindingPrimBoxes, &bvh.primBoxes},
                                   {gpu::kBvhBindingDropped, &bvh.dropped}},
                                  push, count);
}

void BvhBuilder::recordInstanceBoxes(vk::Commands& commands, const Bvh& bvh, const vk::Buffer& instances,
                                     const Bvh& blas) const {
  gpu::BvhPush push{bvh.primitiveCount, 0, bvh.groupCount(), bvh.primitiveCount};
  instanceBoxes_->dispatchThreads(commands,
                                  {{gpu::kBvhBindingInstances, &instances},
                                   {gpu::kBvhBindingBlasGroups, &blas.groups},
                                   {gpu::kBvhBindingPrimBoxes, &bvh.primBoxes}},
                                  push, bvh.primitiveCount);
}

void BvhBuilder::recordBuild(vk::Commands& commands, const Bvh& bvh, uint32_t restructureRounds) const {
  uint32_t n = bvh.primitiveCount;
  VkDeviceSize groupBytes = std::max<size_t>(bvh.groupSizes.size(), 1) * sizeof(gpu::BvhGroup);
  commands.copyBuffer(bvh.groupsInitial, bvh.groups, groupBytes);
  commands.transferToCompute();
  if (n == 0) return;
  gpu::BvhPush push{n, 0, bvh.groupCount(), n};
  centroidBounds_->dispatchThreads(commands,
                                   {{gpu::kBvhBindingPrimBoxes, &bvh.primBoxes},
                                    {gpu::kBvhBindingPrimGroups, &bvh.primGroups},
                                    {gpu::kBvhBindingGroups, &bvh.groups}},
                                   push, n);
  commands.computeToCompute();
  morton_->dispatchThreads(commands,
                           {{gpu::kBvhBindingPrimBoxes, &bvh.primBoxes},
                            {gpu::kBvhBindingPrimGroups, &bvh.primGroups},
                            {gpu::kBvhBindingGroups, &bvh.groups},
                            {gpu::kBvhBindingKeys, &bvh.keys},
                            {gpu::kBvhBindingLeafPrims, &bvh.leafPrims}},
                           push, n);
  commands.computeToCompute();
  uint32_t groupBits = static_cast<uint32_t>(std::bit_width(std::max<uint32_t>(bvh.groupCount(), 1) - 1));
  sort_.record(commands, bvh.keys, bvh.leafPrims, n, bvh.sortScratch, gpu::kBvhMortonBits + groupBits);
  hierarchy_->dispatchThreads(commands,
                              {{gpu::kBvhBindingKeys, &bvh.keys},
                               {gpu::kBvhBindingLeafPrims, &bvh.leafPrims},
                               {gpu::kBvhBindingNodes, &bvh.nodes},
                               {gpu::kBvhBindingLeafParents, &bvh.leafParents},
                               {gpu::kBvhBindingGroups, &bvh.groups}},
                              push, std::max<uint32_t>(n - 1, 1));
  commands.computeToCompute();
  recordFit(commands, bvh, 0, n);
  for (uint32_t round = 0; round < restructureRounds && n > 2; ++round) recordRestructure(commands, bvh);
}

void BvhBuilder::recordRestructure(vk::Commands& commands, const Bvh& bvh) const {
  uint32_t n = bvh.primitiveCount;
  gpu::BvhPush push{n, 0, bvh.groupCount(), n};
  commands.fillBuffer(bvh.counters, 0);
  commands.transferToCompute();
  restructure_->dispatchThreads(commands,
                                {{gpu::kBvhBindingPrimBoxes, &bvh.primBoxes},
                                 {gpu::kBvhBindingLeafPrims, &bvh.leafPrims},
                                 {gpu::kBvhBindingLeafParents, &bvh.leafParents},
                                 {gpu::kBvhBindingNodes, &bvh.nodes},
                                 {gpu::kBvhBindingCounters, &bvh.counters},
                                 {gpu::kBvhBindingNodeStats, &bvh.keys}},
                                push, n);
  commands.computeToCompute();
  commands.computeToTransfer();
}

void BvhBuilder::recordRefit(vk::Commands& commands, const Bvh& bvh, uint32_t group) const {
  recordFit(commands, bvh, bvh.firstPrimitive(group), bvh.groupSizes.at(group));
}

void BvhBuilder::recordFit(vk::Commands& commands, const Bvh& bvh, uint32_t first, uint32_t count) const {
  if (count == 0) return;
  gpu::BvhPush push{count, first, bvh.groupCount(), bvh.primitiveCount};
  commands.fillBuffer(bvh.counters, 0);
  commands.transferToCompute();
  fit_->dispatchThreads(commands,
                        {{gpu::kBvhBindingPrimBoxes, &bvh.primBoxes},
                         {gpu::kBvhBindingPrimGroups, &bvh.primGroups},
                         {gpu::kBvhBindingLeafPrims, &bvh.leafPrims},
                         {gpu::kBvhBindingLeafParents, &bvh.leafParents},
                         {gpu::kBvhBindingNodes, &bvh.nodes},
                         {gpu::kBvhBindingCounters, &bvh.counters},
                         {gpu::kBvhBindingGroups, &bvh.groups}},
                        push, count);
  commands.computeToCompute();
  commands.computeToTransfer();
}

BvhSnapshot BvhBuilder::download(const Bvh& bvh) const {
  BvhSnapshot s;
  uint32_t n = bvh.primitiveCount;
  s.nodes.resize(n > 1 ? n - 1 : 0);
  s.groups.resize(std::max<size_t>(bvh.groupSizes.size(), 1));
  s.leafPrims.resize(n);
  s.leafParents.resize(n);
  vk::download(context_, bvh.nodes, s.nodes.data(), s.nodes.size() * sizeof(gpu::BvhNode));
  vk::download(context_, bvh.groups, s.groups.data(), s.groups.size() * sizeof(gpu::BvhGroup));
  vk::download(context_, bvh.leafPrims, s.leafPrims.data(), n * 4);
  vk::download(context_, bvh.leafParents, s.leafParents.data(), n * 4);
  return s;
}

BvhSnapshot::TreeBoxes BvhSnapshot::treeBoxes(uint32_t group) const {
  const gpu::BvhGroup& g = groups.at(group);
  TreeBoxes boxes;
  boxes.internal.push_back({g.boxLo[0], g.boxLo[1], g.boxLo[2], g.boxHi[0], g.boxHi[1], g.boxHi[2]});
  std::vector<uint32_t> stack;
  if (!(g.root & gpu::kBvhLeafBit) && g.root != gpu::kBvhNone) stack.push_back(g.root);
  // Bounded by the node count, so a corrupted tree cannot loop forever.
  while (!stack.empty() && boxes.internal.size() <= nodes.size()) {
    const gpu::BvhNode& node = nodes.at(stack.back());
    stack.pop_back();
    for (int c = 0; c < 2; ++c) {
      BoxFloats b;
      std::copy_n(&node.box[6 * c], 6, b.begin());
      if (node.child[c] & gpu::kBvhLeafBit) {
        boxes.leaves.push_back(b);
      } else {
        boxes.internal.push_back(b);
        stack.push_back(node.child[c]);
      }
    }
  }
  return boxes;
}

}  // namespace snell::render
