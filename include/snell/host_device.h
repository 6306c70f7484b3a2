// The handles of a device a host application made, as snell's public API
// takes them and its Vulkan layer adopts them (vk::AdoptedDevice), stated
// once. It includes Vulkan's header alone, so every layer may include it
// (tests/tools/check_layers.py places it in the bottom layer).
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>

namespace snell {

/// A device a host application created, for snell to use and never destroy.
/// The device must be Vulkan 1.3 with subgroupSizeControl, computeFullSubgroups
/// and maintenance4 enabled (state them in `enabled13`), and `queue` must
/// support compute and graphics. Host-owned buffers and images snell uses must
/// be in `queueFamily` with exclusive sharing.
struct HostDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  uint32_t queueFamily = 0;
  VkQueue queue = VK_NULL_HANDLE;
  /// What the host enabled of Vulkan 1.3 (its pNext is ignored).
  VkPhysicalDeviceVulkan13Features enabled13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
};

}  // namespace snell
