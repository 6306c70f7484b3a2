// Packing a scene into the buffers the passes read (shaders/shared/trace.h).
#include "render/scene_gpu.h"

#include "render/deform_pass.h"
#include "scene/scene_summary.h"
#include "scene/texture_mips.h"
#include "shared/trace.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "texture_mips.spv.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace snell::render {

namespace {

template <typename T>
vk::Buffer uploaded(vk::Context& context, const std::vector<T>& data, const std::string& name, uint64_t& bytes,
                    bool triangles = false) {
  VkDeviceSize size = data.size() * sizeof(T);
  if (size > context.caps().maxStorageBufferRange) {
    throw std::runtime_error(name + " needs " + std::to_string(size >> 20) + " MiB; the device binds at most " +
                             std::to_string(context.caps().maxStorageBufferRange >> 20) + " MiB in one buffer");
  }
  // Where the driver's acceleration structures are on, they may read the
  // triangles too (the driver-rt peer builds over these very buffers).
  bool driver = triangles && context.caps().driverAccelerationStructures;
  vk::Buffer buffer(context, {std::max<VkDeviceSize>(size, 16),
                              VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                  VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                                  (driver ? VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                                VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT
                                          : 0u),
                              vk::MemoryDomain::Device, name, driver});
  if (size) vk::upload(context, buffer, data.data(), size);
  bytes += buffer.size();
  return buffer;
}

// kSceneBindingSrgbDecode: each sRGB byte's linear value.
std::vector<float> srgbDecodeTable() {
  std::vector<float> table(gpu::kSrgbDecodeWords);
  for (uint32_t v = 0; v < gpu::kSrgbDecodeWords; ++v) table[v] = float(scene::srgbToLinear(static_cast<uint8_t>(v)));
  return table;
}

// Which page each texture's chain goes to, and where: first fit over the
// pages, each at most the device's largest storage buffer. Throws naming the
// numbers when the textures do not fit.
struct TexturePlacement {
  std::vector<uint32_t> page, first;
  std::array<uint64_t, gpu::kTexelPages> pageTexels{};
};

// Pages are read back by tests and tools (transfer source) as well as written.
constexpr VkBufferUsageFlags kTexelPageUsage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

TexturePlacement placeTextures(const vk::Context& context, const scene::Scene& scene) {
  const uint64_t capacity = context.caps().maxStorageBufferRange / 4;
  TexturePlacement place;
  uint64_t total = 0;
  const std::vector<bool> drawn = scene::drawnTextures(scene);
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const scene::Texture& t = scene.textures[i];
    // A texture no material reads takes no texels (its table entry stays, unread).
    uint64_t texels = drawn[i] ? scene::mipChainTexels(std::max(t.width, 1u), std::max(t.height, 1u)) : 0;
    total += texels;
    uint32_t p = 0;
    while (p < gpu::kTexelPages && place.pageTexels[p] + texels > capacity) ++p;
    if (p == gpu::kTexelPages) {
      throw std::runtime_error(scene.source + ": textures need at least " + std::to_string((total * 4) >> 20) +
                               " MiB with their mips; this device holds " + std::to_string(gpu::kTexelPages) +
                               " texel pages of " + std::to_string((capacity * 4) >> 20) + " MiB (texture '" + t.name +
                               "' of " + std::to_string(t.width) + "x" + std::to_string(t.height) + " did not fit)");
    }
    place.page.push_back(p);
    place.first.push_back(static_cast<uint32_t>(place.pageTexels[p]));
    place.pageTexels[p] += texels;
  }
  return place;
}

// Level 0 of every texture copied to its page, then the other levels made on
// the GPU (texture_mips.comp), level by level, every texture at once.
void uploadTextures(vk::Context& context, const scene::Scene& scene, const TexturePlacement& place, SceneGpu& gpu) {
  const std::string& name = scene.source.empty() ? std::string("scene") : scene.source;
  for (uint32_t p = 0; p < gpu::kTexelPages; ++p) {
    VkDeviceSize bytes = std::max<VkDeviceSize>(place.pageTexels[p] * 4, 16);
    gpu.texelPages[p] = vk::Buffer(context, {bytes, kTexelPageUsage,
                                             vk::MemoryDomain::Device, name + " texel page " + std::to_string(p)});
    gpu.textureBytes += place.pageTexels[p] * 4;
    gpu.bytes += bytes;
  }
  if (scene.textures.empty()) return;
  // Level 0 goes through one staging ring of at most kTextureStagingRingBytes: when
  // it is full, what it holds is copied and the ring starts again, so a
  // scene's textures never need a second copy of themselves in host memory.
  const std::vector<bool> colour = scene::colourTextures(scene), drawn = scene::drawnTextures(scene);
  VkDeviceSize total = 0;
  for (size_t i = 0; i < scene.textures.size(); ++i) total += drawn[i] ? VkDeviceSize(scene.textures[i].rgba.size()) : 0;
  const VkDeviceSize ringBytes = std::clamp<VkDeviceSize>(total, 4, kTextureStagingRingBytes);
  vk::Buffer staging(context, {ringBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, vk::MemoryDomain::Upload,
                               name + " texture staging ring"});
  vk::ComputeProgram mips(context, textureMipsDesc());
  vk::Commands commands(context, "upload " + name + " textures");
  commands.begin();
  VkDeviceSize offset = 0;
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const scene::Texture& t = scene.textures[i];
    if (!drawn[i]) continue;
    for (VkDeviceSize done = 0; done < t.rgba.size();) {
      if (offset == ringBytes) {
        commands.submitAndWait();
        commands.begin();
        offset = 0;
      }
      VkDeviceSize bytes = std::min<VkDeviceSize>(t.rgba.size() - done, ringBytes - offset);
      std::memcpy(staging.mapped().data() + offset, t.rgba.data() + done, bytes);
      commands.copyBuffer(staging, gpu.texelPages[place.page[i]], bytes, offset, VkDeviceSize(place.first[i]) * 4 + done);
      offset += bytes;
      done += bytes;
    }
  }
  commands.transferToCompute();
  uint32_t most = 1;
  for (const scene::Texture& t : scene.textures) most = std::max(most, scene::mipLevels(t.width, t.height));
  for (uint32_t level = 1; level < most; ++level) {
    for (size_t i = 0; i < scene.textures.size(); ++i) {
      const scene::Texture& t = scene.textures[i];
      if (!drawn[i] || t.rgba.empty() || level >= scene::mipLevels(t.width, t.height)) continue;
      uint32_t first = place.first[i];
      uint32_t w = t.width, h = t.height;
      for (uint32_t l = 1; l < level; ++l) {
        first += w * h;
        w = std::max(w / 2, 1u), h = std::max(h / 2, 1u);
      }
      gpu::TextureMipPush push{first, w, h, first + w * h, std::max(w / 2, 1u), std::max(h / 2, 1u),
                               colour[i] ? 1u : 0u, 0u};
      mips.dispatchThreads(commands, {{0, &gpu.srgbDecode}, {1, &gpu.texelPages[place.page[i]]}}, push,
                           uint64_t(push.targetWidth) * push.targetHeight);
    }
    commands.computeToCompute();
  }
  commands.submitAndWait();
}

uint32_t wrapMode(bool repeat, bool mirror) {
  return mirror ? gpu::kWrapMirror : repeat ? gpu::kWrapRepeat : gpu::kWrapClamp;
}

gpu::GpuMaterial packMaterial(const scene::Material& m, const scene::Scene& scene) {
  auto slot = [&](const scene::TextureRef& ref) {
    gpu::GpuTextureSlot g{};
    // glm is column-major: t[column][row].
    const glm::mat3& t = ref.transform;
    g.uvRow0 = {t[0][0], t[1][0], t[2][0], 0.0f};
    g.uvRow1 = {t[0][1], t[1][1], t[2][1], 0.0f};
    bool usable = ref.present() && size_t(ref.texture) < scene.textures.size() && scene.textures[size_t(ref.texture)].width > 0;
    g.texture = usable ? static_cast<uint32_t>(ref.texture) : gpu::kNoTexture;
    g.texCoord = static_cast<uint32_t>(ref.texCoord);
    if (usable) g.lodOffset = float(scene::textureLodOffset(scene.textures[size_t(ref.texture)], ref));
    return g;
  };
  gpu::GpuMaterial g{};
  g.baseColorFactor = m.baseColorFactor;
  g.emissiveFactor = glm::vec4(m.emissiveFactor, 0.0f);
  g.attenuationColor = glm::vec4(m.attenuationColor, 0.0f);
  g.transmission = m.transmission;
  g.ior = m.ior;
  g.roughness = m.roughness;
  g.dispersion = m.dispersion;
  g.priority = static_cast<float>(m.priority);
  g.iorScale = m.iorScale;
  g.iorOffset = m.iorOffset;
  g.attenuationDistance = m.attenuates() ? m.attenuationDistance : 0.0f;
  g.base = slot(m.baseColorTexture);
  g.emissive = slot(m.emissiveTexture);
  g.iorMap = slot(m.iorTexture);
  g.normal = slot(m.normalTexture);
  g.normalScale = m.normalScale;
  g.alphaMode = m.alphaMode == scene::AlphaMode::Mask    ? gpu::kAlphaMask
                : m.alphaMode == scene::AlphaMode::Blend ? gpu::kAlphaBlend
                                                         : gpu::kAlphaOpaque;
  g.alphaCutoff = m.alphaCutoff;
  return g;
}

// What the packed materials use: a texture dropped as unusable counts as absent, as the trace sees it.
uint32_t surfaceOf(const std::vector<gpu::GpuMaterial>& materials) {
  uint32_t surface = 0;
  for (const gpu::GpuMaterial& m : materials) {
    for (const gpu::GpuTextureSlot* s : {&m.base, &m.emissive, &m.iorMap, &m.normal}) {
      if (s->texture != gpu::kNoTexture) surface |= gpu::kSurfaceTextures;
    }
    if (m.emissive.texture != gpu::kNoTexture) surface |= gpu::kSurfaceEmissiveMaps;
    if (m.iorMap.texture != gpu::kNoTexture) surface |= gpu::kSurfaceIorMaps;
    if (m.normal.texture != gpu::kNoTexture) surface |= gpu::kSurfaceNormalMaps;
    if (m.alphaMode != gpu::kAlphaOpaque) surface |= gpu::kSurfaceAlpha;
  }
  return surface;
}

}  // namespace

// A host scene's checks: every shape on the host, inside the buffers, with no
// deformation of snell's (the host deforms its own vertices).
static void checkHostShapes(const scene::Scene& scene, const HostBuffers& host) {
  if (!host.positions || !host.normals) throw std::invalid_argument(scene.source + ": the host's vertex buffers are null");
  for (const scene::Shape& shape : scene.shapes) {
    if (!shape.host) throw std::invalid_argument(scene.source + ": shape '" + shape.name + "' has no host vertices");
    if (uint64_t(shape.host->first) + shape.host->count > host.vertexCapacity) {
      throw std::invalid_argument(scene.source + ": shape '" + shape.name + "' uses vertices " +
                                  std::to_string(shape.host->first) + " to " +
                                  std::to_string(uint64_t(shape.host->first) + shape.host->count) +
                                  ", past the host buffers' " + std::to_string(host.vertexCapacity));
    }
    for (uint32_t index : shape.indices) {
      if (index >= shape.vertexCount()) {
        throw std::invalid_argument(scene.source + ": shape '" + shape.name + "' has index " + std::to_string(index) +
                                    " for " + std::to_string(shape.vertexCount()) + " vertices");
      }
    }
    if (shape.morphed() || shape.skinned()) {
      throw std::invalid_argument(scene.source + ": host shape '" + shape.name + "' has morph targets or a skin; the host deforms its own vertices");
    }
  }
}

vk::ComputeProgramDesc textureMipsDesc() { return {"texture mips", kSpvTextureMips, {}, false}; }

SceneGpu uploadScene(vk::Context& context, const scene::Scene& scene, const scene::Pose& pose,
                     const HostBuffers* host) {
  if (host) checkHostShapes(scene, *host);
  // Refused before anything is allocated where the device cannot hold it (the
  // estimate `snell info` prints; allocations are checked one by one as well).
  scene::SceneSummary estimate = scene::summarize(scene, 0, 0);
  context.checkFits(estimate.totalBytes(), (scene.source.empty() ? std::string("the scene") : scene.source) + " (" +
                                               std::to_string(estimate.triangles) + " triangles)");
  SceneGpu gpu;
  std::vector<int> shapeGeometry(scene.shapes.size(), -1);
  // A host's subdivision surfaces refine into snell's buffers, past the host's numbering.
  bool hostCopies = false;
  for (const scene::Shape& shape : scene.shapes) hostCopies = hostCopies || (host && shape.subdivided());
  uint64_t vertices = hostCopies ? host->vertexCapacity : 0, triangles = 0;
  for (size_t i = 0; i < pose.items.size(); ++i) {
    const scene::DrawItem& item = pose.items[i];
    const scene::Shape& shape = scene.shapes[size_t(item.shape)];
    if (!item.deforms() && shapeGeometry[size_t(item.shape)] >= 0) {
      gpu.itemGeometry.push_back(static_cast<uint32_t>(shapeGeometry[size_t(item.shape)]));
    } else {
      GeometryRange range;
      range.shape = item.shape;
      range.item = item.deforms() ? static_cast<int>(i) : -1;
      const bool inPlace = host && !shape.subdivided();
      range.firstVertex = inPlace ? shape.host->first : static_cast<uint32_t>(vertices);
      range.vertexCount = static_cast<uint32_t>(shape.vertexCount());
      if (shape.part()) {  // its triangles index its source's vertices, uploaded with the source
        const int source = shapeGeometry[size_t(shape.vertexSource)];
        if (item.deforms() || source < 0) throw std::logic_error(scene.source + ": a part drawn without its source");
        range.firstVertex = gpu.geometries[size_t(source)].firstVertex;
        range.vertexCount = 0;
      }
      range.firstTriangle = static_cast<uint32_t>(triangles);
      range.triangleCount = static_cast<uint32_t>(shape.triangleCount());
      if (!inPlace) vertices += range.vertexCount;
      triangles += shape.triangleCount();
      if (vertices >= (1ull << 31) || triangles >= (1ull << 31)) {
        throw std::runtime_error(scene.source + ": more than 2^31 vertices or triangles in view");
      }
      if (!item.deforms()) shapeGeometry[size_t(item.shape)] = static_cast<int>(gpu.geometries.size());
      gpu.itemGeometry.push_back(static_cast<uint32_t>(gpu.geometries.size()));
      gpu.geometries.push_back(range);
    }
    bool hasMaterial = shape.material >= 0 && size_t(shape.material) < scene.materials.size();
    gpu.itemMaterial.push_back(hasMaterial ? static_cast<uint32_t>(shape.material)
                                           : static_cast<uint32_t>(scene.materials.size()));
    const scene::Material* material = hasMaterial ? &scene.materials[size_t(shape.material)] : nullptr;
    gpu.itemRefractive.push_back(material && material->refractive() ? 1 : 0);
    gpu.itemSeeThrough.push_back(material && (material->refractive() || material->alphaMode != scene::AlphaMode::Opaque));
    // The default material is single-sided too, as glTF's is.
    const scene::Material& drawn = material ? *material : scene::Material{};
    gpu.itemSingleSided.push_back(!drawn.doubleSided && !drawn.refractive());
    if (gpu.itemSingleSided.back()) gpu.surface |= gpu::kSurfaceSingleSided;
  }
  if (host && !hostCopies) vertices = host->vertexCapacity;  // the host's numbering, gaps and all
  gpu.vertexCount = static_cast<uint32_t>(vertices);
  gpu.triangleCount = static_cast<uint32_t>(triangles);

  std::vector<float> positions, normals;
  std::vector<glm::vec4> texcoords;
  std::vector<uint32_t> indices;
  positions.reserve(vertices * 3);
  normals.reserve(vertices * 3);
  texcoords.reserve(vertices);
  indices.reserve(triangles * 3);
  if (host) texcoords.assign(vertices, glm::vec4(0.0f));
  // Until the first frame copies and refines the host's, its vertices here are zero.
  if (hostCopies) positions.assign(vertices * 3, 0.0f), normals.assign(vertices * 3, 0.0f);
  for (const GeometryRange& range : gpu.geometries) {
    const scene::Shape& shape = scene.shapes[size_t(range.shape)];
    for (size_t v = 0; host && v < range.vertexCount; ++v) {
      glm::vec2 uv0 = v < shape.texcoords0.size() ? shape.texcoords0[v] : glm::vec2(0.0f);
      glm::vec2 uv1 = v < shape.texcoords1.size() ? shape.texcoords1[v] : glm::vec2(0.0f);
      texcoords[range.firstVertex + v] = glm::vec4(uv0, uv1);
    }
    for (size_t v = 0; !host && v < range.vertexCount; ++v) {
      const glm::vec3& p = shape.positions[v];
      glm::vec3 n = v < shape.normals.size() ? shape.normals[v] : glm::vec3(0.0f);
      positions.insert(positions.end(), {p.x, p.y, p.z});
      normals.insert(normals.end(), {n.x, n.y, n.z});
      glm::vec2 uv0 = v < shape.texcoords0.size() ? shape.texcoords0[v] : glm::vec2(0.0f);
      glm::vec2 uv1 = v < shape.texcoords1.size() ? shape.texcoords1[v] : glm::vec2(0.0f);
      texcoords.emplace_back(uv0, uv1);
    }
    for (uint32_t index : shape.indices) indices.push_back(range.firstVertex + index);
  }

  std::vector<gpu::GpuMaterial> materials;
  for (const scene::Material& m : scene.materials) materials.push_back(packMaterial(m, scene));
  materials.push_back(packMaterial(scene::Material{}, scene));  // for shapes without one
  gpu.surface |= surfaceOf(materials);

  TexturePlacement place = placeTextures(context, scene);
  std::vector<gpu::GpuTexture> textures;
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    const scene::Texture& t = scene.textures[i];
    uint32_t flags = wrapMode(t.repeatS, t.mirrorS) | (wrapMode(t.repeatT, t.mirrorT) << 2) |
                     (t.linearFilter ? 0u : gpu::kTextureFlagNearest) |
                     (scene::mipLevels(std::max(t.width, 1u), std::max(t.height, 1u)) << gpu::kTextureLevelsShift) |
                     (place.page[i] << gpu::kTexturePageShift);
    textures.push_back({place.first[i], t.width, t.height, flags});
  }

  const std::string& name = scene.source.empty() ? std::string("scene") : scene.source;
  if (hostCopies) {
    const VkDeviceSize hostBytes = VkDeviceSize(host->vertexCapacity) * 12;
    gpu.hostPositions = vk::Buffer::borrow(context, host->positions, hostBytes, name + " host positions");
    gpu.hostNormals = vk::Buffer::borrow(context, host->normals, hostBytes, name + " host normals");
    gpu.positions = uploaded(context, positions, name + " positions", gpu.bytes, true);
    gpu.normals = uploaded(context, normals, name + " normals", gpu.bytes);
  } else if (host) {
    gpu.positions = vk::Buffer::borrow(context, host->positions, vertices * 12, name + " host positions");
    gpu.normals = vk::Buffer::borrow(context, host->normals, vertices * 12, name + " host normals");
  } else {
    gpu.positions = uploaded(context, positions, name + " positions", gpu.bytes, true);
    gpu.normals = uploaded(context, normals, name + " normals", gpu.bytes);
  }
  gpu.texcoords = uploaded(context, texcoords, name + " texcoords", gpu.bytes);
  gpu.indices = uploaded(context, indices, name + " indices", gpu.bytes, true);
  gpu.materials = uploaded(context, materials, name + " materials", gpu.bytes);
  gpu.textures = uploaded(context, textures, name + " texture table", gpu.bytes);
  gpu.srgbDecode = uploaded(context, srgbDecodeTable(), name + " sRGB decode", gpu.bytes);
  const auto start = std::chrono::steady_clock::now();
  uploadTextures(context, scene, place, gpu);
  gpu.textureUploadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return gpu;
}

namespace {

// A matrix's top three rows, as the shaders read an affine transform.
void rows(const glm::dmat4& m, glm::vec4 out[3]) {
  for (int r = 0; r < 3; ++r) out[r] = glm::vec4(glm::dvec4(m[0][r], m[1][r], m[2][r], m[3][r]));
}

}  // namespace

std::vector<gpu::GpuInstance> SceneGpu::packInstances(const scene::Pose& pose, const glm::dvec3& origin) const {
  std::vector<gpu::GpuInstance> instances(pose.items.size());
  for (size_t i = 0; i < pose.items.size(); ++i) {
    const scene::DrawItem& item = pose.items[i];
    // Skinned positions come out of the deform pass relative to the item's anchor.
    glm::dmat4 toWorld = item.world;
    if (item.skinned) toWorld = glm::dmat4(1.0), toWorld[3] = glm::dvec4(DeformPass::anchorOf(item), 1.0);
    toWorld[3] -= glm::dvec4(origin, 0.0);
    gpu::GpuInstance& inst = instances[i];
    rows(toWorld, inst.objectToWorld);
    rows(glm::inverse(toWorld), inst.worldToObject);
    inst.geometry = itemGeometry[i];
    inst.material = itemMaterial[i];
    // Faces are tested in the instance's own space, where a mirroring transform turns no front round (glTF).
    inst.flags = itemSingleSided[i] ? gpu::kInstanceCullBackFaces : 0u;
  }
  return instances;
}

std::vector<gpu::GpuLight> SceneGpu::packLights(const scene::Scene& scene, const scene::Pose& pose,
                                                const glm::dvec3& origin) {
  std::vector<gpu::GpuLight> lights;
  for (size_t n = 0; n < scene.nodes.size() && n < pose.world.size(); ++n) {
    int index = scene.nodes[n].light;
    if (index < 0 || size_t(index) >= scene.lights.size()) continue;
    const scene::Light& light = scene.lights[size_t(index)];
    glm::dmat4 world(pose.world[n]);
    gpu::GpuLight g{};
    uint32_t type = light.type == scene::LightType::Directional ? gpu::kLightDirectional
                    : light.type == scene::LightType::Point     ? gpu::kLightPoint
                                                                : gpu::kLightSpot;
    g.positionType = glm::vec4(glm::vec3(glm::dvec3(world[3]) - origin), float(type));
    glm::dvec3 direction = -glm::normalize(glm::dvec3(world[2]));
    g.direction = glm::vec4(glm::vec3(direction), std::isfinite(light.range) ? light.range : 0.0f);
    g.radiance = glm::vec4(light.color * light.intensity, 0.0f);
    g.cone = glm::vec4(std::cos(light.innerConeAngle), std::cos(light.outerConeAngle), 0.0f, 0.0f);
    lights.push_back(g);
  }
  return lights;
}

void SceneGpu::appendBindings(std::vector<vk::BufferBinding>& out, const vk::Buffer& instances,
                              const vk::Buffer& lights) const {
  out.insert(out.end(), {{gpu::kSceneBindingInstances, &instances},
                         {gpu::kSceneBindingPositions, &positions},
                         {gpu::kSceneBindingNormals, &normals},
                         {gpu::kSceneBindingTexcoords, &texcoords},
                         {gpu::kSceneBindingIndices, &indices},
                         {gpu::kSceneBindingMaterials, &materials},
                         {gpu::kSceneBindingLights, &lights},
                         {gpu::kSceneBindingTextures, &textures},
                         {gpu::kSceneBindingSrgbDecode, &srgbDecode}});
  for (uint32_t p = 0; p < gpu::kTexelPages; ++p) out.push_back({gpu::kSceneBindingTexelPages + p, &texelPages[p]});
}

}  // namespace snell::render
