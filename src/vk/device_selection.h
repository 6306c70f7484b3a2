// Which Vulkan device snell runs on, and why every other one was not chosen.
// The choice is a pure function of facts read from each device, so it is
// testable without owning several GPUs.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>
#include <span>
#include <set>
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
  uint32_t vendorId = 0;           ///< PCI vendor (0x10de NVIDIA, 0x1002 AMD, 0x8086 Intel)
  std::string uuid;   ///< deviceUUID, 8-4-4-4-12 hex digits (nvidia-smi prints it after "GPU-")
  std::string pciBus; ///< domain:bus:device.function (VK_EXT_pci_bus_info); empty where the driver has none
  uint32_t computeQueueFamily = UINT32_MAX;
  /// VK_KHR_pipeline_executable_properties: the driver reports per-pipeline
  /// statistics (registers, spills), which benchmarks print.
  bool pipelineStatistics = false;
  /// Requirements this device does not meet, in words; empty when it qualifies.
  std::vector<std::string> unmet;
  /// Why it cannot run work although it meets the rest, in words; empty when it
  /// can. A device without device-local memory (RADV's null device under
  /// RADV_FORCE_FAMILY) still compiles pipelines: DeviceUse::Compile takes it.
  std::string cannotRun;
};

/// What a device is chosen for: running work, or only compiling pipelines
/// (`snell bench pipelines`), which needs no memory.
enum class DeviceUse { Run, Compile };

/// Whether `d` meets every requirement of `use`.
bool qualifies(const DeviceFacts& d, DeviceUse use = DeviceUse::Run);
/// The requirements of `use` that `d` does not meet, in words.
std::vector<std::string> unmetFor(const DeviceFacts& d, DeviceUse use = DeviceUse::Run);

/// Reads the facts of one physical device and checks snell's requirements:
/// Vulkan 1.3, a compute queue, subgroup basic/ballot/arithmetic/shuffle in compute
/// shaders, subgroupSizeControl, computeFullSubgroups and maintenance4.
DeviceFacts readDeviceFacts(VkPhysicalDevice device, uint32_t index);

/// The names of the device extensions `device` offers.
std::set<std::string> deviceExtensions(VkPhysicalDevice device);

/// The outcome of choosing: the chosen device (if any) and one line per device
/// saying why it was or was not chosen.
struct DeviceChoice {
  std::optional<uint32_t> chosen;  ///< position in the span given
  std::vector<std::string> verdicts;
};

/// Chooses a device: `override` (--device or SNELL_DEVICE: an index, a UUID
/// with or without nvidia-smi's "GPU-" prefix, or a case-insensitive
/// substring of the name) narrows the field; among qualifying devices a
/// discrete GPU ranks first, then integrated, virtual, CPU (lavapipe); ties go
/// to the larger device-local memory, then to the lower index. `source` says
/// where the override came from, for the verdicts ("SNELL_DEVICE=..." if empty).
DeviceChoice chooseDevice(std::span<const DeviceFacts> devices, const std::string& override,
                          const std::string& source = "", DeviceUse use = DeviceUse::Run);

/// A launcher's GPU list as a device override. Slurm and CUDA launchers name
/// GPUs by CUDA_VISIBLE_DEVICES (indices or GPU-UUIDs) or SLURM_STEP_GPUS
/// (the node's GPU indices), which the Vulkan driver does not read: an index
/// k is the k-th GPU in PCI bus order (nvidia-smi's, and Slurm's, numbering),
/// a UUID names itself. The first entry is taken. Returns the override (a
/// device index, as text) and, in `why`, one line saying how it was found;
/// throws VulkanError naming the variable when it names no device.
std::string launcherOverride(std::span<const DeviceFacts> devices, const std::string& variable,
                             const std::string& value, std::string& why);

/// Every GPU of a launcher's list (CUDA_VISIBLE_DEVICES=0,1), as launcherOverride maps one.
std::vector<uint32_t> launcherDevices(std::span<const DeviceFacts> devices, const std::string& variable,
                                      const std::string& value);

/// The devices --devices names, a worker each: "all" is every qualifying
/// device of the best one's type (every GPU; lavapipe where there is none);
/// otherwise a comma list of indices and UUIDs, where one device may come
/// twice (two workers on it). Throws std::invalid_argument naming the entry
/// that names no device, or one that does not qualify, and why (VulkanError
/// where "all" finds no qualifying device).
std::vector<uint32_t> chooseDeviceList(std::span<const DeviceFacts> devices, const std::string& list);

/// "discrete GPU", "integrated GPU", "virtual GPU", "CPU" or "other".
const char* deviceTypeName(VkPhysicalDeviceType type);

/// "1.3.230"
std::string versionString(uint32_t apiVersion);

}  // namespace snell::vk
