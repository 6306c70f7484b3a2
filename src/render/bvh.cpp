// Host side of the BVH passes (shaders/comp/bvh/*.comp).
#include "render/bvh.h"

#include "render/pass_names.h"
#include "vk/error.h"

#include "bvh_build_boxes.spv.h"
#include "bvh_hploc.spv.h"
#include "bvh_morton.spv.h"
#include "bvh_quantise.spv.h"
#include "bvh_refit.spv.h"
#include "bvh_restructure.spv.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <numeric>

namespace snell::render {

namespace {

uint32_t flagsOf(const Bvh& bvh) {
  return (bvh.leaves == BvhLeaves::Instances ? gpu::kBvhFlagInstances : 0u) |
         (bvh.childBoxes == BvhChildBoxes::Exact ? gpu::kBvhFlagChildBoxes : 0u) |
         (bvh.hasWideRecords() ? gpu::kBvhFlagWideRecords : 0u);
}

// One subgroup per workgroup for the passes that hand boxes from one
// invocation to another through device atomics: lavapipe (Mesa 22.3) lost
// boxes handed between subgroups of one workgroup that way, though the same
// exchange between workgroups, or within a subgroup, held (tests/bvh_test.cpp).
uint32_t handOffWorkgroup(const vk::Context& context) {
  uint32_t subgroup = context.caps().maxSubgroupSize;
  return context.facts().type == VK_PHYSICAL_DEVICE_TYPE_CPU ? subgroup : std::max(subgroup, 64u);
}

}  // namespace

bool keepsWideRecords(const vk::Context& context, BvhLeaves leaves, BvhChildBoxes childBoxes, uint64_t primitives) {
  return leaves == BvhLeaves::Triangles && childBoxes == BvhChildBoxes::Exact &&
         primitives * 4 * sizeof(gpu::BvhWideEntry) <= context.caps().maxStorageBufferRange;
}

uint64_t Bvh::treeBytes() const {
  return nodes.size() + groups.size() + (childBoxes == BvhChildBoxes::Exact ? exactChildBoxes.size() : 0) +
         (hasWideRecords() ? wideRecords.size() : 0);
}

uint64_t Bvh::workBytes() const {
  uint64_t bytes = 0;
  for (const vk::Buffer* b : {&stats, &dropped, &buildEntries, &refitEntries, &exactBoxes}) bytes += b->size();
  return bytes;
}

struct BvhBuilder::Scratch {
  uint64_t primitives = 0;
  vk::Buffer primBoxes, keys, values, parentIds, clusters, counters, nodeStats;
  RadixSort::Scratch sort32, sort64;
};

std::vector<vk::ComputeProgramDesc> BvhBuilder::programDescs(const vk::Context& context, BvhTuning tuning) {
  auto program = [](const char* name, std::span<const uint32_t> spirv, std::vector<vk::SpecConstant> spec) {
    return vk::ComputeProgramDesc{name, spirv, std::move(spec), false};
  };
  // H-PLOC's teams are subgroups, each clustering one window. One team per
  // workgroup: lavapipe needs it (above), and on an H100 a 1M-triangle sphere
  // built in 1.13 ms with 32 invocations against 1.22 ms with 128, 10M in 8.3
  // against 8.9 ms (same run, bench/results/scale.md).
  const vk::DeviceCaps& caps = context.caps();
  uint32_t hplocWidth = tuning.hplocWorkgroup ? tuning.hplocWorkgroup : caps.maxSubgroupSize;
  return {
      program("bvh build boxes", kSpvBvhBuildBoxes, {{gpu::kBvhSpecWorkgroupSize, 64}}),
      program("bvh morton", kSpvBvhMorton, {{gpu::kBvhSpecWorkgroupSize, 64}}),
      vk::ComputeProgramDesc{"bvh hploc",
                             kSpvBvhHploc,
                             {{gpu::kBvhSpecWorkgroupSize, hplocWidth},
                              {gpu::kBvhSpecSlots, (gpu::kBvhWindow + caps.minSubgroupSize - 1) / caps.minSubgroupSize},
                              {gpu::kBvhSpecTeams, hplocWidth / caps.minSubgroupSize}},
                             true},
      program("bvh refit", kSpvBvhRefit,
              {{gpu::kBvhSpecWorkgroupSize, tuning.refitWorkgroup ? tuning.refitWorkgroup : handOffWorkgroup(context)}}),
      program("bvh restructure", kSpvBvhRestructure, {{gpu::kBvhSpecWorkgroupSize, handOffWorkgroup(context)}}),
      program("bvh quantise", kSpvBvhQuantise, {{gpu::kBvhSpecWorkgroupSize, 64}}),
  };
}

BvhBuilder::BvhBuilder(vk::Context& context, BvhTuning tuning)
    : context_(context), sort32_(context, KeyWidth::Bits32), sort64_(context, KeyWidth::Bits64) {
  std::vector<vk::ComputeProgramDesc> descs = programDescs(context, tuning);
  std::unique_ptr<vk::ComputeProgram>* programs[] = {&boxes_, &morton_, &hploc_, &refit_, &restructure_, &quantise_};
  for (size_t i = 0; i < descs.size(); ++i) *programs[i] = std::make_unique<vk::ComputeProgram>(context, descs[i]);
  placeholder_ = vk::storageBuffer(context, 16, "bvh placeholder");
}

BvhBuilder::~BvhBuilder() = default;

Bvh BvhBuilder::makeBvh(const std::vector<uint32_t>& groupSizes, BvhLeaves leaves, const std::string& name,
                        BvhChildBoxes childBoxes) const {
  Bvh bvh;
  bvh.leaves = leaves;
  bvh.childBoxes = childBoxes;
  bvh.name = name;
  bvh.groupSizes = groupSizes;
  uint64_t primitives = 0;
  for (uint32_t size : groupSizes) {
    bvh.first.push_back(static_cast<uint32_t>(primitives));
    primitives += size;
  }
  uint64_t limit = std::min<uint64_t>(gpu::kBvhMaxPrimitives - 1, sort64_.maxCount());
  if (primitives > limit) {
    throw vk::VulkanError(name + ": " + std::to_string(primitives) +
                          " primitives are more than one BVH can hold on this device (" + std::to_string(limit) + ")");
  }
  bvh.primitiveCount = static_cast<uint32_t>(primitives);
  bvh.wide = keepsWideRecords(context_, leaves, childBoxes, primitives);
  size_t groupCount = std::max<size_t>(groupSizes.size(), 1);
  bvh.nodes = vk::storageBuffer(context_, primitives * sizeof(gpu::BvhNode), name + " nodes");
  bvh.groups = vk::storageBuffer(context_, groupCount * sizeof(gpu::BvhGroup), name + " groups");
  bvh.stats = vk::storageBuffer(context_, groupCount * 16, name + " SAH statistics");
  bvh.dropped = vk::storageBuffer(context_, 4, name + " dropped triangles");
  bvh.buildEntries = vk::storageBuffer(context_, groupCount * sizeof(gpu::BvhBuildEntry), name + " build list");
  bvh.refitEntries = vk::storageBuffer(context_, groupCount * sizeof(gpu::BvhRefitEntry), name + " refit list");
  // Every build and refit passes exact boxes up through them.
  bvh.exactBoxes = vk::storageBuffer(context_, primitives * 24, name + " exact boxes");
  bool exact = childBoxes == BvhChildBoxes::Exact;
  bvh.exactChildBoxes = vk::storageBuffer(context_, exact ? primitives * gpu::kBvhChildBoxBytes : 16, name + " exact child boxes");
  bvh.wideRecords = vk::storageBuffer(context_, bvh.hasWideRecords() ? primitives * 4 * sizeof(gpu::BvhWideEntry) : 16,
                                      name + " 4-wide records");

  std::vector<gpu::BvhGroup> groups(groupCount);
  for (size_t g = 0; g < groups.size(); ++g) {
    gpu::BvhGroup& group = groups[g];
    std::fill(std::begin(group.boxLo), std::end(group.boxLo), INFINITY);
    std::fill(std::begin(group.boxHi), std::end(group.boxHi), -INFINITY);
    group.root = gpu::kBvhNone;
    if (g < groupSizes.size()) {
      group.first = bvh.first[g];
      group.count = groupSizes[g];
    }
  }
  vk::upload(context_, bvh.groups, groups.data(), groups.size() * sizeof(gpu::BvhGroup));
  vk::Commands commands(context_, name + " setup");
  commands.begin();
  // Slots of unbuilt groups (and a group's one slot no node takes) read the
  // same every time; arrival counts start even.
  commands.fillBuffer(bvh.nodes, 0);
  commands.fillBuffer(bvh.wideRecords, 0);
  commands.fillBuffer(bvh.dropped, 0);
  commands.fillBuffer(bvh.stats, 0);
  commands.transferToCompute();
  commands.submitAndWait();
  return bvh;
}

void BvhBuilder::ensureScratch(vk::Commands& commands, uint64_t primitives) {
  if (scratch_ && scratch_->primitives >= primitives) return;
  // An earlier build recorded into the same commands may still use the old scratch.
  if (scratch_) commands.keepAlive(scratch_);
  auto s = std::make_shared<Scratch>();
  s->primitives = std::max<uint64_t>(primitives, scratch_ ? scratch_->primitives : 0);
  s->primBoxes = vk::storageBuffer(context_, s->primitives * 24, "bvh build primitive boxes");
  s->keys = vk::storageBuffer(context_, s->primitives * 8, "bvh build keys");
  s->values = vk::storageBuffer(context_, s->primitives * 4, "bvh build values");
  s->parentIds = vk::storageBuffer(context_, s->primitives * 4, "bvh build meeting points");
  s->clusters = vk::storageBuffer(context_, s->primitives * sizeof(gpu::BvhCluster), "bvh build clusters");
  scratch_ = std::move(s);
}

void BvhBuilder::releaseScratch() { scratch_.reset(); }

uint64_t BvhBuilder::scratchBytes() const {
  if (!scratch_) return 0;
  uint64_t bytes = 0;
  const Scratch& s = *scratch_;
  for (const vk::Buffer* b : {&s.primBoxes, &s.keys, &s.values, &s.parentIds, &s.clusters, &s.counters, &s.nodeStats,
                              &s.sort32.keys, &s.sort32.values, &s.sort32.histogram, &s.sort64.keys, &s.sort64.values,
                              &s.sort64.histogram}) {
    bytes += b->size();
  }
  return bytes;
}

void BvhBuilder::recordBuild(vk::Commands& commands, Bvh& bvh, const BvhInputs& inputs,
                             std::span<const uint32_t> groups, vk::UploadArena& arena, uint32_t restructureRounds) {
  std::vector<uint32_t> all;
  if (groups.empty()) {
    all.resize(bvh.groupCount());
    std::iota(all.begin(), all.end(), 0u);
    groups = all;
  }
  std::vector<gpu::BvhBuildEntry> entries;
  uint64_t positions = 0;
  for (uint32_t g : groups) {
    uint32_t size = bvh.groupSizes.at(g);
    if (size == 0) continue;
    gpu::BvhBuildEntry e{};
    e.group = g;
    e.first = bvh.first[g];
    e.count = size;
    e.base = static_cast<uint32_t>(positions);
    std::fill(std::begin(e.centroidLo), std::end(e.centroidLo), 0xffffffffu);
    std::fill(std::begin(e.centroidHi), std::end(e.centroidHi), 0xffffffffu);
    entries.push_back(e);
    positions += size;
  }
  if (entries.empty()) return;
  ensureScratch(commands, positions);
  Scratch& s = *scratch_;
  uint32_t entryBits = static_cast<uint32_t>(std::bit_width(entries.size() - 1));
  uint32_t keyBits = gpu::kBvhMortonBits + entryBits;
  bool keys32 = keyBits <= 32;
  const RadixSort& sort = keys32 ? sort32_ : sort64_;
  RadixSort::Scratch& sortScratch = keys32 ? s.sort32 : s.sort64;
  if (sortScratch.capacity < positions) sortScratch = sort.makeScratch(s.primitives);

  arena.copy(commands, entries, bvh.buildEntries);
  commands.fillBuffer(s.parentIds, gpu::kBvhNone, 0, positions * 4);
  commands.transferToCompute();
  uint32_t flags = flagsOf(bvh) | (keys32 ? gpu::kBvhFlagKeys32 : 0u);
  uint32_t entryCount = static_cast<uint32_t>(entries.size());
  bool instances = bvh.leaves == BvhLeaves::Instances;
  gpu::BvhPush push{static_cast<uint32_t>(positions), entryCount, flags, bvh.primitiveCount};
  if (stepTiming_) commands.beginPass(pass::kBvhBoxes);
  boxes_->dispatchThreads(commands,
                          {{gpu::kBvhBindingBuildEntries, &bvh.buildEntries},
                           {gpu::kBvhBindingPositions, instances ? &placeholder_ : inputs.positions},
                           {gpu::kBvhBindingIndices, instances ? &placeholder_ : inputs.indices},
                           {gpu::kBvhBindingInstances, instances ? inputs.instances : &placeholder_},
                           {gpu::kBvhBindingBlasGroups, instances ? &inputs.blas->groups : &placeholder_},
                           {gpu::kBvhBindingPrimBoxes, &s.primBoxes},
                           {gpu::kBvhBindingDropped, &bvh.dropped}},
                          push, positions);
  commands.computeToCompute();
  if (stepTiming_) commands.beginPass(pass::kBvhMorton);
  morton_->dispatchThreads(commands,
                           {{gpu::kBvhBindingBuildEntries, &bvh.buildEntries},
                            {gpu::kBvhBindingPrimBoxes, &s.primBoxes},
                            {gpu::kBvhBindingKeys, &s.keys},
                            {gpu::kBvhBindingValues, &s.values}},
                           push, positions);
  commands.computeToCompute();
  if (stepTiming_) commands.beginPass(pass::kBvhSort);
  sort.record(commands, s.keys, s.values, positions, sortScratch, keyBits);
  if (stepTiming_) commands.beginPass(pass::kBvhHploc);
  hploc_->dispatchThreads(commands,
                          {{gpu::kBvhBindingBuildEntries, &bvh.buildEntries},
                           {gpu::kBvhBindingKeys, &s.keys},
                           {gpu::kBvhBindingValues, &s.values},
                           {gpu::kBvhBindingPrimBoxes, &s.primBoxes},
                           {gpu::kBvhBindingParentIds, &s.parentIds},
                           {gpu::kBvhBindingClusters, &s.clusters},
                           {gpu::kBvhBindingNodes, &bvh.nodes},
                           {gpu::kBvhBindingExactBoxes, &bvh.exactBoxes},
                           {gpu::kBvhBindingGroups, &bvh.groups}},
                          push, positions);
  commands.computeToCompute();
  for (uint32_t round = 0; round < restructureRounds; ++round) {
    recordRestructure(commands, bvh, entryCount, static_cast<uint32_t>(positions));
  }
  if (stepTiming_) commands.beginPass(pass::kBvhQuantise);
  quantise_->dispatchThreads(commands,
                             {{gpu::kBvhBindingBuildEntries, &bvh.buildEntries},
                              {gpu::kBvhBindingPrimBoxes, &s.primBoxes},
                              {gpu::kBvhBindingExactBoxes, &bvh.exactBoxes},
                              {gpu::kBvhBindingChildBoxes, &bvh.exactChildBoxes},
                              {gpu::kBvhBindingWideRecords, &bvh.wideRecords},
                              {gpu::kBvhBindingNodes, &bvh.nodes}},
                             push, positions);
  commands.computeToCompute();
  if (stepTiming_) commands.endPass();
  commands.computeToTransfer();
}

void BvhBuilder::recordRestructure(vk::Commands& commands, Bvh& bvh, uint32_t entryCount, uint32_t primitives) {
  Scratch& s = *scratch_;
  if (s.counters.size() < uint64_t(bvh.primitiveCount) * 4) {
    commands.keepAlive(std::make_shared<vk::Buffer>(std::move(s.counters)));  // an earlier round may use them
    commands.keepAlive(std::make_shared<vk::Buffer>(std::move(s.nodeStats)));
    s.counters = vk::storageBuffer(context_, uint64_t(bvh.primitiveCount) * 4, "bvh restructure arrivals");
    s.nodeStats = vk::storageBuffer(context_, uint64_t(bvh.primitiveCount) * 8, "bvh restructure subtree costs");
  }
  gpu::BvhPush push{primitives, entryCount, flagsOf(bvh), bvh.primitiveCount};
  commands.fillBuffer(s.counters, 0);
  commands.transferToCompute();
  restructure_->dispatchThreads(commands,
                                {{gpu::kBvhBindingBuildEntries, &bvh.buildEntries},
                                 {gpu::kBvhBindingNodes, &bvh.nodes},
                                 {gpu::kBvhBindingPrimBoxes, &s.primBoxes},
                                 {gpu::kBvhBindingExactBoxes, &bvh.exactBoxes},
                                 {gpu::kBvhBindingCounters, &s.counters},
                                 {gpu::kBvhBindingNodeStats, &s.nodeStats}},
                                push, primitives);
  commands.computeToCompute();
  commands.computeToTransfer();
}

void BvhBuilder::recordRefit(vk::Commands& commands, Bvh& bvh, const BvhInputs& inputs,
                             std::span<const uint32_t> groups, vk::UploadArena& arena) {
  std::vector<uint32_t> all;
  if (groups.empty()) {
    all.resize(bvh.groupCount());
    std::iota(all.begin(), all.end(), 0u);
    groups = all;
  }
  std::vector<gpu::BvhRefitEntry> entries;
  uint64_t threads = 0;
  for (uint32_t g : groups) {
    uint32_t size = bvh.groupSizes.at(g);
    if (size == 0) continue;
    entries.push_back({g, bvh.first[g], size, static_cast<uint32_t>(threads)});
    threads += std::max(size - 1, 1u);  // one per node slot, or the lone leaf
  }
  if (entries.empty()) return;
  arena.copy(commands, entries, bvh.refitEntries);
  commands.fillBuffer(bvh.stats, 0);
  commands.transferToCompute();
  bool instances = bvh.leaves == BvhLeaves::Instances;
  gpu::BvhPush push{static_cast<uint32_t>(threads), static_cast<uint32_t>(entries.size()), flagsOf(bvh),
                    bvh.primitiveCount};
  refit_->dispatchThreads(commands,
                          {{gpu::kBvhBindingRefitEntries, &bvh.refitEntries},
                           {gpu::kBvhBindingPositions, instances ? &placeholder_ : inputs.positions},
                           {gpu::kBvhBindingIndices, instances ? &placeholder_ : inputs.indices},
                           {gpu::kBvhBindingInstances, instances ? inputs.instances : &placeholder_},
                           {gpu::kBvhBindingBlasGroups, instances ? &inputs.blas->groups : &placeholder_},
                           {gpu::kBvhBindingNodes, &bvh.nodes},
                           {gpu::kBvhBindingExactBoxes, &bvh.exactBoxes},
                           {gpu::kBvhBindingChildBoxes, &bvh.exactChildBoxes},
                           {gpu::kBvhBindingWideRecords, &bvh.wideRecords},
                           {gpu::kBvhBindingGroups, &bvh.groups},
                           {gpu::kBvhBindingStats, &bvh.stats},
                           {gpu::kBvhBindingDropped, &bvh.dropped}},
                          push, threads);
  commands.computeToCompute();
  commands.computeToTransfer();
}

BvhSnapshot BvhBuilder::download(const Bvh& bvh) const {
  BvhSnapshot s;
  s.nodes.resize(bvh.primitiveCount);
  s.groups.resize(std::max<size_t>(bvh.groupSizes.size(), 1));
  std::vector<glm::uvec4> stats(s.groups.size());
  vk::download(context_, bvh.nodes, s.nodes.data(), s.nodes.size() * sizeof(gpu::BvhNode));
  if (bvh.childBoxes == BvhChildBoxes::Exact) {
    s.exactChildBoxes.resize(2 * s.nodes.size());
    vk::download(context_, bvh.exactChildBoxes, s.exactChildBoxes.data(), s.exactChildBoxes.size() * sizeof(BoxFloats));
  }
  if (bvh.hasWideRecords()) {
    s.wideRecords.resize(4 * s.nodes.size());
    vk::download(context_, bvh.wideRecords, s.wideRecords.data(), s.wideRecords.size() * sizeof(gpu::BvhWideEntry));
  }
  vk::download(context_, bvh.groups, s.groups.data(), s.groups.size() * sizeof(gpu::BvhGroup));
  vk::download(context_, bvh.stats, stats.data(), stats.size() * 16);
  for (const glm::uvec4& v : stats) s.sah.push_back(sahCost(v));
  return s;
}

double BvhBuilder::sahCost(const glm::uvec4& stats) {
  double sum = double(uint64_t(stats.x) | (uint64_t(stats.y) << 32)) / gpu::kBvhSahScale;
  float rootArea = std::bit_cast<float>(stats.z), buildArea = std::bit_cast<float>(stats.w);
  if (!(rootArea > 0.0f)) return 0.0;
  return sum * std::max(double(buildArea), 1e-30) / double(rootArea);
}

BoxFloats BvhSnapshot::childBox(const gpu::BvhNode& node, int c) {
  auto byte = [&](int i) { return (node.quant[i / 4] >> (8 * (i % 4))) & 0xffu; };
  BoxFloats box;
  if (byte(6 * c) > byte(6 * c + 3)) {  // an empty child
    box = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    return box;
  }
  for (int k = 0; k < 3; ++k) {
    float step = std::bit_cast<float>(((node.scale >> (8 * k)) & 0xffu) << 23);
    box[size_t(k)] = node.origin[k] + float(byte(6 * c + k)) * step;
    box[size_t(k) + 3] = node.origin[k] + float(byte(6 * c + 3 + k)) * step;
  }
  return box;
}

BoxFloats BvhSnapshot::storedChildBox(uint32_t node, int c) const {
  if (exactChildBoxes.empty()) return childBox(nodes.at(node), c);
  BoxFloats box = exactChildBoxes.at(2 * size_t(node) + size_t(c));
  if (box[0] == INFINITY) box = {INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};  // the point at +inf
  return box;
}

BvhSnapshot::TreeBoxes BvhSnapshot::treeBoxes(uint32_t group) const {
  const gpu::BvhGroup& g = groups.at(group);
  TreeBoxes boxes;
  if (g.root == gpu::kBvhNone) return boxes;
  BoxFloats root{g.boxLo[0], g.boxLo[1], g.boxLo[2], g.boxHi[0], g.boxHi[1], g.boxHi[2]};
  boxes.internal.push_back(root);
  if (g.root & gpu::kBvhLeafBit) {
    boxes.leaves.push_back(root);
    return boxes;
  }
  std::vector<uint32_t> stack{g.root};
  // Bounded by the node count, so a corrupted tree cannot loop forever.
  while (!stack.empty() && boxes.internal.size() <= nodes.size()) {
    uint32_t n = stack.back();
    stack.pop_back();
    if (n >= nodes.size()) break;
    const gpu::BvhNode& node = nodes[n];
    for (int c = 0; c < 2; ++c) {
      BoxFloats b = storedChildBox(n, c);
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

BvhSnapshot::TreeBoxes BvhSnapshot::exactTreeBoxes(
    uint32_t group, const std::function<BoxFloats(uint32_t prim)>& primitiveBox) const {
  const gpu::BvhGroup& g = groups.at(group);
  TreeBoxes boxes;
  if (g.root == gpu::kBvhNone) return boxes;
  boxes.internal.emplace_back();  // the root's, filled in at the end
  size_t visited = 0;
  // Bounded by the node count, so a corrupted tree cannot recurse forever.
  std::function<BoxFloats(uint32_t)> subtree = [&](uint32_t ref) {
    if (ref & gpu::kBvhLeafBit) return primitiveBox(ref & ~gpu::kBvhLeafBit);
    BoxFloats box{INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
    if (ref >= nodes.size() || ++visited > nodes.size()) return box;
    for (int c = 0; c < 2; ++c) {
      uint32_t child = nodes[ref].child[c];
      BoxFloats b = subtree(child);
      (child & gpu::kBvhLeafBit ? boxes.leaves : boxes.internal).push_back(b);
      for (size_t k = 0; k < 3; ++k) {
        box[k] = std::min(box[k], b[k]);
        box[k + 3] = std::max(box[k + 3], b[k + 3]);
      }
    }
    return box;
  };
  boxes.internal.front() = subtree(g.root);
  if (g.root & gpu::kBvhLeafBit) boxes.leaves.push_back(boxes.internal.front());
  return boxes;
}

}  // namespace snell::render
