// Every way a shape's vertices reach a frame (see vertex_feed.h).
#include "render/vertex_feed.h"

#include "render/pass_names.h"
#include "scene/subdivision.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace snell::render {

VertexFeed::VertexFeed(vk::Context& context, const scene::Scene& scene, const SceneGpu& gpu, bool keep,
                       const std::string& name)
    : scene_(scene), gpu_(gpu), refine_(context, scene, gpu) {
  // A scene of host buffers that copies them: the host's vertices are the
  // host's to give, so the first frame takes them all.
  if (gpu.copiesHost()) dirty_.assign(scene.shapes.size(), 1);
  if (!keep) return;
  keptFirst_.assign(scene.shapes.size(), 0);
  dirty_.assign(scene.shapes.size(), 0);
  for (size_t i = 0; i < scene.shapes.size(); ++i) {
    const scene::Shape& shape = scene.shapes[i];
    if (shape.host) throw std::invalid_argument("renderer: kept vertices are for scenes without host buffers");
    if (shape.morphed() || shape.skinned()) {
      throw std::invalid_argument(name + ": kept vertices are for scenes snell does not deform ('" + shape.name +
                                  "' has morph targets or a skin)");
    }
    keptFirst_[i] = keptCount_;
    if (!shape.part()) keptCount_ += static_cast<uint32_t>(shape.writtenVertexCount());  // a part's are its source's
  }
  kept_ = vk::Buffer(context, {std::max<VkDeviceSize>(VkDeviceSize(keptCount_) * 24, 16),
                               VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryDomain::Readback, name + " kept vertices"});
  for (size_t i = 0; i < scene.shapes.size(); ++i) {
    const scene::Shape& shape = scene.shapes[i];
    if (shape.part()) continue;
    KeptVertices k = kept(int(i));
    if (shape.refinement) {  // the cage at rest; its normals are the refine pass's to make
      const std::vector<glm::vec3>& cage = shape.refinement->cageRest;
      std::memcpy(k.positions, cage.data(), cage.size() * 12);
      std::memset(k.normals, 0, cage.size() * 12);
      continue;
    }
    for (size_t v = 0; v < shape.positions.size(); ++v) {
      const glm::vec3 n = v < shape.normals.size() ? shape.normals[v] : glm::vec3(0.0f);
      std::memcpy(k.positions + 3 * v, &shape.positions[v], 12);
      std::memcpy(k.normals + 3 * v, &n, 12);
    }
  }
}

KeptVertices VertexFeed::kept(int shape) {
  if (!keeps()) throw std::invalid_argument("renderer: made without kept vertices");
  if (shape < 0 || size_t(shape) >= scene_.shapes.size()) {
    throw std::invalid_argument("renderer: no shape " + std::to_string(shape) + " of " +
                                std::to_string(scene_.shapes.size()));
  }
  const scene::Shape& s = scene_.shapes[size_t(shape)];
  if (s.part()) return kept(s.vertexSource);  // its vertices are its source's
  auto* floats = reinterpret_cast<float*>(kept_.mapped().data());
  const size_t first = keptFirst_[size_t(shape)];
  return {floats + 3 * first, floats + 3 * (size_t(keptCount_) + first), static_cast<uint32_t>(s.writtenVertexCount())};
}

void VertexFeed::markDirty(int shape) {
  if (!dirty_.empty()) dirty_.at(size_t(shape)) = 1;
}

FeedCounts VertexFeed::record(vk::Commands& commands, vk::UploadArena& arena, DeformPass& deform) {
  FeedCounts counts;
  std::vector<VertexCopy> copies;
  for (size_t shape = 0; shape < dirty_.size(); ++shape) {
    // A part's vertices are its source's, which the source's copy brings.
    if (!std::exchange(dirty_[shape], 0) || scene_.shapes[shape].part()) continue;
    ++counts.shapesCopied;
    if (keeps()) {
      recordKeptCopy(commands, int(shape));
    } else {
      for (const VertexCopy& c : hostCopies(int(shape))) copies.push_back(c);
    }
    refine_.markDirty(int(shape));  // a cage: refined from the copy, or from the host's buffers in place
  }
  if (keeps() && counts.shapesCopied) commands.fullBarrier();
  deform.recordCopies(commands, arena, gpu_.hostPositions, gpu_.hostNormals, gpu_.positions, gpu_.normals, copies);
  if (!refine_.pending()) return counts;
  commands.beginPass(pass::kRefine);
  for (int shape : refine_.record(commands, gpu_, arena)) {
    ++counts.shapesRefined;
    counts.verticesRefined += static_cast<uint32_t>(scene_.shapes[size_t(shape)].vertexCount());
  }
  commands.endPass();
  return counts;
}

void VertexFeed::recordKeptCopy(vk::Commands& commands, int shape) {
  const VkDeviceSize from = VkDeviceSize(keptFirst_[size_t(shape)]) * 12;
  if (const scene::Shape& s = scene_.shapes[size_t(shape)]; s.refinement) {
    if (!refine_.refines(shape)) return;  // not drawn
    commands.copyBuffer(kept_, refine_.cageBuffer(), VkDeviceSize(s.cageVertices) * 12, from,
                        VkDeviceSize(refine_.cageFirst(shape)) * 12);
    return;
  }
  const VkDeviceSize normalsAt = VkDeviceSize(keptCount_) * 12;
  for (const GeometryRange& range : gpu_.geometries) {
    if (range.shape != shape) continue;
    const VkDeviceSize to = VkDeviceSize(range.firstVertex) * 12, bytes = VkDeviceSize(range.vertexCount) * 12;
    commands.copyBuffer(kept_, gpu_.positions, bytes, from, to);
    commands.copyBuffer(kept_, gpu_.normals, bytes, normalsAt + from, to);
  }
}

std::vector<VertexCopy> VertexFeed::hostCopies(int shape) const {
  std::vector<VertexCopy> copies;
  const scene::Shape& s = scene_.shapes.at(size_t(shape));
  if (!gpu_.copiesHost() || !s.host || s.subdivided()) return copies;
  for (const GeometryRange& range : gpu_.geometries) {
    if (range.shape == shape) copies.push_back({s.host->first, range.firstVertex, range.vertexCount});
  }
  return copies;
}

}  // namespace snell::render
