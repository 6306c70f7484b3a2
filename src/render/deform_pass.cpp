// Host side of the deform pass (shaders/comp/deform.comp).
#include "render/deform_pass.h"

#include "shared/deform.h"
#include "vk/error.h"

#include "deform.spv.h"

#include <cstring>

namespace snell::render {

namespace {

constexpr uint32_t kWorkgroupSize = 64;
constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

template <typename T>
vk::Buffer uploaded(vk::Context& context, const std::vector<T>& data, const std::string& name) {
  vk::Buffer buffer(context, {data.size() * sizeof(T), kStorage, vk::MemoryDomain::Device, name});
  vk::upload(context, buffer, data.data(), data.size() * sizeof(T));
  return buffer;
}

std::vector<float> flatten(const std::vector<glm::vec3>& v) {
  std::vector<float> out(v.size() * 3);
  std::memcpy(out.data(), v.data(), out.size() * sizeof(float));
  return out;
}

std::unique_ptr<DeformInputs> uploadShape(vk::Context& context, const scene::Shape& shape) {
  auto inputs = std::make_unique<DeformInputs>();
  inputs->vertexCount = static_cast<uint32_t>(shape.vertexCount());
  inputs->targetCount = static_cast<uint32_t>(shape.targets.size());
  inputs->positions = uploaded(context, flatten(shape.positions), shape.name + " rest positions");
  inputs->normals = uploaded(context, flatten(shape.normals), shape.name + " rest normals");
  if (!shape.targets.empty()) {
    std::vector<float> deltas(size_t(6) * shape.targets.size() * shape.vertexCount(), 0.0f);
    for (size_t t = 0; t < shape.targets.size(); ++t) {
      const scene::MorphTarget& target = shape.targets[t];
      for (size_t v = 0; v < shape.vertexCount(); ++v) {
        float* d = &deltas[6 * (t * shape.vertexCount() + v)];
        if (!target.positions.empty()) std::memcpy(d, &target.positions[v], 12);
        if (!target.normals.empty()) std::memcpy(d + 3, &target.normals[v], 12);
      }
    }
    inputs->morphDeltas = uploaded(context, deltas, shape.name + " morph deltas");
  }
  if (shape.skinned()) {
    inputs->joints = uploaded(context, shape.joints, shape.name + " joints");
    inputs->skinWeights = uploaded(context, shape.weights, shape.name + " skin weights");
  }
  return inputs;
}

}  // namespace

DeformPass::DeformPass(vk::Context& context, const scene::Scene& scene, const scene::Pose& layout,
                       const std::function<DeformSlot(int item)>& slots)
    : context_(context), scene_(scene) {
  program_ = std::make_unique<vk::ComputeProgram>(
      context, vk::ComputeProgramDesc{"deform", kSpvDeform, {{gpu::kDeformSpecWorkgroupSize, kWorkgroupSize}}, false});
  empty_ = vk::Buffer(context, {16, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryDomain::Device, "deform placeholder"});
  inputs_.resize(scene.shapes.size());
  for (size_t i = 0; i < layout.items.size(); ++i) {
    const scene::DrawItem& item = layout.items[i];
    if (!item.deforms()) continue;
    const scene::Shape& shape = scene.shapes[size_t(item.shape)];
    if (!inputs_[size_t(item.shape)]) inputs_[size_t(item.shape)] = uploadShape(context, shape);
    DeformOutput out;
    out.item = static_cast<int>(i);
    out.shape = item.shape;
    out.jointCount = static_cast<uint32_t>(item.jointMatrices.size());
    std::string name = shape.name + " (item " + std::to_string(i) + ")";
    VkDeviceSize floats3 = shape.vertexCount() * 12;
    out.morphWeights = vk::Buffer(context, {std::max<size_t>(shape.targets.size(), 1) * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                            vk::MemoryDomain::Upload, name + " morph weights"});
    out.jointMatrices = vk::Buffer(context, {std::max<size_t>(out.jointCount, 1) * sizeof(glm::mat4),
                                             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryDomain::Upload,
                                             name + " joint matrices"});
    if (slots) {
      out.slot = slots(static_cast<int>(i));
    } else {
      out.ownPositions = vk::Buffer(context, {floats3, kStorage, vk::MemoryDomain::Device, name + " deformed positions"});
      out.ownNormals = vk::Buffer(context, {floats3, kStorage, vk::MemoryDomain::Device, name + " deformed normals"});
    }
    outputs_.push_back(std::move(out));
  }
  // Pointers into outputs_ are taken once it no longer grows.
  for (DeformOutput& out : outputs_) {
    if (!out.slot.positions) out.slot = {&out.ownPositions, &out.ownNormals, 0};
  }
}

void DeformPass::record(vk::Commands& commands, const scene::Pose& pose, const glm::dvec3& origin) {
  const glm::dmat4 rebase = glm::translate(glm::dmat4(1.0), -origin);
  for (DeformOutput& out : outputs_) {
    const scene::DrawItem* found = static_cast<size_t>(out.item) < pose.items.size() ? &pose.items[size_t(out.item)] : nullptr;
    if (!found || found->scene != &scene_ || found->shape != out.shape || found->jointMatrices.size() != out.jointCount) {
      throw vk::VulkanError("deform pass: the pose is not of the scene and draw items it was built for");
    }
    const scene::DrawItem& item = *found;
    const DeformInputs& in = *inputs_[size_t(out.shape)];
    uint32_t targets = std::min<uint32_t>(in.targetCount, static_cast<uint32_t>(item.weights.size()));
    if (targets) std::memcpy(out.morphWeights.mapped().data(), item.weights.data(), targets * sizeof(float));
    if (out.jointCount) {
      auto* matrices = reinterpret_cast<glm::mat4*>(out.jointMatrices.mapped().data());
      for (uint32_t j = 0; j < out.jointCount; ++j) matrices[j] = glm::mat4(rebase * item.jointMatrices[j]);
    }
    gpu::DeformPush push{in.vertexCount, targets, item.skinned ? out.jointCount : 0u, out.slot.firstVertex};
    auto orEmpty = [&](const vk::Buffer& b) { return b.handle() ? &b : &empty_; };
    program_->dispatchThreads(commands,
                              {{gpu::kDeformBindingRestPositions, &in.positions},
                               {gpu::kDeformBindingRestNormals, &in.normals},
                               {gpu::kDeformBindingMorphDeltas, orEmpty(in.morphDeltas)},
                               {gpu::kDeformBindingMorphWeights, &out.morphWeights},
                               {gpu::kDeformBindingJoints, orEmpty(in.joints)},
                               {gpu::kDeformBindingSkinWeights, orEmpty(in.skinWeights)},
                               {gpu::kDeformBindingJointMatrices, &out.jointMatrices},
                               {gpu::kDeformBindingPositions, out.slot.positions},
                               {gpu::kDeformBindingNormals, out.slot.normals}},
                              push, in.vertexCount);
  }
  if (!outputs_.empty()) {
    commands.computeToCompute();
    commands.computeToTransfer();
  }
}

}  // namespace snell::render
