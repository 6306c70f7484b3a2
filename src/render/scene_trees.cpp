// The scene's trees over the frames (see scene_trees.h).
#include "render/scene_trees.h"

#include "render/pass_names.h"
#include "shared/bvh.h"

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cstring>

namespace snell::render {

namespace {

// Where each part of a frame's statistics lies: the SAH of every bottom-level
// group, the top level's, the dropped triangles, then (when shapes are
// measured) every group record, each starting with the box its refit wrote.
struct StatisticsLayout {
  VkDeviceSize topAt, droppedAt, groupsAt, bytes;
  StatisticsLayout(uint32_t groups, bool measures) {
    topAt = uint64_t(groups) * 16;
    droppedAt = topAt + 16;
    groupsAt = droppedAt + 16;
    bytes = groupsAt + (measures ? uint64_t(groups) * sizeof(gpu::BvhGroup) : 0);
  }
};

}  // namespace

SceneTrees::SceneTrees(vk::Context& context, const SceneGpu& gpu, std::string name, double rebuildGrowth,
                       uint64_t rebuildBudget, BvhChildBoxes childBoxes)
    : context_(context), gpu_(gpu), name_(std::move(name)), rebuildBudget_(rebuildBudget), childBoxes_(childBoxes),
      rebuilds_(gpu.geometries.size(), rebuildGrowth), moved_(gpu.geometries.size(), 1) {
  int shapes = 0;
  for (const GeometryRange& g : gpu.geometries) shapes = std::max(shapes, g.shape + 1);
  shapeEdits_.assign(size_t(shapes), 0);
  shapeUnmeasured_.assign(size_t(shapes), 0);
}

SceneTrees::~SceneTrees() = default;

void SceneTrees::measure(int shape) {
  if (shape < 0 || size_t(shape) >= shapeEdits_.size()) return;  // not drawn: no tree to measure it
  ++shapeEdits_[size_t(shape)];
  shapeUnmeasured_[size_t(shape)] = 1;
}

void SceneTrees::prepare() {
  if (builder_) return;
  builder_ = std::make_unique<BvhBuilder>(context_);
  std::vector<uint32_t> counts;
  for (const GeometryRange& g : gpu_.geometries) counts.push_back(g.triangleCount);
  blas_ = std::make_unique<Bvh>(builder_->makeBvh(counts, BvhLeaves::Triangles, name_ + " bottom level", childBoxes_));
  tlas_ = std::make_unique<Bvh>(builder_->makeBvh({static_cast<uint32_t>(gpu_.itemGeometry.size())},
                                                  BvhLeaves::Instances, name_ + " top level", childBoxes_));
}

SceneTrees::Work SceneTrees::plan(bool instancesChanged, bool fresh, FrameStats& stats) {
  prepare();
  Work w;
  if (fresh) built_ = topBuilt_ = false;
  if (!built_) {
    for (uint32_t g = 0; g < gpu_.geometries.size(); ++g) w.build.push_back(g);
    rebuilds_.clear();
  } else {
    std::vector<uint32_t> triangles;
    for (const GeometryRange& g : gpu_.geometries) triangles.push_back(g.triangleCount);
    w.build = rebuilds_.take(rebuildBudget_, triangles);
  }
  for (uint32_t g : w.build) moved_[g] = 0;
  w.refit = w.build;  // a refit right after a build measures the new tree's SAH
  for (uint32_t g = 0; g < gpu_.geometries.size(); ++g) {
    if (!moved_[g]) continue;
    moved_[g] = 0;
    w.refit.push_back(g);
  }
  for (uint32_t g : w.refit) {
    const GeometryRange& range = gpu_.geometries[g];
    if (range.item < 0 && shapeUnmeasured_[size_t(range.shape)]) {
      w.measures.push_back({g, range.shape, shapeEdits_[size_t(range.shape)]});
    }
  }
  built_ = true;
  if (rebuilds_.takeTopRebuild() || !topBuilt_) {
    w.buildTop = w.refitTop = true;
    topBuilt_ = true;
    topDirty_ = false;
  } else if (topDirty_ || instancesChanged || !w.refit.empty()) {
    w.refitTop = true;
    topDirty_ = false;
  }

  stats.treesBuilt = static_cast<uint32_t>(w.build.size());
  stats.treesRefit = static_cast<uint32_t>(w.refit.size() - w.build.size());
  stats.treesSkipped = static_cast<uint32_t>(gpu_.geometries.size() - w.refit.size());
  for (uint32_t g : w.build) stats.trianglesBuilt += gpu_.geometries[g].triangleCount;
  for (size_t k = w.build.size(); k < w.refit.size(); ++k) {
    stats.trianglesRefit += gpu_.geometries[w.refit[k]].triangleCount;
  }
  stats.topLevelBuilt = w.buildTop ? 1 : 0;
  stats.topLevelRefit = w.refitTop && !w.buildTop ? 1 : 0;
  stats.topLevelSkipped = w.refitTop ? 0 : 1;
  return w;
}

void SceneTrees::record(vk::Commands& commands, const Work& w, const vk::Buffer& instances, vk::UploadArena& arena) {
  BvhInputs triangles{&gpu_.positions, &gpu_.indices, nullptr, nullptr};
  if (!w.build.empty()) {
    commands.beginPass(pass::kBlasBuild);
    builder_->recordBuild(commands, *blas_, triangles, w.build, arena);
    commands.endPass();
  }
  if (!w.refit.empty()) {
    // Counts the triangles the refit finds non-finite (it covers every tree built this frame too).
    commands.fillBuffer(blas_->dropped, 0);
    commands.transferToCompute();
    commands.beginPass(pass::kBlasRefit);
    builder_->recordRefit(commands, *blas_, triangles, w.refit, arena);
    commands.endPass();
  }
  if (w.refitTop) {
    commands.beginPass(pass::kTlas);
    BvhInputs top{nullptr, nullptr, &instances, blas_.get()};
    if (w.buildTop) builder_->recordBuild(commands, *tlas_, top, {}, arena);
    builder_->recordRefit(commands, *tlas_, top, {}, arena);
    commands.endPass();
  }
}

VkDeviceSize SceneTrees::statisticsBytes(const Work& w) const {
  return StatisticsLayout(blas_ ? blas_->groupCount() : 0, !w.measures.empty()).bytes;
}

void SceneTrees::recordStatistics(vk::Commands& commands, const Work& w, const vk::Buffer& buffer,
                                  VkDeviceSize at) const {
  if (!blas_) return;
  const uint32_t groups = blas_->groupCount();
  const StatisticsLayout l(groups, !w.measures.empty());
  if (!w.refit.empty()) {
    commands.copyBuffer(blas_->stats, buffer, uint64_t(groups) * 16, 0, at);
    commands.copyBuffer(blas_->dropped, buffer, 4, 0, at + l.droppedAt);
  }
  if (!w.measures.empty()) commands.copyBuffer(blas_->groups, buffer, uint64_t(groups) * sizeof(gpu::BvhGroup), 0, at + l.groupsAt);
  if (w.refitTop) commands.copyBuffer(tlas_->stats, buffer, 16, 0, at + l.topAt);
}

std::vector<ShapeBox> SceneTrees::collect(const Work& w, const std::byte* data, FrameStats& stats) {
  std::vector<ShapeBox> boxes;
  if (!blas_) return boxes;
  const StatisticsLayout l(blas_->groupCount(), !w.measures.empty());
  auto sahAt = [&](VkDeviceSize at) {
    glm::uvec4 s;
    std::memcpy(&s, data + at, 16);
    return BvhBuilder::sahCost(s);
  };
  if (!w.refit.empty()) {
    std::memcpy(&stats.droppedTriangles, data + l.droppedAt, 4);
    std::vector<char> built(gpu_.geometries.size(), 0);
    for (uint32_t g : w.build) built[g] = 1;
    for (uint32_t g : w.refit) stats.sahGrowth = std::max(stats.sahGrowth, rebuilds_.noteBottom(g, sahAt(uint64_t(g) * 16), built[g]));
  }
  if (w.refitTop) rebuilds_.noteTop(sahAt(l.topAt), w.buildTop);
  for (const Work::Measure& m : w.measures) {
    if (shapeEdits_[size_t(m.shape)] != m.edit) continue;  // rewritten since: a later refit measures it
    gpu::BvhGroup group;
    std::memcpy(&group, data + l.groupsAt + uint64_t(m.group) * sizeof(gpu::BvhGroup), sizeof(group));
    boxes.push_back({m.shape, glm::dvec3(glm::make_vec3(group.boxLo)), glm::dvec3(glm::make_vec3(group.boxHi))});
    shapeUnmeasured_[size_t(m.shape)] = 0;
  }
  return boxes;
}

uint64_t SceneTrees::bytes() const {
  if (!blas_) return 0;
  return blas_->treeBytes() + tlas_->treeBytes() + blas_->workBytes() + tlas_->workBytes() + builder_->scratchBytes();
}

double SceneTrees::treeBytesPerTriangle() const {
  if (!blas_ || gpu_.triangleCount == 0) return 0.0;
  return double(blas_->treeBytes() + tlas_->treeBytes()) / gpu_.triangleCount;
}

}  // namespace snell::render
