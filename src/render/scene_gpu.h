// The scene's static data on the GPU, laid out for the BVH, trace and raster
// passes: every vertex of every geometry in one set of buffers (deforming
// items write their slice each frame), triangles with absolute vertex
// indices, materials, and texel pages holding every texture's mip chain.
#pragma once

#include "scene/evaluate.h"
#include "scene/scene.h"
#include "shared/bvh.h"
#include "shared/trace.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "vk/context.h"
#include "vk/descriptors.h"

#include <glm/glm.hpp>

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
  /// Per pose item: a viewport leaves its pixels to the trace (its faces
  /// refract, or alpha may make them see-through).
  std::vector<char> itemSeeThrough;
  /// Per pose item: its faces are seen from the front only (a single-sided
  /// material that is not glass: glTF's and USD's doubleSided false).
  std::vector<char> itemSingleSided;
  /// gpu::kSurface* bits: what its materials use (the trace compiles out the rest).
  uint32_t surface = 0;
  uint32_t vertexCount = 0, triangleCount = 0;
  vk::Buffer positions, normals;  ///< float[3 * vertexCount]; rest pose, deformed slices rewritten per frame
  /// A host scene with subdivision surfaces: the host's own buffers, which
  /// hold their cages; `positions` and `normals` are then snell's, holding
  /// the refined vertices past the host's and a copy of every other mesh's,
  /// taken when the host marks it dirty (vertex_feed.h).
  vk::Buffer hostPositions, hostNormals;
  vk::Buffer texcoords;           ///< vec4 per vertex: uv0, uv1
  vk::Buffer indices;             ///< uint[3 * triangleCount], absolute
  vk::Buffer materials;           ///< gpu::GpuMaterial[], the scene's then a default one
  vk::Buffer textures;            ///< gpu::GpuTexture[]
  vk::Buffer srgbDecode;          ///< float[kSrgbDecodeWords]: each sRGB byte's linear value
  std::array<vk::Buffer, gpu::kTexelPages> texelPages;  ///< RGBA8 mip chains (unused pages: 16 bytes)
  uint64_t textureBytes = 0;      ///< GPU memory the texel pages take, mips included
  double textureUploadSeconds = 0.0;  ///< level 0 through the staging ring, then the mips made on the GPU

  /// Each pose item's instance record relative to `origin`, in double until
  /// the cast, so float data near the camera keeps its precision however far
  /// the scene is from the world's origin.
  std::vector<gpu::GpuInstance> packInstances(const scene::Pose& pose, const glm::dvec3& origin) const;
  /// The lights of `scene`'s nodes at the pose, relative to `origin`.
  static std::vector<gpu::GpuLight> packLights(const scene::Scene& scene, const scene::Pose& pose,
                                               const glm::dvec3& origin);

  /// Appends the scene binding set (shared/scene.h) with the renderer's
  /// `instances` and `lights`: every pass that reads the scene binds these.
  void appendBindings(std::vector<vk::BufferBinding>& out, const vk::Buffer& instances, const vk::Buffer& lights) const;
  uint64_t bytes = 0;             ///< GPU memory the buffers above take

  /// Whether the scene's vertices are copies of a host's (hostPositions set).
  bool copiesHost() const { return hostPositions.handle() != VK_NULL_HANDLE; }
};

/// Level 0 of the textures goes to the GPU through one staging ring of at most this many bytes.
inline constexpr uint64_t kTextureStagingRingBytes = 32ull << 20;

/// A host application's vertex buffers, read in place (the embedding API):
/// packed float triples, `vertexCapacity` vertices each, usable as storage
/// buffers. Every shape of such a scene keeps its vertices here (Shape::host).
struct HostBuffers {
  VkBuffer positions = VK_NULL_HANDLE, normals = VK_NULL_HANDLE;
  uint32_t vertexCapacity = 0;
};

/// Uploads the scene for the draw items of `pose` (which items exist does not
/// change with time). Throws std::runtime_error naming the scene when it is
/// larger than the device's buffers can hold. With `host`, positions and
/// normals are the host's buffers, and every shape must be a host shape.
SceneGpu uploadScene(vk::Context& context, const scene::Scene& scene, const scene::Pose& pose,
                     const HostBuffers* host = nullptr);

/// The pipeline the upload makes each texture's mip levels with.
vk::ComputeProgramDesc textureMipsDesc();

}  // namespace snell::render
