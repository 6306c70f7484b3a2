// The host's copy of a scene's vertices (see kept_vertices.h).
#include "render/kept_vertices.h"

#include "scene/subdivision.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace snell::render {

KeptVertexCopy::KeptVertexCopy(vk::Context& context, const scene::Scene& scene, const std::string& name)
    : scene_(scene), first_(scene.shapes.size(), 0), dirty_(scene.shapes.size(), 0) {
  for (size_t i = 0; i < scene.shapes.size(); ++i) {
    const scene::Shape& shape = scene.shapes[i];
    if (shape.morphed() || shape.skinned()) {
      throw std::invalid_argument(name + ": kept vertices are for scenes snell does not deform ('" + shape.name +
                                  "' has morph targets or a skin)");
    }
    first_[i] = count_;
    count_ += static_cast<uint32_t>(shape.writtenVertexCount());
  }
  buffer_ = vk::Buffer(context, {std::max<VkDeviceSize>(VkDeviceSize(count_) * 24, 16), VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                 vk::MemoryDomain::Readback, name + " kept vertices"});
  for (size_t i = 0; i < scene.shapes.size(); ++i) {
    const scene::Shape& shape = scene.shapes[i];
    KeptVertices kept = this->shape(int(i));
    if (shape.refinement) {  // the cage at rest; its normals are the refine pass's to make
      const std::vector<glm::vec3>& cage = shape.refinement->cageRest;
      std::memcpy(kept.positions, cage.data(), cage.size() * 12);
      std::memset(kept.normals, 0, cage.size() * 12);
      continue;
    }
    for (size_t v = 0; v < shape.positions.size(); ++v) {
      const glm::vec3 n = v < shape.normals.size() ? shape.normals[v] : glm::vec3(0.0f);
      std::memcpy(kept.positions + 3 * v, &shape.positions[v], 12);
      std::memcpy(kept.normals + 3 * v, &n, 12);
    }
  }
}

KeptVertices KeptVertexCopy::shape(int shape) {
  auto* floats = reinterpret_cast<float*>(buffer_.mapped().data());
  const size_t first = first_.at(size_t(shape));
  return {floats + 3 * first, floats + 3 * (size_t(count_) + first),
          static_cast<uint32_t>(scene_.shapes[size_t(shape)].writtenVertexCount())};
}

uint32_t KeptVertexCopy::recordCopies(vk::Commands& commands, const SceneGpu& gpu, RefinePass& refine) {
  const VkDeviceSize normalsAt = VkDeviceSize(count_) * 12;
  uint32_t copied = 0;
  for (size_t shape = 0; shape < dirty_.size(); ++shape) {
    if (!dirty_[shape]) continue;
    dirty_[shape] = 0;
    ++copied;
    const VkDeviceSize from = VkDeviceSize(first_[shape]) * 12;
    if (const scene::Shape& s = scene_.shapes[shape]; s.refinement) {
      if (!refine.refines(int(shape))) continue;  // not drawn
      commands.copyBuffer(buffer_, refine.cageBuffer(), VkDeviceSize(s.cageVertices) * 12, from,
                          VkDeviceSize(refine.cageFirst(int(shape))) * 12);
      refine.markDirty(int(shape));
      continue;
    }
    for (const GeometryRange& range : gpu.geometries) {
      if (range.shape != int(shape)) continue;
      const VkDeviceSize to = VkDeviceSize(range.firstVertex) * 12, bytes = VkDeviceSize(range.vertexCount) * 12;
      commands.copyBuffer(buffer_, gpu.positions, bytes, from, to);
      commands.copyBuffer(buffer_, gpu.normals, bytes, normalsAt + from, to);
    }
  }
  return copied;
}

}  // namespace snell::render
