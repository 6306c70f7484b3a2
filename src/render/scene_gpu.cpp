// Packing a scene into the buffers the passes read (shaders/shared/trace.h).
#include "render/scene_gpu.h"

#include "shared/trace.h"
#include "vk/commands.h"

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

// The head of the texel buffer (kSrgbDecodeWords): float bits of each sRGB byte's linear value.
std::vector<uint32_t> srgbDecodeTable() {
  std::vector<uint32_t> table(gpu::kSrgbDecodeWords);
  for (uint32_t v = 0; v < gpu::kSrgbDecodeWords; ++v) {
    float linear = static_cast<float>(scene::srgbToLinear(static_cast<uint8_t>(v)));
    std::memcpy(&table[v], &linear, sizeof linear);
  }
  return table;
}

uint32_t wrapMode(bool repeat, bool mirror) {
  return mirror ? gpu::kWrapMirror : repeat ? gpu::kWrapRepeat : gpu::kWrapClamp;
}

void uvRows(const scene::TextureRef& ref, glm::vec4& row0, glm::vec4& row1) {
  // glm is column-major: m[column][row].
  const glm::mat3& m = ref.transform;
  row0 = {m[0][0], m[1][0], m[2][0], row0.w};
  row1 = {m[0][1], m[1][1], m[2][1], row1.w};
}

gpu::GpuMaterial packMaterial(const scene::Material& m, const scene::Scene& scene) {
  auto texture = [&](const scene::TextureRef& ref) {
    bool usable = ref.present() && size_t(ref.texture) < scene.textures.size() && scene.textures[size_t(ref.texture)].width > 0;
    return usable ? static_cast<uint32_t>(ref.texture) : gpu::kNoTexture;
  };
  gpu::GpuMaterial g{};
  g.baseColorFactor = m.baseColorFactor;
  g.emissiveFactor = glm::vec4(m.emissiveFactor, m.transmission);
  g.baseUvRow0.w = m.ior;
  uvRows(m.baseColorTexture, g.baseUvRow0, g.baseUvRow1);
  uvRows(m.emissiveTexture, g.emissiveUvRow0, g.emissiveUvRow1);
  g.textures = {texture(m.baseColorTexture), static_cast<uint32_t>(m.baseColorTexture.texCoord),
                texture(m.emissiveTexture), static_cast<uint32_t>(m.emissiveTexture.texCoord)};
  g.baseUvRow1.w = m.roughness;
  g.emissiveUvRow0.w = m.dispersion;
  g.emissiveUvRow1.w = static_cast<float>(m.priority);
  g.attenuation = glm::vec4(m.attenuationColor, m.attenuates() ? m.attenuationDistance : 0.0f);
  uvRows(m.iorTexture, g.iorUvRow0, g.iorUvRow1);
  g.iorUvRow0.w = m.iorScale;
  g.iorUvRow1.w = m.iorOffset;
  g.iorTexture = {texture(m.iorTexture), static_cast<uint32_t>(m.iorTexture.texCoord), 0u, 0u};
  return g;
}

}  // namespace

SceneGpu uploadScene(vk::Context& context, const scene::Scene& scene, const scene::Pose& layout) {
  SceneGpu gpu;
  std::vector<int> shapeGeometry(scene.shapes.size(), -1);
  uint64_t vertices = 0, triangles = 0;
  for (size_t i = 0; i < layout.items.size(); ++i) {
    const scene::DrawItem& item = layout.items[i];
    const scene::Shape& shape = scene.shapes[size_t(item.shape)];
    if (!item.deforms() && shapeGeometry[size_t(item.shape)] >= 0) {
      gpu.itemGeometry.push_back(static_cast<uint32_t>(shapeGeometry[size_t(item.shape)]));
    } else {
      GeometryRange range;
      range.shape = item.shape;
      range.item = item.deforms() ? static_cast<int>(i) : -1;
      range.firstVertex = static_cast<uint32_t>(vertices);
      range.vertexCount = static_cast<uint32_t>(shape.vertexCount());
      range.firstTriangle = static_cast<uint32_t>(triangles);
      range.triangleCount = static_cast<uint32_t>(shape.triangleCount());
      vertices += shape.vertexCount();
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
    gpu.itemRefractive.push_back(hasMaterial && scene.materials[size_t(shape.material)].refractive() ? 1 : 0);
  }
  gpu.vertexCount = static_cast<uint32_t>(vertices);
  gpu.triangleCount = static_cast<uint32_t>(triangles);

  std::vector<float> positions, normals;
  std::vector<glm::vec4> texcoords;
  std::vector<uint32_t> indices;
  positions.reserve(vertices * 3);
  normals.reserve(vertices * 3);
  texcoords.reserve(vertices);
  indices.reserve(triangles * 3);
  for (const GeometryRange& range : gpu.geometries) {
    const scene::Shape& shape = scene.shapes[size_t(range.shape)];
    for (size_t v = 0; v < shape.vertexCount(); ++v) {
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

  std::vector<gpu::GpuTexture> textures;
  std::vector<uint32_t> texels = srgbDecodeTable();
  for (const scene::Texture& t : scene.textures) {
    gpu::GpuTexture g{static_cast<uint32_t>(texels.size()), t.width, t.height,
                      wrapMode(t.repeatS, t.mirrorS) | (wrapMode(t.repeatT, t.mirrorT) << 2) | (t.linearFilter ? 0u : 16u)};
    size_t count = size_t(t.width) * t.height;
    size_t at = texels.size();
    texels.resize(at + count);
    if (count) std::memcpy(&texels[at], t.rgba.data(), count * 4);
    textures.push_back(g);
  }

  const std::string& name = scene.source.empty() ? std::string("scene") : scene.source;
  gpu.positions = uploaded(context, positions, name + " positions", gpu.bytes, true);
  gpu.normals = uploaded(context, normals, name + " normals", gpu.bytes);
  gpu.texcoords = uploaded(context, texcoords, name + " texcoords", gpu.bytes);
  gpu.indices = uploaded(context, indices, name + " indices", gpu.bytes, true);
  gpu.materials = uploaded(context, materials, name + " materials", gpu.bytes);
  gpu.textures = uploaded(context, textures, name + " texture table", gpu.bytes);
  gpu.texels = uploaded(context, texels, name + " texels", gpu.bytes);
  return gpu;
}

}  // namespace snell::render
