// The scene's static data on the GPU, laid out for the BVH, trace and raster
// passes: every vertex of every geometry in one set of buffers (deforming
// items write their slice each frame), triangles with absolute vertex
// indices, materials, and texel pages holding every texture's mip chain.
#pragma once

#include "scene/evaluate.h"
#include "scene/scene.h"
#include "shared/trace.h"
#include "vk/buffer.h"
#include "vk/context.h"
#include "vk/descriptors.h"

#include <array>
#include <cstdint>
#include <vector>

namespace snell::render {

/// One bottom-level group: a static shape (shared by all its instances) or
/// one deforming draw item's own copy of its shape.
struct GeometryRange {
  int shape = -1;
  int item = -1;  ///< the deforming draw item; -1 for a static shape
  uint32_t firstVertex = 0, vertexCount = 0;
  uint32_t firstTriangle = 0, triangleCount = 0;
};

struct SceneGpu {
  std::vector<GeometryRange> geometries;
  std::vector<uint32_t> itemGeometry;  ///< per pose item
  std::vector<uint32_t> itemMaterial;  ///< per pose item: index into the material table
  std::vector<char> itemRefractive;    ///< per pose item: its faces refract (material transmission > 0)
  uint32_t vertexCount = 0, triangleCount = 0;
  vk::Buffer positions, normals;  ///< float[3 * vertexCount]; rest pose, deformed slices rewritten per frame
  vk::Buffer texcoords;           ///< vec4 per vertex: uv0, uv1
  vk::Buffer indices;             ///< uint[3 * triangleCount], absolute
  vk::Buffer materials;           ///< gpu::GpuMaterial[], the scene's then a default one
  vk::Buffer textures;            ///< gpu::GpuTexture[]
  vk::Buffer srgbDecode;          ///< float[kSrgbDecodeWords]: each sRGB byte's linear value
  std::array<vk::Buffer, gpu::kTexelPages> texelPages;  ///< RGBA8 mip chains (unused pages: 16 bytes)
  uint64_t textureBytes = 0;      ///< GPU memory the texel pages take, mips included

  /// Appends the bindings of the scene's textures as trace.h numbers them for
  /// a pass: the texture table, the sRGB decode table, then the pages from `firstPageSlot`.
  void appendTextureBindings(std::vector<vk::BufferBinding>& out, uint32_t tableSlot, uint32_t decodeSlot,
                             uint32_t firstPageSlot) const;
  uint64_t bytes = 0;             ///< GPU memory the buffers above take
};

/// Uploads the scene for the draw items of `layout` (which items exist does not
/// change with time). Throws std::runtime_error naming the scene when it is
/// larger than the device's buffers can hold.
SceneGpu uploadScene(vk::Context& context, const scene::Scene& scene, const scene::Pose& layout);

/// Mip levels of a width x height texture: down to 1x1, each level half the
/// one above (rounded down, at least 1).
uint32_t mipLevels(uint32_t width, uint32_t height);
/// Texels of a width x height texture's whole mip chain.
uint64_t mipChainTexels(uint32_t width, uint32_t height);

}  // namespace snell::render
