// The driver's own ray tracing acceleration structures
// (VK_KHR_acceleration_structure) over the same triangles as snell's trees:
// the peer whose build, update and memory snell's are measured against, on
// the same GPU in the same run. Where the device has none (lavapipe), the
// benchmarks say so and carry on.
#pragma once

#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"

#include <vulkan/vulkan.h>

#include <cstdint>

namespace snell::peer {

enum class DriverBuild {
  FastBuild,  ///< VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR
  FastTrace,  ///< VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR
};

/// Usage flags the positions and indices a DriverBlas reads must have been created with.
inline constexpr VkBufferUsageFlags kDriverInputUsage =
    VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

/// One bottom-level acceleration structure over an indexed triangle mesh,
/// built to allow in-place updates.
class DriverBlas {
 public:
  /// `positions` holds float triples, `indices` uint32 triples; both with
  /// kDriverInputUsage and device addresses. Throws when the context has no
  /// driver acceleration structures (DeviceCaps::driverAccelerationStructures).
  DriverBlas(vk::Context& context, const vk::Buffer& positions, uint32_t vertexCount, const vk::Buffer& indices,
             uint32_t triangleCount, DriverBuild mode);
  ~DriverBlas();
  DriverBlas(const DriverBlas&) = delete;
  DriverBlas& operator=(const DriverBlas&) = delete;

  /// Records a build from scratch, between barriers.
  void recordBuild(vk::Commands& commands);
  /// Records an in-place update (the same triangles, moved), between barriers.
  void recordUpdate(vk::Commands& commands);

  /// The structure's own size, as the driver asked for it.
  uint64_t structureBytes() const { return structureBytes_; }
  uint64_t scratchBytes() const { return scratch_.size(); }

 private:
  void record(vk::Commands& commands, bool update);

  vk::Context& context_;
  VkAccelerationStructureGeometryKHR geometry_{};
  VkBuildAccelerationStructureFlagsKHR flags_ = 0;
  uint32_t triangleCount_ = 0;
  uint64_t structureBytes_ = 0;
  vk::Buffer storage_, scratch_;
  VkDeviceAddress scratchAddress_ = 0;
  VkAccelerationStructureKHR structure_ = VK_NULL_HANDLE;
  PFN_vkCmdBuildAccelerationStructuresKHR build_ = nullptr;
  PFN_vkDestroyAccelerationStructureKHR destroy_ = nullptr;
};

}  // namespace snell::peer
