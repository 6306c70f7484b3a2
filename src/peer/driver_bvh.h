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
#include <memory>
#include <string>
#include <vector>

namespace snell::peer {

enum class DriverBuild {
  FastBuild,  ///< VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR
  FastTrace,  ///< VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR
};

/// Usage flags the positions and indices a DriverBlas reads must have been created with.
inline constexpr VkBufferUsageFlags kDriverInputUsage =
    VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;

/// An acceleration structure with its storage and its build scratch, which
/// both levels need alike; destroyed once the GPU is done with it.
class DriverStructure {
 public:
  DriverStructure(vk::Context& context, VkAccelerationStructureTypeKHR type, VkDeviceSize bytes,
                  VkDeviceSize scratchBytes, const std::string& name);
  ~DriverStructure();
  DriverStructure(const DriverStructure&) = delete;
  DriverStructure& operator=(const DriverStructure&) = delete;

  VkAccelerationStructureKHR handle() const { return structure_; }
  VkDeviceAddress address() const { return address_; }
  VkDeviceAddress scratchAddress() const { return scratchAddress_; }
  uint64_t storageBytes() const { return storage_.size(); }
  uint64_t scratchBytes() const { return scratch_.size(); }

 private:
  vk::Context& context_;
  vk::Buffer storage_, scratch_;
  VkDeviceAddress scratchAddress_ = 0, address_ = 0;
  VkAccelerationStructureKHR structure_ = VK_NULL_HANDLE;
  PFN_vkDestroyAccelerationStructureKHR destroy_ = nullptr;
};

/// One bottom-level acceleration structure over an indexed triangle mesh,
/// built to allow in-place updates.
class DriverBlas {
 public:
  /// `positions` holds float triples, `indices` uint32 triples; both with
  /// kDriverInputUsage and device addresses. Throws when the context has no
  /// driver acceleration structures (DeviceCaps::driverAccelerationStructures).
  /// `firstTriangle`: where this mesh's triangles start in `indices`.
  DriverBlas(vk::Context& context, const vk::Buffer& positions, uint32_t vertexCount, const vk::Buffer& indices,
             uint32_t triangleCount, DriverBuild mode, uint32_t firstTriangle = 0);
  DriverBlas(const DriverBlas&) = delete;
  DriverBlas& operator=(const DriverBlas&) = delete;

  /// Records a build from scratch, between barriers.
  void recordBuild(vk::Commands& commands);
  /// Records an in-place update (the same triangles, moved), between barriers.
  void recordUpdate(vk::Commands& commands);
  /// Records builds (or updates) of several in one call, between one pair of
  /// barriers, so the driver may run them side by side as an application would.
  static void recordBatch(vk::Commands& commands, const std::vector<DriverBlas*>& structures, bool update);

  /// The structure's own size, as the driver asked for it.
  uint64_t structureBytes() const { return structureBytes_; }
  uint64_t scratchBytes() const { return structure_->scratchBytes(); }
  /// What a top-level instance refers to it by.
  VkDeviceAddress address() const { return structure_->address(); }

 private:
  void record(vk::Commands& commands, bool update);
  VkAccelerationStructureBuildGeometryInfoKHR buildInfo(bool update) const;

  VkAccelerationStructureGeometryKHR geometry_{};
  VkBuildAccelerationStructureFlagsKHR flags_ = 0;
  uint32_t triangleCount_ = 0;
  uint64_t structureBytes_ = 0;
  std::unique_ptr<DriverStructure> structure_;
  PFN_vkCmdBuildAccelerationStructuresKHR build_ = nullptr;
};

/// A top-level acceleration structure over up to `capacity` instances
/// (VkAccelerationStructureInstanceKHR in `instances`, written before each build).
class DriverTlas {
 public:
  DriverTlas(vk::Context& context, uint32_t capacity);
  DriverTlas(const DriverTlas&) = delete;
  DriverTlas& operator=(const DriverTlas&) = delete;

  /// The buffer the instances go in (device-local; copy into it, then build).
  const vk::Buffer& instances() const { return instances_; }
  /// Records a build over the first `count` instances, between barriers.
  void recordBuild(vk::Commands& commands, uint32_t count);
  /// What a ray tracing shader traces against.
  VkDeviceAddress address() const { return structure_->address(); }
  uint64_t bytes() const { return structure_->storageBytes() + structure_->scratchBytes() + instances_.size(); }

 private:
  uint32_t capacity_ = 0;
  vk::Buffer instances_;
  std::unique_ptr<DriverStructure> structure_;
  PFN_vkCmdBuildAccelerationStructuresKHR build_ = nullptr;
};

}  // namespace snell::peer
