// Host side of the refine pass (shaders/comp/refine.comp).
#include "render/refine_pass.h"

#include "scene/subdivision.h"
#include "vk/error.h"

#include "refine.spv.h"

#include <algorithm>
#include <stdexcept>

namespace snell::render {

namespace {

constexpr uint32_t kWorkgroupSize = 64;

// Appends `values` to `out`; returns where they start.
template <typename T>
uint32_t append(std::vector<T>& out, const std::vector<T>& values) {
  const size_t at = out.size();
  out.insert(out.end(), values.begin(), values.end());
  if (out.size() >= (1ull << 32)) throw std::runtime_error("refine pass: its tables pass 2^32 words");
  return static_cast<uint32_t>(at);
}

}  // namespace

RefinePass::RefinePass(vk::Context& context, const scene::Scene& scene, const SceneGpu& gpu)
    : context_(context), tablesOf_(scene.shapes.size(), -1) {
  std::vector<uint32_t> words;
  std::vector<float> weights;
  uint32_t refined = 0, cageVertices = 0;
  for (const GeometryRange& range : gpu.geometries) {
    const scene::Shape& shape = scene.shapes[size_t(range.shape)];
    // A part (Shape::vertexSource) is drawn from its source's refined vertices.
    if (!shape.refinement || shape.part() || tablesOf_[size_t(range.shape)] >= 0) continue;
    const scene::Refinement& r = *shape.refinement;
    ShapeTables tables;
    tables.shape = range.shape;
    gpu::RefineJob& job = tables.job;
    job.refinedCount = r.refinedVertices;
    job.vertexCount = static_cast<uint32_t>(r.vertexOf.size());
    job.cageFirst = shape.host ? shape.host->first : cageVertices;
    job.refinedFirst = refined;
    job.outputFirst = range.firstVertex;
    job.flags = (r.limitSurface ? gpu::kRefineFlagLimitSurface : 0u) |
                (r.normals == scene::SubdivisionNormals::Limit && !r.limit.indices.empty() ? gpu::kRefineFlagLimitNormals : 0u);
    job.refineOffsets = append(words, r.refine.offsets);
    job.refineIndices = append(words, r.refine.indices);
    job.refineWeights = append(weights, r.refine.weights);
    job.limitOffsets = append(words, r.limit.offsets);
    job.limitIndices = append(words, r.limit.indices);
    job.limitWeights = append(weights, r.limitWeights);
    job.aroundOffsets = append(words, r.around.offsets);
    job.aroundTriangles = append(words, r.around.indices);
    job.corners = append(words, r.triangleCorners);
    job.vertexOf = append(words, r.vertexOf);
    refined += r.refinedVertices;
    cageVertices += r.cageVertices;
    tablesOf_[size_t(range.shape)] = static_cast<int>(shapes_.size());
    shapes_.push_back(tables);
  }
  if (shapes_.empty()) return;
  const std::string name = scene.source.empty() ? std::string("scene") : scene.source;
  auto uploaded = [&](const auto& data, const std::string& what) {
    const VkDeviceSize bytes = data.size() * sizeof(data[0]);
    if (bytes > context.caps().maxStorageBufferRange) {
      throw std::runtime_error(name + ": subdivision " + what + " need " + std::to_string(bytes >> 20) +
                               " MiB; the device binds at most " +
                               std::to_string(context.caps().maxStorageBufferRange >> 20) + " MiB in one buffer");
    }
    return vk::uploadedBuffer(context, data, name + " " + what);
  };
  words_ = uploaded(words, "refine tables");
  weights_ = uploaded(weights, "refine weights");
  refined_ = vk::storageBuffer(context, VkDeviceSize(refined) * 12, name + " refined vertices");
  jobs_ = vk::storageBuffer(context, shapes_.size() * sizeof(gpu::RefineJob), name + " refine jobs");
  if (gpu.copiesHost()) {
    cage_ = &gpu.hostPositions;
  } else {
    ownCage_ = vk::storageBuffer(context, VkDeviceSize(cageVertices) * 12, name + " subdivision cages");
    cage_ = &ownCage_;
  }
  std::vector<vk::ComputeProgramDesc> descs = programDescs();
  refine_ = std::make_unique<vk::ComputeProgram>(context, descs[0]);
  limit_ = std::make_unique<vk::ComputeProgram>(context, descs[1]);
}

std::vector<vk::ComputeProgramDesc> RefinePass::programDescs() {
  auto program = [](uint32_t stage, const char* what) {
    return vk::ComputeProgramDesc{
        what, kSpvRefine, {{gpu::kRefineSpecWorkgroupSize, kWorkgroupSize}, {gpu::kRefineSpecStage, stage}}, false};
  };
  return {program(gpu::kRefineStageRefine, "refine"), program(gpu::kRefineStageLimit, "refine limit")};
}

uint32_t RefinePass::cageFirst(int shape) const {
  int at = shape >= 0 && size_t(shape) < tablesOf_.size() ? tablesOf_[size_t(shape)] : -1;
  if (at < 0) throw std::invalid_argument("refine pass: shape " + std::to_string(shape) + " is no subdivision surface");
  return shapes_[size_t(at)].job.cageFirst;
}

void RefinePass::markDirty(int shape) {
  if (shape >= 0 && size_t(shape) < tablesOf_.size() && tablesOf_[size_t(shape)] >= 0) {
    shapes_[size_t(tablesOf_[size_t(shape)])].dirty = true;
  }
}

bool RefinePass::pending() const {
  return std::any_of(shapes_.begin(), shapes_.end(), [](const ShapeTables& t) { return t.dirty; });
}

std::vector<int> RefinePass::record(vk::Commands& commands, const SceneGpu& gpu, vk::UploadArena& arena) {
  std::vector<gpu::RefineJob> jobs;
  std::vector<int> refined;
  uint32_t refineThreads = 0, limitThreads = 0;
  for (ShapeTables& tables : shapes_) {
    if (!tables.dirty) continue;
    tables.dirty = false;
    gpu::RefineJob job = tables.job;
    job.refineBase = refineThreads;
    job.limitBase = limitThreads;
    refineThreads += job.refinedCount;
    limitThreads += job.vertexCount;
    jobs.push_back(job);
    refined.push_back(tables.shape);
  }
  if (jobs.empty()) return refined;
  arena.copy(commands, jobs, jobs_);
  commands.transferToCompute();
  const uint32_t count = static_cast<uint32_t>(jobs.size());
  const std::initializer_list<vk::BufferBinding> bindings = {{gpu::kRefineBindingCage, cage_},
                                                             {gpu::kRefineBindingWords, &words_},
                                                             {gpu::kRefineBindingWeights, &weights_},
                                                             {gpu::kRefineBindingRefined, &refined_},
                                                             {gpu::kRefineBindingPositions, &gpu.positions},
                                                             {gpu::kRefineBindingNormals, &gpu.normals},
                                                             {gpu::kRefineBindingJobs, &jobs_}};
  refine_->dispatchThreads(commands, bindings, gpu::RefinePush{refineThreads, count, 0, 0}, refineThreads);
  commands.computeToCompute();
  limit_->dispatchThreads(commands, bindings, gpu::RefinePush{limitThreads, count, 0, 0}, limitThreads);
  commands.computeToCompute();
  commands.computeToGraphics();
  commands.computeToTransfer();
  return refined;
}

uint64_t RefinePass::bytes() const {
  return words_.size() + weights_.size() + refined_.size() + jobs_.size() + ownCage_.size();
}

}  // namespace snell::render
