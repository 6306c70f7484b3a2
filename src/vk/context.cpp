// Instance and device creation, adoption of a host's device, the validation
// messenger and deferred destruction.
#include "vk/context.h"

#include "vk/error.h"

#include <cerrno>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iomanip>
#include <sstream>

namespace snell::vk {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

bool hasLayer(const char* name) {
  uint32_t count = 0;
  VK_CHECK(vkEnumerateInstanceLayerProperties(&count, nullptr));
  std::vector<VkLayerProperties> layers(count);
  VK_CHECK(vkEnumerateInstanceLayerProperties(&count, layers.data()));
  return std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

bool hasInstanceExtension(const char* name) {
  uint32_t count = 0;
  VK_CHECK(vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr));
  std::vector<VkExtensionProperties> extensions(count);
  VK_CHECK(vkEnumerateInstanceExtensionProperties(nullptr, &count, extensions.data()));
  return std::any_of(extensions.begin(), extensions.end(),
                     [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

// The device override and where it came from: the caller's (--device),
// SNELL_DEVICE, then a launcher's GPU list. Slurm and CUDA launchers set
// CUDA_VISIBLE_DEVICES, GPU_DEVICE_ORDINAL and SLURM_STEP_GPUS, which no Vulkan driver reads:
// without them every task of a node would pile onto its first GPU.
std::string resolveOverride(const std::string& given, const DeviceEnvironment& environment,
                            std::span<const DeviceFacts> facts, std::string& why) {
  if (!given.empty()) {
    why = "device=" + given;
    return given;
  }
  if (!environment.device.empty()) {
    why = "SNELL_DEVICE=" + environment.device;
    return environment.device;
  }
  if (!environment.launcherVariable.empty()) {
    return launcherOverride(facts, environment.launcherVariable, environment.launcherValue, why);
  }
  why = "none named: the best in rank, discrete, integrated, virtual GPU, then CPU";
  return "";
}

struct InstanceRequest {
  std::string applicationName = "snell";
  bool validation = false;
  bool synchronizationValidation = false;
  std::vector<std::string> extensions;
};

VkInstance createInstance(const InstanceRequest& request, bool& debugUtils) {
  uint32_t loaderVersion = VK_API_VERSION_1_0;
  VK_CHECK(vkEnumerateInstanceVersion(&loaderVersion));
  if (loaderVersion < VK_API_VERSION_1_3) {
    throw VulkanError("the Vulkan loader supports " + versionString(loaderVersion) +
                      "; snell needs 1.3 (Debian 12: apt-get install libvulkan1)");
  }
  std::vector<const char*> layers;
  if (request.validation) {
    if (!hasLayer(kValidationLayer)) {
      throw VulkanError(std::string("validation was requested but ") + kValidationLayer +
                        " is not installed (Debian 12: apt-get install vulkan-validationlayers)");
    }
    layers.push_back(kValidationLayer);
  }
  std::vector<const char*> extensions;
  debugUtils = hasInstanceExtension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  if (debugUtils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  for (const std::string& e : request.extensions) {
    if (!hasInstanceExtension(e.c_str())) throw VulkanError("the Vulkan instance lacks the extension " + e);
    extensions.push_back(e.c_str());
  }

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = request.applicationName.c_str();
  app.pEngineName = "snell";
  app.apiVersion = VK_API_VERSION_1_3;

  VkValidationFeatureEnableEXT syncFeature = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = &syncFeature;

  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pNext = (request.validation && request.synchronizationValidation) ? &features : nullptr;
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  VK_CHECK(vkCreateInstance(&info, nullptr, &instance));
  return instance;
}

std::vector<DeviceFacts> readAllFacts(VkInstance instance, std::vector<VkPhysicalDevice>& handles) {
  uint32_t count = 0;
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  handles.resize(count);
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, handles.data()));
  std::vector<DeviceFacts> facts;
  for (uint32_t i = 0; i < count; ++i) facts.push_back(readDeviceFacts(handles[i], i));
  return facts;
}

// The devices' facts from an instance of their own, for a survey.
std::vector<DeviceFacts> readFactsOnce() {
  bool debugUtils = false;
  VkInstance instance = createInstance({}, debugUtils);
  std::vector<DeviceFacts> facts;
  try {
    std::vector<VkPhysicalDevice> handles;
    facts = readAllFacts(instance, handles);
  } catch (...) {
    vkDestroyInstance(instance, nullptr);
    throw;
  }
  vkDestroyInstance(instance, nullptr);
  return facts;
}

std::string mebibytes(uint64_t bytes) {
  std::ostringstream text;
  text << (bytes >> 20) << " MiB";
  return text.str();
}

}  // namespace

std::string DeviceReport::table() const {
  std::ostringstream out;
  if (devices.empty()) {
    out << "no Vulkan device found (Debian 12: apt-get install mesa-vulkan-drivers for lavapipe)\n";
    return out.str();
  }
  for (size_t i = 0; i < devices.size(); ++i) {
    const DeviceFacts& d = devices[i];
    bool chosen = choice.chosen && *choice.chosen == i;
    out << (chosen ? "* " : "  ") << "[" << d.index << "] " << d.name << "\n"
        << "      type " << deviceTypeName(d.type) << ", Vulkan " << versionString(d.apiVersion) << ", driver "
        << (d.driverName.empty() ? "?" : d.driverName) << " " << d.driverInfo << "\n"
        << "      subgroup " << d.subgroupSize << " lanes (" << d.minSubgroupSize << "-" << d.maxSubgroupSize
        << " in compute), device-local memory " << mebibytes(d.deviceLocalBytes) << "\n"
        << "      UUID " << d.uuid << ", PCI bus " << (d.pciBus.empty() ? "unknown" : d.pciBus) << "\n"
        << "      " << choice.verdicts[i] << "\n";
  }
  return out.str();
}

DeviceReport surveyDevices(const std::string& deviceOverride, const DeviceEnvironment& environment) {
  DeviceReport report;
  report.devices = readFactsOnce();
  report.override = resolveOverride(deviceOverride, environment, report.devices, report.why);
  report.choice = chooseDevice(report.devices, report.override, report.why);
  return report;
}

std::vector<uint32_t> devicesForList(const std::string& list, const DeviceEnvironment& environment, std::string& why) {
  std::vector<DeviceFacts> facts = readFactsOnce();
  if (list == "all" && !environment.launcherVariable.empty()) {
    why = environment.launcherVariable + "=" + environment.launcherValue + ": every GPU the launcher gave";
    return launcherDevices(facts, environment.launcherVariable, environment.launcherValue);
  }
  why = list == "all" ? "--devices all: every device of the best kind that qualifies" : "--devices " + list;
  return chooseDeviceList(facts, list);
}

std::unique_ptr<Context> Context::create(const ContextDesc& desc) {
  std::unique_ptr<Context> context(new Context());
  Context& c = *context;
  c.owned_ = true;
  bool debugUtils = false;
  c.instance_ = createInstance(
      {desc.applicationName, desc.validation, desc.synchronizationValidation, desc.instanceExtensions}, debugUtils);
  c.validation_ = desc.validation;
  c.compileOnly_ = desc.compileOnly;
  c.pipelineStatisticsRequested_ = desc.pipelineStatistics;

  if (debugUtils) {
    auto createMessenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(c.instance_, "vkCreateDebugUtilsMessengerEXT"));
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
    info.pfnUserCallback = &Context::onDebugMessage;
    info.pUserData = &c;
    if (createMessenger) VK_CHECK(createMessenger(c.instance_, &info, nullptr, &c.messenger_));
    // SNELL_FAULT=validation-message: one message through the layer's own
    // channel, so tests see each command fail the way a real one would make it.
    const char* fault = std::getenv("SNELL_FAULT");
    auto submit = reinterpret_cast<PFN_vkSubmitDebugUtilsMessageEXT>(
        vkGetInstanceProcAddr(c.instance_, "vkSubmitDebugUtilsMessageEXT"));
    if (c.messenger_ && submit && fault && std::string(fault) == kFaultValidationMessage) {
      VkDebugUtilsMessengerCallbackDataEXT message{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CALLBACK_DATA_EXT};
      message.pMessageIdName = "snell-fault";
      message.pMessage = "SNELL_FAULT=validation-message: a validation message injected for a test";
      submit(c.instance_, VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT, VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT,
             &message);
    }
  }

  std::vector<VkPhysicalDevice> handles;
  std::vector<DeviceFacts> facts = readAllFacts(c.instance_, handles);
  std::string why;
  std::string override = resolveOverride(desc.deviceOverride, desc.environment, facts, why);
  DeviceChoice choice = chooseDevice(facts, override, why, desc.compileOnly ? DeviceUse::Compile : DeviceUse::Run);
  if (!choice.chosen) {
    DeviceReport report{facts, choice, override, why};
    throw VulkanError("no Vulkan device meets snell's requirements (" + why + "):\n" + report.table());
  }
  c.deviceWhy_ = why;
  const DeviceFacts& chosen = facts[*choice.chosen];
  VkPhysicalDevice physical = handles[*choice.chosen];

  float priority = 1.0f;
  VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queueInfo.queueFamilyIndex = chosen.computeQueueFamily;
  queueInfo.queueCount = 1;
  queueInfo.pQueuePriorities = &priority;

  VkPhysicalDeviceVulkan13Features features13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  features13.subgroupSizeControl = VK_TRUE;
  features13.computeFullSubgroups = VK_TRUE;
  features13.maintenance4 = VK_TRUE;
  // The raster pass: offered by every Vulkan 1.3 device, and enabled when it is.
  VkPhysicalDeviceVulkan13Features supported13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceFeatures2 supported{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &supported13};
  vkGetPhysicalDeviceFeatures2(physical, &supported);
  features13.dynamicRendering = supported13.dynamicRendering;
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &features13};
  features.features.fillModeNonSolid = supported.features.fillModeNonSolid;

  std::vector<const char*> extensions;
  const std::set<std::string> available = deviceExtensions(physical);
  auto has = [&](const std::string& name) { return available.count(name) > 0; };
  for (const std::string& e : desc.deviceExtensions) {
    if (!has(e)) throw VulkanError(chosen.name + " lacks the device extension " + e);
    extensions.push_back(e.c_str());
  }
  for (const std::string& e : desc.optionalDeviceExtensions) {
    if (has(e)) extensions.push_back(e.c_str()), c.optionalEnabled_.push_back(e);
  }
  VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR executableInfo{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
  if (desc.pipelineStatistics && chosen.pipelineStatistics) {
    extensions.push_back(VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
    executableInfo.pipelineExecutableInfo = VK_TRUE;
    executableInfo.pNext = features13.pNext;
    features13.pNext = &executableInfo;
  }
  // The driver's acceleration structures, for the peer benchmarks, only where offered.
  VkPhysicalDeviceVulkan12Features features12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceAccelerationStructureFeaturesKHR accelerationFeatures{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR rayTracingFeatures{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
  bool driverAcceleration = false, driverRayTracing = false;
  if (desc.driverAccelerationStructures || desc.driverRayTracing) {
    VkPhysicalDeviceRayTracingPipelineFeaturesKHR supportedRayTracing{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
    VkPhysicalDeviceAccelerationStructureFeaturesKHR supportedAcceleration{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, &supportedRayTracing};
    VkPhysicalDeviceVulkan12Features supported12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES,
                                                 &supportedAcceleration};
    VkPhysicalDeviceFeatures2 probe{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &supported12};
    if (has(VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME) && has(VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME)) {
      vkGetPhysicalDeviceFeatures2(physical, &probe);
      driverAcceleration = supportedAcceleration.accelerationStructure && supported12.bufferDeviceAddress;
      driverRayTracing = desc.driverRayTracing && driverAcceleration &&
                         has(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME) && supportedRayTracing.rayTracingPipeline;
    }
    if (driverAcceleration) {
      extensions.push_back(VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME);
      extensions.push_back(VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME);
      features12.bufferDeviceAddress = VK_TRUE;
      accelerationFeatures.accelerationStructure = VK_TRUE;
      features12.pNext = &accelerationFeatures;
      accelerationFeatures.pNext = features13.pNext;
      features13.pNext = &features12;
    }
    if (driverRayTracing) {
      extensions.push_back(VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME);
      rayTracingFeatures.rayTracingPipeline = VK_TRUE;
      rayTracingFeatures.pNext = accelerationFeatures.pNext;
      accelerationFeatures.pNext = &rayTracingFeatures;
    }
  }

  // Bounds checks, for the tests: robustness2 drops a write past the bound
  // range (robustBufferAccess alone may land it anywhere inside the buffer).
  VkPhysicalDeviceRobustness2FeaturesEXT robustness2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ROBUSTNESS_2_FEATURES_EXT};
  std::string robustAccess;
  if (desc.robustBufferAccess) {
    VkPhysicalDeviceRobustness2FeaturesEXT offered2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ROBUSTNESS_2_FEATURES_EXT};
    VkPhysicalDeviceFeatures2 probe{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &offered2};
    if (has(VK_EXT_ROBUSTNESS_2_EXTENSION_NAME)) vkGetPhysicalDeviceFeatures2(physical, &probe);
    if (supported.features.robustBufferAccess) {
      features.features.robustBufferAccess = VK_TRUE;  // robustBufferAccess2 requires it
      robustAccess = "robustBufferAccess";
      if (offered2.robustBufferAccess2) {
        extensions.push_back(VK_EXT_ROBUSTNESS_2_EXTENSION_NAME);
        robustness2.robustBufferAccess2 = VK_TRUE;
        robustness2.pNext = features13.pNext;
        features13.pNext = &robustness2;
        robustAccess = "robustBufferAccess2";
      }
    }
  }

  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.pNext = &features;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queueInfo;
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  VK_CHECK(vkCreateDevice(physical, &info, nullptr, &c.device_));
  c.queueFamily_ = chosen.computeQueueFamily;
  vkGetDeviceQueue(c.device_, c.queueFamily_, 0, &c.queue_);
  if (debugUtils) {
    c.setObjectName_ = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
        vkGetInstanceProcAddr(c.instance_, "vkSetDebugUtilsObjectNameEXT"));
  }
  c.initialise(physical, chosen, features13.dynamicRendering, features.features.fillModeNonSolid);
  c.caps_.driverAccelerationStructures = driverAcceleration;
  c.caps_.driverRayTracing = driverRayTracing;
  c.caps_.bufferDeviceAddress = driverAcceleration;
  c.caps_.robustAccess = robustAccess;
  return context;
}

std::unique_ptr<Context> Context::adopt(const AdoptedDevice& host) {
  if (!host.instance || !host.physicalDevice || !host.device || !host.queue) {
    throw VulkanError("adopting a host device needs its VkInstance, VkPhysicalDevice, VkDevice and VkQueue; one is null");
  }
  DeviceFacts facts = readDeviceFacts(host.physicalDevice, 0);
  if (!host.enabled13.subgroupSizeControl) facts.unmet.push_back("the host did not enable subgroupSizeControl");
  if (!host.enabled13.computeFullSubgroups) facts.unmet.push_back("the host did not enable computeFullSubgroups");
  if (!host.enabled13.maintenance4) facts.unmet.push_back("the host did not enable maintenance4");
  uint32_t familyCount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(host.physicalDevice, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  vkGetPhysicalDeviceQueueFamilyProperties(host.physicalDevice, &familyCount, families.data());
  if (host.queueFamily >= familyCount || !(families[host.queueFamily].queueFlags & VK_QUEUE_COMPUTE_BIT)) {
    facts.unmet.push_back("queue family " + std::to_string(host.queueFamily) + " does not support compute");
  }
  if (!facts.unmet.empty()) {
    std::string reasons;
    for (const std::string& u : facts.unmet) reasons += "\n  - " + u;
    throw VulkanError("cannot adopt the host's device " + facts.name + ":" + reasons);
  }
  std::unique_ptr<Context> context(new Context());
  Context& c = *context;
  c.owned_ = false;
  c.instance_ = host.instance;
  c.device_ = host.device;
  c.queue_ = host.queue;
  c.queueFamily_ = host.queueFamily;
  facts.computeQueueFamily = host.queueFamily;
  facts.pipelineStatistics = false;  // we cannot know whether the host enabled the extension
  // Present only if the host enabled VK_EXT_debug_utils; otherwise names are skipped.
  c.setObjectName_ = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
      vkGetInstanceProcAddr(host.instance, "vkSetDebugUtilsObjectNameEXT"));
  c.initialise(host.physicalDevice, facts, host.enabled13.dynamicRendering, host.fillModeNonSolid);
  return context;
}

void Context::initialise(VkPhysicalDevice physicalDevice, const DeviceFacts& facts, bool dynamicRendering,
                         bool fillModeNonSolid) {
  physicalDevice_ = physicalDevice;
  facts_ = facts;
  caps_.dynamicRendering = dynamicRendering;
  caps_.fillModeNonSolid = fillModeNonSolid;
  VkPhysicalDeviceProperties props{};
  vkGetPhysicalDeviceProperties(physicalDevice, &props);
  VkPhysicalDeviceMaintenance3Properties maintenance3{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES};
  VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &maintenance3};
  vkGetPhysicalDeviceProperties2(physicalDevice, &props2);
  const VkPhysicalDeviceLimits& limits = props.limits;
  caps_.minSubgroupSize = facts.minSubgroupSize;
  caps_.maxSubgroupSize = facts.maxSubgroupSize;
  caps_.maxComputeSharedMemoryBytes = limits.maxComputeSharedMemorySize;
  caps_.maxComputeWorkgroupInvocations = limits.maxComputeWorkGroupInvocations;
  for (int i = 0; i < 3; ++i) caps_.maxComputeWorkgroupCount[i] = limits.maxComputeWorkGroupCount[i];
  caps_.maxStorageBufferRange = limits.maxStorageBufferRange;
  caps_.maxMemoryAllocationSize = maintenance3.maxMemoryAllocationSize;
  caps_.maxPushConstantsSize = limits.maxPushConstantsSize;
  caps_.timestampPeriodNs = limits.timestampPeriod;
  caps_.pipelineStatistics = owned_ && facts.pipelineStatistics && pipelineStatisticsRequested_;

  uint32_t familyCount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  vkGetPhysicalDeviceQueueFamilyProperties(physicalDevice, &familyCount, families.data());
  caps_.timestampValidBits = families[queueFamily_].timestampValidBits;

  vkGetPhysicalDeviceMemoryProperties(physicalDevice, &memory_);
  for (uint32_t h = 0; h < memory_.memoryHeapCount; ++h) {
    if (memory_.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) memoryLimit_ += memory_.memoryHeaps[h].size;
  }
  if (const char* limit = std::getenv("SNELL_DEVICE_MEMORY_LIMIT"); limit && *limit) {
    char* end = nullptr;
    errno = 0;
    unsigned long long bytes = std::strtoull(limit, &end, 10);
    if (*end != '\0' || errno || bytes == 0 || limit[0] == '-') {
      throw VulkanError(std::string("SNELL_DEVICE_MEMORY_LIMIT=") + limit + ": expected a number of bytes above 0");
    }
    memoryLimit_ = std::min<uint64_t>(memoryLimit_ ? memoryLimit_ : bytes, bytes);
  }
  // A CPU driver runs a frame on the host's cores, beside whatever else they
  // run: a busy 2-core machine took 66 s over one frame of a million aimed
  // rays that a GPU traces in milliseconds. It is not hung, so it waits longer.
  waitTimeoutSeconds_ = facts.type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 600.0 : 60.0;
  waitTimeoutWhy_ = std::string(facts.type == VK_PHYSICAL_DEVICE_TYPE_CPU ? "a CPU device's limit" : "a GPU's limit") +
                    "; SNELL_GPU_TIMEOUT=SECONDS sets another";
  if (const char* limit = std::getenv("SNELL_GPU_TIMEOUT"); limit && *limit) {
    char* end = nullptr;
    double seconds = std::strtod(limit, &end);
    if (*end != '\0' || !(seconds > 0.0) || !(seconds <= 1e6)) {
      throw VulkanError(std::string("SNELL_GPU_TIMEOUT=") + limit + ": expected seconds, above 0 and at most 1000000");
    }
    waitTimeoutSeconds_ = seconds;
    waitTimeoutWhy_ = std::string("SNELL_GPU_TIMEOUT=") + limit;
  }
  setName(VK_OBJECT_TYPE_DEVICE, device_, "snell device");
  setName(VK_OBJECT_TYPE_QUEUE, queue_, "snell queue");
  // A compile-only context measures the compiler: every pipeline is compiled
  // afresh (a null device's UUID is all zeros, too, whatever it stands for).
  if (compileOnly_) return;
  pipelineCache_ = std::make_unique<PipelineCache>(device_, physicalDevice);
  if (!pipelineCache_->warning().empty()) std::fprintf(stderr, "snell: note: %s\n", pipelineCache_->warning().c_str());
}

Context::~Context() {
  {
    std::lock_guard lock(compileMutex_);
    stopCompilers_ = true;
  }
  compileReady_.notify_all();
  for (std::thread& t : compilers_) t.join();  // programs waited for their own compiles; any left finish here
  // The host's device too: our handles die with us. Not where nothing was
  // submitted: a null device (compile only) has no queue to wait on.
  if (device_ && submitted_) vkDeviceWaitIdle(device_);
  for (Retired& r : retired_) r.destroy();
  retired_.clear();
  if (pipelineCache_) {
    if (std::string failed = pipelineCache_->save(); !failed.empty()) std::fprintf(stderr, "snell: note: %s\n", failed.c_str());
    pipelineCache_.reset();
  }
  if (!owned_) return;
  if (device_) vkDestroyDevice(device_, nullptr);
  if (messenger_) {
    auto destroyMessenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroyMessenger) destroyMessenger(instance_, messenger_, nullptr);
  }
  if (instance_) vkDestroyInstance(instance_, nullptr);
}

std::shared_future<VkPipeline> Context::compileAsync(std::string name, std::function<VkResult(VkPipeline*)> create) {
  static const bool log = [] {
    const char* v = std::getenv("SNELL_LOG_PIPELINES");
    return v && std::string(v) == "1";
  }();
  std::packaged_task<VkPipeline()> task([this, name = std::move(name), create = std::move(create)] {
    VkPipeline pipeline = VK_NULL_HANDLE;
    auto started = std::chrono::steady_clock::now();
    VK_CHECK(compile([&] { return create(&pipeline); }));
    if (log) {
      double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
      std::fprintf(stderr, "snell: compiled pipeline '%s' in %.1f ms\n", name.c_str(), ms);
    }
    setName(VK_OBJECT_TYPE_PIPELINE, pipeline, name);
    return pipeline;
  });
  std::shared_future<VkPipeline> result = task.get_future().share();
  // A CPU device (lavapipe) compiles at a pipeline's first dispatch, not here:
  // threads would buy nothing but the allocator's arenas.
  if (facts_.type == VK_PHYSICAL_DEVICE_TYPE_CPU) {
    task();
    return result;
  }
  {
    std::lock_guard lock(compileMutex_);
    if (compilers_.empty()) {
      unsigned threads = std::clamp(std::thread::hardware_concurrency(), 1u, 8u);
      for (unsigned t = 0; t < threads; ++t) compilers_.emplace_back([this] { compileWorker(); });
    }
    compileQueue_.push_back(std::move(task));
  }
  compileReady_.notify_one();
  return result;
}

void Context::compileWorker() {
  for (;;) {
    std::packaged_task<VkPipeline()> task;
    {
      std::unique_lock lock(compileMutex_);
      compileReady_.wait(lock, [this] { return stopCompilers_ || !compileQueue_.empty(); });
      if (compileQueue_.empty()) return;  // stopping, with nothing left to compile
      task = std::move(compileQueue_.front());
      compileQueue_.pop_front();
    }
    task();  // a failure is kept in the task's future
  }
}

VkBool32 VKAPI_PTR Context::onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                           VkDebugUtilsMessageTypeFlagsEXT types,
                                           const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* context = static_cast<Context*>(user);
  // General messages come from the loader (a stray ICD file, say), not from our use of the API.
  if (types & (VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT)) {
    context->validationMessages_.fetch_add(1);
  }
  const char* level = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
  std::fprintf(stderr, "[vulkan %s] %s\n", level, data && data->pMessage ? data->pMessage : "(no message)");
  return VK_FALSE;
}

void Context::setName(VkObjectType type, uint64_t handle, const std::string& name) const {
  if (!setObjectName_ || handle == 0) return;
  VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  info.objectType = type;
  info.objectHandle = handle;
  info.pObjectName = name.c_str();
  VK_CHECK(setObjectName_(device_, &info));
}

void Context::retire(std::function<void()> destroy) {
  retired_.push_back({submitted_, std::move(destroy)});
  collectRetired();
}

uint64_t Context::noteSubmitted() {
  inFlight_.insert(++submitted_);
  return submitted_;
}

void Context::noteCompleted(uint64_t serial) {
  inFlight_.erase(serial);
  collectRetired();
}

void Context::collectRetired() {
  // Everything up to the oldest submission still in flight has finished.
  uint64_t safe = inFlight_.empty() ? submitted_ : *inFlight_.begin() - 1;
  auto done = std::stable_partition(retired_.begin(), retired_.end(), [&](const Retired& r) { return r.serial > safe; });
  std::vector<Retired> ready(std::make_move_iterator(done), std::make_move_iterator(retired_.end()));
  retired_.erase(done, retired_.end());
  for (Retired& r : ready) r.destroy();
}

namespace {

std::string mib(uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MiB", double(bytes) / 1048576.0);
  return text;
}

}  // namespace

void Context::checkFits(uint64_t bytes, const std::string& what) const {
  if (bytes <= memoryAvailable()) return;
  throw VulkanError(what + " needs " + mib(bytes) + " of device memory; " + mib(memoryAvailable()) + " of the " +
                        mib(memoryLimit_) + " limit is free (" + facts_.name +
                        (std::getenv("SNELL_DEVICE_MEMORY_LIMIT") ? ", SNELL_DEVICE_MEMORY_LIMIT" : "") + ")",
                    VK_ERROR_OUT_OF_DEVICE_MEMORY);
}

VkDeviceMemory Context::allocateMemory(const VkMemoryAllocateInfo& info, const std::string& what) {
  uint32_t heap = memory_.memoryTypes[info.memoryTypeIndex].heapIndex;
  bool counted = memory_.memoryHeaps[heap].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT;
  std::lock_guard lock(memoryMutex_);
  if (counted) checkFits(info.allocationSize, "'" + what + "'");
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkResult result = callUnlessFaulted("vkAllocateMemory", [&] { return vkAllocateMemory(device_, &info, nullptr, &memory); });
  if (result != VK_SUCCESS) {
    throw VulkanError("allocating " + mib(info.allocationSize) + " for '" + what + "' failed with " +
                          std::string(resultName(result)) + " (" + mib(memoryInUse()) + " in use, of " +
                          mib(memoryLimit_) + ")",
                      result);
  }
  if (counted) {
    counted_[memory] = info.allocationSize;
    uint64_t now = memoryInUse_.fetch_add(info.allocationSize) + info.allocationSize;
    if (now > memoryPeak_.load()) memoryPeak_.store(now);
  }
  return memory;
}

void Context::freeMemory(VkDeviceMemory memory) {
  if (!memory) return;
  vkFreeMemory(device_, memory, nullptr);
  std::lock_guard lock(memoryMutex_);
  if (auto it = counted_.find(memory); it != counted_.end()) {
    memoryInUse_.fetch_sub(it->second);
    counted_.erase(it);
  }
}

uint32_t Context::findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) const {
  uint32_t fallback = UINT32_MAX;
  for (uint32_t i = 0; i < memory_.memoryTypeCount; ++i) {
    if (!(typeBits & (1u << i))) continue;
    VkMemoryPropertyFlags flags = memory_.memoryTypes[i].propertyFlags;
    if ((flags & required) != required) continue;
    if ((flags & preferred) == preferred) return i;
    if (fallback == UINT32_MAX) fallback = i;
  }
  return fallback;
}

}  // namespace snell::vk
