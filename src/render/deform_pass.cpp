// Host side of the deform pass (shaders/comp/deform.comp).
#include "render/deform_pass.h"

#include "shared/deform.h"
#include "vk/error.h"

#include "deform.spv.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cstring>
#include <numeric>

namespace snell::render {

namespace {

constexpr uint32_t kWorkgroupSize = 64;

}  // namespace

vk::ComputeProgramDesc DeformPass::programDesc() {
  return {"deform", kSpvDeform, {{gpu::kDeformSpecWorkgroupSize, kWorkgroupSize}}, false};
}

DeformPass::DeformPass(vk::Context& context, const scene::Scene& scene, const scene::Pose& pose,
                       const std::function<DeformSlot(int item)>& slots)
    : context_(context), scene_(scene) {
  program_ = std::make_unique<vk::ComputeProgram>(context, programDesc());
  shapes_.resize(scene.shapes.size());
  std::vector<float> restPositions, restNormals, morphDeltas;
  std::vector<glm::uvec4> joints;
  std::vector<glm::vec4> skinWeights;
  uint32_t ownVertices = 0, weightCapacity = 0, jointCapacity = 0;
  for (size_t i = 0; i < pose.items.size(); ++i) {
    const scene::DrawItem& item = pose.items[i];
    if (!item.deforms()) continue;
    const scene::Shape& shape = scene.shapes[size_t(item.shape)];
    ShapeData& data = shapes_[size_t(item.shape)];
    if (!data.uploaded) {
      // Each deforming shape's rest pose once, however many items draw it.
      data.uploaded = true;
      data.vertexCount = static_cast<uint32_t>(shape.vertexCount());
      data.targetCount = static_cast<uint32_t>(shape.targets.size());
      data.restFirst = static_cast<uint32_t>(restPositions.size() / 3);
      data.morphFirst = static_cast<uint32_t>(morphDeltas.size());
      data.skinFirst = static_cast<uint32_t>(joints.size());
      for (size_t v = 0; v < shape.vertexCount(); ++v) {
        const glm::vec3& p = shape.positions[v];
        glm::vec3 n = v < shape.normals.size() ? shape.normals[v] : glm::vec3(0.0f);
        restPositions.insert(restPositions.end(), {p.x, p.y, p.z});
        restNormals.insert(restNormals.end(), {n.x, n.y, n.z});
      }
      for (const scene::MorphTarget& target : shape.targets) {
        for (size_t v = 0; v < shape.vertexCount(); ++v) {
          glm::vec3 dp = target.positions.empty() ? glm::vec3(0.0f) : target.positions[v];
          glm::vec3 dn = target.normals.empty() ? glm::vec3(0.0f) : target.normals[v];
          morphDeltas.insert(morphDeltas.end(), {dp.x, dp.y, dp.z, dn.x, dn.y, dn.z});
        }
      }
      if (shape.skinned()) {
        joints.insert(joints.end(), shape.joints.begin(), shape.joints.end());
        skinWeights.insert(skinWeights.end(), shape.weights.begin(), shape.weights.end());
      }
    }
    DeformOutput out;
    out.item = static_cast<int>(i);
    out.shape = item.shape;
    out.jointCount = static_cast<uint32_t>(item.jointMatrices.size());
    if (slots) {
      out.slot = slots(static_cast<int>(i));
    } else {
      out.slot.firstVertex = ownVertices;
      ownVertices += data.vertexCount;
    }
    weightCapacity += data.targetCount;
    jointCapacity += out.jointCount;
    outputs_.push_back(out);
  }
  std::string name = scene.source.empty() ? std::string("scene") : scene.source;
  restPositions_ = vk::uploadedBuffer(context, restPositions, name + " rest positions");
  restNormals_ = vk::uploadedBuffer(context, restNormals, name + " rest normals");
  morphDeltas_ = vk::uploadedBuffer(context, morphDeltas, name + " morph deltas");
  joints_ = vk::uploadedBuffer(context, joints, name + " skin joints");
  skinWeights_ = vk::uploadedBuffer(context, skinWeights, name + " skin weights");
  auto device = [&](VkDeviceSize bytes, const std::string& what) {
    return vk::storageBuffer(context, bytes, name + " " + what);
  };
  jobs_ = device(outputs_.size() * sizeof(gpu::DeformJob), "deform jobs");
  weights_ = device(weightCapacity * 4ull, "morph weights");
  jointMatrices_ = device(jointCapacity * sizeof(glm::mat4), "joint matrices");
  if (!slots) {
    ownPositions_ = device(ownVertices * 12ull, "deformed positions");
    ownNormals_ = device(ownVertices * 12ull, "deformed normals");
    for (DeformOutput& out : outputs_) out.slot.positions = &ownPositions_, out.slot.normals = &ownNormals_;
  }
  for (const DeformOutput& out : outputs_) {
    if (out.slot.positions != outputs_.front().slot.positions || out.slot.normals != outputs_.front().slot.normals) {
      throw vk::VulkanError("deform pass: every item must write into the same vertex buffers");
    }
  }
}

glm::dvec3 DeformPass::anchorOf(const scene::DrawItem& item) {
  if (!item.skinned || item.jointMatrices.empty()) return glm::dvec3(0.0);
  return glm::dvec3(item.jointMatrices.front()[3]);
}

void DeformPass::record(vk::Commands& commands, const scene::Pose& pose, vk::UploadArena& arena,
                        std::span<const uint32_t> which) {
  std::vector<uint32_t> all;
  if (which.empty()) {
    all.resize(outputs_.size());
    std::iota(all.begin(), all.end(), 0u);
    which = all;
  }
  std::vector<gpu::DeformJob> jobs;
  std::vector<float> weights;
  std::vector<glm::mat4> matrices;
  uint32_t threads = 0;
  for (uint32_t o : which) {
    DeformOutput& out = outputs_.at(o);
    const scene::DrawItem* found = static_cast<size_t>(out.item) < pose.items.size() ? &pose.items[size_t(out.item)] : nullptr;
    if (!found || found->scene != &scene_ || found->shape != out.shape || found->jointMatrices.size() != out.jointCount) {
      throw vk::VulkanError("deform pass: the pose is not of the scene and draw items it was built for");
    }
    const scene::DrawItem& item = *found;
    const ShapeData& shape = shapes_[size_t(out.shape)];
    gpu::DeformJob job{};
    job.threadBase = threads;
    job.vertexCount = shape.vertexCount;
    job.restFirst = shape.restFirst;
    job.outputFirst = out.slot.firstVertex;
    job.morphFirst = shape.morphFirst;
    job.targetCount = std::min<uint32_t>(shape.targetCount, static_cast<uint32_t>(item.weights.size()));
    job.weightFirst = static_cast<uint32_t>(weights.size());
    job.skinFirst = shape.skinFirst;
    job.jointFirst = static_cast<uint32_t>(matrices.size());
    job.jointCount = item.skinned ? out.jointCount : 0u;
    weights.insert(weights.end(), item.weights.begin(), item.weights.begin() + job.targetCount);
    // Joint matrices moved to the anchor in double, before the cast to float.
    out.anchor = anchorOf(item);
    const glm::dmat4 rebase = glm::translate(glm::dmat4(1.0), -out.anchor);
    for (uint32_t j = 0; j < job.jointCount; ++j) matrices.push_back(glm::mat4(rebase * item.jointMatrices[j]));
    threads += shape.vertexCount;
    jobs.push_back(job);
  }
  if (jobs.empty()) return;
  arena.copy(commands, jobs, jobs_);
  arena.copy(commands, weights, weights_);
  arena.copy(commands, matrices, jointMatrices_);
  commands.transferToCompute();
  gpu::DeformPush push{threads, static_cast<uint32_t>(jobs.size()), 0, 0};
  const DeformSlot& slot = outputs_.front().slot;
  program_->dispatchThreads(commands,
                            {{gpu::kDeformBindingRestPositions, &restPositions_},
                             {gpu::kDeformBindingRestNormals, &restNormals_},
                             {gpu::kDeformBindingMorphDeltas, &morphDeltas_},
                             {gpu::kDeformBindingMorphWeights, &weights_},
                             {gpu::kDeformBindingJoints, &joints_},
                             {gpu::kDeformBindingSkinWeights, &skinWeights_},
                             {gpu::kDeformBindingJointMatrices, &jointMatrices_},
                             {gpu::kDeformBindingPositions, slot.positions},
                             {gpu::kDeformBindingNormals, slot.normals},
                             {gpu::kDeformBindingJobs, &jobs_}},
                            push, threads);
  commands.computeToCompute();
  commands.computeToGraphics();
  commands.computeToTransfer();
}

void DeformPass::recordCopies(vk::Commands& commands, vk::UploadArena& arena, const vk::Buffer& fromPositions,
                              const vk::Buffer& fromNormals, const vk::Buffer& toPositions,
                              const vk::Buffer& toNormals, std::span<const VertexCopy> copies) {
  std::vector<gpu::DeformJob> jobs;
  uint32_t threads = 0;
  for (const VertexCopy& c : copies) {
    gpu::DeformJob job{};
    job.threadBase = threads;
    job.vertexCount = c.count;
    job.restFirst = c.from;
    job.outputFirst = c.to;
    threads += c.count;
    jobs.push_back(job);
  }
  if (jobs.empty()) return;
  if (copyJobs_.size() < jobs.size() * sizeof(gpu::DeformJob)) {
    copyJobs_ = vk::storageBuffer(context_, jobs.size() * sizeof(gpu::DeformJob), "vertex copy jobs");
  }
  arena.copy(commands, jobs, copyJobs_);
  commands.transferToCompute();
  gpu::DeformPush push{threads, static_cast<uint32_t>(jobs.size()), 0, 0};
  program_->dispatchThreads(commands,
                            {{gpu::kDeformBindingRestPositions, &fromPositions},
                             {gpu::kDeformBindingRestNormals, &fromNormals},
                             {gpu::kDeformBindingMorphDeltas, &morphDeltas_},
                             {gpu::kDeformBindingMorphWeights, &weights_},
                             {gpu::kDeformBindingJoints, &joints_},
                             {gpu::kDeformBindingSkinWeights, &skinWeights_},
                             {gpu::kDeformBindingJointMatrices, &jointMatrices_},
                             {gpu::kDeformBindingPositions, &toPositions},
                             {gpu::kDeformBindingNormals, &toNormals},
                             {gpu::kDeformBindingJobs, &copyJobs_}},
                            push, threads);
  commands.computeToCompute();
  commands.computeToGraphics();
  commands.computeToTransfer();
}

uint64_t DeformPass::bytes() const {
  uint64_t total = 0;
  for (const vk::Buffer* b : {&restPositions_, &restNormals_, &morphDeltas_, &joints_, &skinWeights_, &jobs_, &weights_,
                              &jointMatrices_, &ownPositions_, &ownNormals_, &copyJobs_}) {
    total += b->size();
  }
  return total;
}

}  // namespace snell::render
