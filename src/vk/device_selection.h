// Which Vulkan device snell runs on, and why every other one was not chosen.
// The choice is a pure function of facts read from each device, so it is
// testable without owning several GPUs.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace snell::vk {

/// What snell needs to know about one physical device to choose it.
struct DeviceFacts {
  uint32_t index = 0;  ///< position in vkEnumeratePhysicalDevices order
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  VkDriverId driverId = VkDriverId(0);
  std::string driverName;  ///< e.g. "llvmpipe", "NVIDIA"
  std::string driverInfo;  ///< the driver's version text
  uint32_t apiVersion = 0;
  uint32_t subgroupSize = 0;     ///< default subgroup size
  uint32_t minSubgroupSize = 0;  ///< smallest the driver may pick for compute
  uint32_t maxSubgroupSize = 0;
  uint64_t deviceLocalBytes = 0;  ///< sum of the DEVICE_LOCAL heaps
  uint32_t computeQueueFamily = UINT32_MAX;
  /// VK_KHR_pipeline_executable_properties: the driver reports per-pipeline
  /// statistics (registers, spills), which benchmarks print.
  bool pipelineStatistics = false;
  /// Requirements this device does not meet, in words; empty when it qualifies.
  std::vector<std::string> unmet;
};

/// Reads the facts of one physical device and checks snell's requirements:
/// Vulkan 1.3, a compute queue, subgroup basic/ballot/arithmetic in compute
/// shaders, subgroupSizeControl, computeFullSubgroups and maintenance4.
DeviceFacts readDeviceFacts(VkPhysicalDevice device, uint32_t index);

/// The outcome of choosing: the chosen device (if any) and one line per device
/// saying why it was or was not chosen.
struct DeviceChoice {
  std::optional<uint32_t> chosen;  ///< position in the span given
  std::vector<std::string> verdicts;
};

/// Chooses a device: `override` (SNELL_DEVICE: an index, or a case-insensitive
/// substring of the name) narrows the field; among qualifying devices a discrete
/// GPU ranks first, then integrated, virtual, CPU (lavapipe); ties go to the
/// larger device-local memory, then to the lower index.
DeviceChoice chooseDevice(std::span<const DeviceFacts> devices, const std::string& override);

/// "discrete GPU", "integrated GPU", "virtual GPU", "CPU" or "other".
const char* deviceTypeName(VkPhysicalDeviceType type);

/// "1.3.230"
std::string versionString(uint32_t apiVersion);

}  // namespace snell::vk
