// The Vulkan context: instance, physical device, device and queue, either
// created by snell or adopted from a host application that keeps ownership.
#pragma once

#include "snell/host_device.h"
#include "vk/device_selection.h"
#include "vk/error.h"
#include "vk/pipeline_cache.h"

#include <vulkan/vulkan.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <future>
#include <memory>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <thread>
#include <unordered_map>
#include <set>
#include <string>
#include <algorithm>
#include <vector>

namespace snell::vk {

/// What the process environment says about the device, where no one names
/// one: SNELL_DEVICE, else the GPUs a launcher gave the process (Slurm or a
/// CUDA-style scheduler), which no Vulkan driver reads and launcherOverride
/// maps onto Vulkan's devices. io::deviceEnvironment() fills it.
struct DeviceEnvironment {
  std::string device;  ///< SNELL_DEVICE's value ("": unset)
  std::string launcherVariable, launcherValue;  ///< e.g. CUDA_VISIBLE_DEVICES and "2" ("": none)
};

/// How snell creates its own context.
struct ContextDesc {
  std::string applicationName = "snell";
  /// Turn on VK_LAYER_KHRONOS_validation; creation fails if the layer is missing.
  bool validation = false;
  /// With validation: also check synchronization (missing barriers, hazards).
  bool synchronizationValidation = false;
  /// An index, a UUID or a name substring; empty: what `environment` says.
  std::string deviceOverride;
  /// The process environment's say on the device (io::deviceEnvironment reads it; vk reads none).
  DeviceEnvironment environment;
  /// Ask the driver for per-pipeline statistics where it offers them.
  bool pipelineStatistics = false;
  /// Only pipelines are made (`snell bench pipelines`): nothing is submitted,
  /// no pipeline comes from or goes to the disk cache, and a device without
  /// device-local memory, such as RADV's null device, qualifies.
  bool compileOnly = false;
  /// Extra extensions a window needs (a surface on the instance, the swapchain
  /// on the device); creation fails naming any the system lacks.
  std::vector<std::string> instanceExtensions, deviceExtensions;
  /// Device extensions enabled only where the device offers them (Context::enabled says).
  std::vector<std::string> optionalDeviceExtensions;
  /// Turn on the driver's own acceleration structures (VK_KHR_acceleration_structure
  /// and buffer device addresses) where the device offers them, for the
  /// benchmarks' peer; DeviceCaps::driverAccelerationStructures says whether it is on.
  bool driverAccelerationStructures = false;
  /// With driverAccelerationStructures: the driver's ray tracing pipelines too
  /// (VK_KHR_ray_tracing_pipeline), for the driver-rt method; DeviceCaps::driverRayTracing.
  bool driverRayTracing = false;
  /// Bounds-checked buffer access, a debugging aid (the tests and SNELL_VALIDATION=1
  /// turn it on): robustBufferAccess2 (VK_EXT_robustness2) where offered, else
  /// robustBufferAccess. A shader's write past a buffer's end is then dropped, so
  /// it shows as wrong pixels in a test instead of damaging whatever memory lies
  /// beyond (on a CPU driver, the process's heap). DeviceCaps::robustAccess says which.
  bool robustBufferAccess = false;
};

/// Handles a host application created (snell::HostDevice, whose rules hold);
/// snell uses them and never destroys them. `enabled13` states what the host
/// enabled so snell can check it.
struct AdoptedDevice : snell::HostDevice {
  /// Whether the host enabled fillModeNonSolid (snell's wireframes need it).
  bool fillModeNonSolid = false;
};

/// Limits and properties the passes size themselves by.
struct DeviceCaps {
  uint32_t minSubgroupSize = 0;
  uint32_t maxSubgroupSize = 0;
  uint32_t maxComputeSharedMemoryBytes = 0;
  uint32_t maxComputeWorkgroupInvocations = 0;
  uint32_t maxComputeWorkgroupCount[3] = {0, 0, 0};
  uint64_t maxStorageBufferRange = 0;
  uint64_t maxMemoryAllocationSize = 0;
  uint32_t maxPushConstantsSize = 0;
  float timestampPeriodNs = 0;  ///< nanoseconds per timestamp tick
  uint32_t timestampValidBits = 0;  ///< 0: the queue cannot time passes
  /// Pipelines capture the driver's statistics (ComputeProgram::statistics).
  bool pipelineStatistics = false;
  /// Graphics through vkCmdBeginRendering (the raster pass needs it).
  bool dynamicRendering = false;
  /// Wireframes (VK_POLYGON_MODE_LINE).
  bool fillModeNonSolid = false;
  /// VK_KHR_acceleration_structure is enabled (ContextDesc::driverAccelerationStructures asked for it).
  bool driverAccelerationStructures = false;
  /// VK_KHR_ray_tracing_pipeline is enabled (ContextDesc::driverRayTracing asked for it).
  bool driverRayTracing = false;
  /// Buffers may ask for device addresses (bufferDeviceAddress is enabled).
  bool bufferDeviceAddress = false;
  /// The bounds checks ContextDesc::robustBufferAccess enabled: "robustBufferAccess2",
  /// "robustBufferAccess", or "" (none asked for or none offered).
  std::string robustAccess;
};

/// Every devices' facts and the verdict on each, without creating a device.
struct DeviceReport {
  std::vector<DeviceFacts> devices;
  DeviceChoice choice;
  std::string override;
  /// How the override was found ("SNELL_DEVICE=1", "CUDA_VISIBLE_DEVICES=2: ...").
  std::string why;
  /// A table with one row per device and its verdict.
  std::string table() const;
};

/// Surveys the Vulkan devices as Context::create would choose among them.
DeviceReport surveyDevices(const std::string& deviceOverride, const DeviceEnvironment& environment);

/// The devices of a --devices list (chooseDeviceList), a worker each; "all"
/// within a launcher's GPUs (`environment`) is every GPU it lists. `why`
/// says how they were found; throws std::invalid_argument naming a bad entry
/// (VulkanError where the launcher's own list names no device).
std::vector<uint32_t> devicesForList(const std::string& list, const DeviceEnvironment& environment, std::string& why);

/// Owns (or borrows) the Vulkan device everything else runs on, counts
/// validation messages, and defers destruction of handles the GPU may still use.
class Context {
 public:
  /// Creates an instance and device; throws VulkanError listing every device
  /// and why it was rejected when none qualifies.
  static std::unique_ptr<Context> create(const ContextDesc& desc = {});
  /// Wraps a host application's device; throws if it misses a requirement.
  static std::unique_ptr<Context> adopt(const AdoptedDevice& host);

  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_; }
  VkPhysicalDevice physicalDevice() const { return physicalDevice_; }
  VkDevice device() const { return device_; }
  VkQueue queue() const { return queue_; }
  uint32_t queueFamily() const { return queueFamily_; }
  const DeviceFacts& facts() const { return facts_; }
  /// Why this device: "SNELL_DEVICE=1", "CUDA_VISIBLE_DEVICES=2: GPU 2 in PCI bus order is ...".
  const std::string& deviceWhy() const { return deviceWhy_; }
  const DeviceCaps& caps() const { return caps_; }
  bool ownsDevice() const { return owned_; }
  /// Made with ContextDesc::compileOnly: submitting work is a logic error.
  bool compileOnly() const { return compileOnly_; }
  /// Whether an optional device extension (ContextDesc::optionalDeviceExtensions) was enabled.
  bool enabled(const std::string& extension) const {
    return std::find(optionalEnabled_.begin(), optionalEnabled_.end(), extension) != optionalEnabled_.end();
  }

  /// Validation warnings and errors seen so far (0 when validation is off).
  uint64_t validationMessageCount() const { return validationMessages_.load(); }
  /// Whether VK_LAYER_KHRONOS_validation is active on this context.
  bool validationEnabled() const { return validation_; }

  /// Gives a Vulkan object a name that validation messages and tools show;
  /// does nothing when VK_EXT_debug_utils is unavailable.
  void setName(VkObjectType type, uint64_t handle, const std::string& name) const;
  template <typename Handle>
  void setName(VkObjectType type, Handle handle, const std::string& name) const {
    setName(type, reinterpret_cast<uint64_t>(handle), name);
  }

  /// Runs `destroy` once every submission made so far has completed.
  void retire(std::function<void()> destroy);
  /// Submission bookkeeping for Commands: a serial per queue submission.
  uint64_t noteSubmitted();
  void noteCompleted(uint64_t serial);
  /// Destroys what no in-flight submission can use any more.
  void collectRetired();

  /// Memory type for `typeBits` with `required` flags, preferring `preferred`;
  /// UINT32_MAX when none has them.
  uint32_t findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) const;

  /// A device-level entry point of an enabled extension; throws VulkanError
  /// naming it where the driver has none.
  template <typename Function>
  Function deviceFunction(const char* name) const {
    auto f = reinterpret_cast<Function>(vkGetDeviceProcAddr(device_, name));
    if (!f) throw VulkanError(std::string(name) + " is missing: its extension is not enabled on " + facts_.name);
    return f;
  }

  /// vkAllocateMemory with snell's accounting: memory in the device-local heaps
  /// counts against memoryLimit(), and an allocation past it, or one the driver
  /// refuses, throws VulkanError naming `what` with the numbers.
  VkDeviceMemory allocateMemory(const VkMemoryAllocateInfo& info, const std::string& what);
  /// vkFreeMemory, and the accounting.
  void freeMemory(VkDeviceMemory memory);
  /// Device-local memory snell holds now, at most so far, and may hold: the
  /// device-local heaps' size, or SNELL_DEVICE_MEMORY_LIMIT (bytes) where smaller.
  uint64_t memoryInUse() const { return memoryInUse_.load(); }
  uint64_t memoryPeak() const { return memoryPeak_.load(); }
  uint64_t memoryLimit() const { return memoryLimit_; }
  uint64_t memoryAvailable() const { return memoryLimit_ > memoryInUse() ? memoryLimit_ - memoryInUse() : 0; }
  /// Refuses work needing `bytes` more device memory than is available, before
  /// anything is allocated: throws VulkanError (VK_ERROR_OUT_OF_DEVICE_MEMORY)
  /// naming `what` with the bytes needed and available.
  void checkFits(uint64_t bytes, const std::string& what) const;

  /// How long a submission may run before waiting on it reports the device
  /// as hung: 60 s on a GPU, 600 s on a CPU device (lavapipe, SwiftShader),
  /// or SNELL_GPU_TIMEOUT (seconds); and which of these it is, in words
  /// (with how to set another).
  double waitTimeoutSeconds() const { return waitTimeoutSeconds_; }
  const std::string& waitTimeoutWhy() const { return waitTimeoutWhy_; }

  /// The pipeline cache every pipeline is made through, kept on disk between processes.
  VkPipelineCache pipelineCache() const { return pipelineCache_ ? pipelineCache_->handle() : VK_NULL_HANDLE; }
  const PipelineCache* diskCache() const { return pipelineCache_.get(); }
  /// Pipeline creation time, summed over every program made on this context
  /// (on several threads, the sum of their times).
  void noteCompile(double seconds) { compileMicroseconds_.fetch_add(uint64_t(seconds * 1e6)); }
  double compileSeconds() const { return double(compileMicroseconds_.load()) * 1e-6; }
  uint64_t pipelinesCreated() const { return pipelinesCreated_.load(); }
  /// Runs `create` (a vkCreate*Pipelines call through pipelineCache()) and counts its time.
  template <typename Create>
  VkResult compile(Create&& create) {
    auto started = std::chrono::steady_clock::now();
    VkResult result = create();
    noteCompile(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count());
    pipelinesCreated_.fetch_add(1);
    return result;
  }
  /// The same on the context's compile threads: programs compile side by
  /// side, and a program's first use waits for its own pipeline only.
  /// `create` fills in the pipeline; a failure throws at get().
  /// SNELL_LOG_PIPELINES=1 prints each pipeline's name and compile time.
  std::shared_future<VkPipeline> compileAsync(std::string name, std::function<VkResult(VkPipeline*)> create);

 private:
  Context() = default;
  void initialise(VkPhysicalDevice physicalDevice, const DeviceFacts& facts, bool dynamicRendering,
                  bool fillModeNonSolid);
  static VkBool32 VKAPI_PTR onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                           VkDebugUtilsMessageTypeFlagsEXT types,
                                           const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queueFamily_ = 0;
  std::vector<std::string> optionalEnabled_;
  bool owned_ = false;
  bool compileOnly_ = false;
  bool validation_ = false;
  bool pipelineStatisticsRequested_ = false;
  DeviceFacts facts_;
  std::string deviceWhy_;
  DeviceCaps caps_;
  VkPhysicalDeviceMemoryProperties memory_{};
  PFN_vkSetDebugUtilsObjectNameEXT setObjectName_ = nullptr;
  std::atomic<uint64_t> validationMessages_{0};

  uint64_t submitted_ = 0;
  std::set<uint64_t> inFlight_;
  struct Retired {
    uint64_t serial;
    std::function<void()> destroy;
  };
  std::vector<Retired> retired_;

  uint64_t memoryLimit_ = 0;
  double waitTimeoutSeconds_ = 60.0;
  std::string waitTimeoutWhy_;
  std::atomic<uint64_t> memoryInUse_{0}, memoryPeak_{0};
  std::mutex memoryMutex_;
  std::unordered_map<VkDeviceMemory, uint64_t> counted_;  ///< device-local allocations and their sizes

  std::unique_ptr<PipelineCache> pipelineCache_;
  // A few long-lived compile threads, not one per pipeline: each new thread
  // gave the allocator a new arena, and a viewer switching scenes a thousand
  // frames long grew by 200 MiB.
  void compileWorker();
  std::mutex compileMutex_;
  std::condition_variable compileReady_;
  std::deque<std::packaged_task<VkPipeline()>> compileQueue_;
  std::vector<std::thread> compilers_;
  bool stopCompilers_ = false;
  std::atomic<uint64_t> compileMicroseconds_{0}, pipelinesCreated_{0};
};

}  // namespace snell::vk
