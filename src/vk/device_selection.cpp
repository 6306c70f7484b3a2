// Device facts, requirements and ranking (see device_selection.h).
#include "vk/device_selection.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "vk/error.h"

namespace snell::vk {

namespace {

int typeRank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

bool isIndex(const std::string& text, uint32_t& index) {
  if (text.empty()) return false;
  auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), index);
  return error == std::errc() && end == text.data() + text.size();
}

// 8-4-4-4-12 hex digits, as nvidia-smi -L prints a UUID after "GPU-".
std::string uuidText(const uint8_t (&bytes)[VK_UUID_SIZE]) {
  static const char digits[] = "0123456789abcdef";
  std::string text;
  for (uint32_t i = 0; i < VK_UUID_SIZE; ++i) {
    if (i == 4 || i == 6 || i == 8 || i == 10) text += '-';
    text += {digits[bytes[i] >> 4], digits[bytes[i] & 15]};
  }
  return text;
}

// A UUID as a user or launcher writes it: "GPU-" prefix and case dropped.
std::string bareUuid(const std::string& text) {
  std::string t = lower(text);
  return t.rfind("gpu-", 0) == 0 ? t.substr(4) : t;
}

bool looksLikeUuid(const std::string& text) {
  std::string t = bareUuid(text);
  return t.size() >= 8 && std::count(t.begin(), t.end(), '-') >= 1 &&
         std::all_of(t.begin(), t.end(), [](char c) { return std::isxdigit(static_cast<unsigned char>(c)) || c == '-'; });
}

}  // namespace

const char* deviceTypeName(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "CPU";
    default: return "other";
  }
}

std::string versionString(uint32_t v) {
  std::ostringstream text;
  text << VK_API_VERSION_MAJOR(v) << "." << VK_API_VERSION_MINOR(v) << "." << VK_API_VERSION_PATCH(v);
  return text.str();
}

std::set<std::string> deviceExtensions(VkPhysicalDevice device) {
  uint32_t count = 0;
  VK_CHECK(vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr));
  std::vector<VkExtensionProperties> properties(count);
  VK_CHECK(vkEnumerateDeviceExtensionProperties(device, nullptr, &count, properties.data()));
  std::set<std::string> names;
  for (const VkExtensionProperties& p : properties) names.insert(p.extensionName);
  return names;
}

DeviceFacts readDeviceFacts(VkPhysicalDevice device, uint32_t index) {
  DeviceFacts facts;
  facts.index = index;
  VkPhysicalDeviceProperties basic{};
  vkGetPhysicalDeviceProperties(device, &basic);
  facts.name = basic.deviceName;
  facts.type = basic.deviceType;
  facts.apiVersion = basic.apiVersion;

  VkPhysicalDeviceMemoryProperties memory{};
  vkGetPhysicalDeviceMemoryProperties(device, &memory);
  for (uint32_t h = 0; h < memory.memoryHeapCount; ++h) {
    if (memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) facts.deviceLocalBytes += memory.memoryHeaps[h].size;
  }
  if (facts.deviceLocalBytes == 0) {
    facts.cannotRun = "it has no device-local memory (a null device, such as RADV_FORCE_FAMILY's, only compiles "
                      "pipelines: 'snell bench pipelines')";
  }

  uint32_t familyCount = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &familyCount, families.data());
  // Prefer a family that also draws: the raster pass shares the queue with compute.
  for (uint32_t f = 0; f < familyCount; ++f) {
    VkQueueFlags flags = families[f].queueFlags;
    if (!(flags & VK_QUEUE_COMPUTE_BIT)) continue;
    bool graphics = flags & VK_QUEUE_GRAPHICS_BIT;
    if (facts.computeQueueFamily == UINT32_MAX || graphics) facts.computeQueueFamily = f;
    if (graphics) break;
  }
  if (facts.computeQueueFamily == UINT32_MAX) facts.unmet.push_back("no queue family supports compute");

  if (basic.apiVersion < VK_API_VERSION_1_3) {
    facts.unmet.push_back("Vulkan " + versionString(basic.apiVersion) + " is below the required 1.3");
    return facts;  // the 1.2/1.3 property structs below may not be chained on it
  }

  const std::set<std::string> extensions = deviceExtensions(device);
  auto hasExtension = [&](const char* name) { return extensions.count(name) > 0; };

  VkPhysicalDevicePCIBusInfoPropertiesEXT pci{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PCI_BUS_INFO_PROPERTIES_EXT};
  bool hasPci = hasExtension(VK_EXT_PCI_BUS_INFO_EXTENSION_NAME);
  VkPhysicalDeviceVulkan13Properties props13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_PROPERTIES,
                                             hasPci ? &pci : nullptr};
  VkPhysicalDeviceVulkan12Properties props12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_PROPERTIES, &props13};
  VkPhysicalDeviceVulkan11Properties props11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_PROPERTIES, &props12};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &props11};
  vkGetPhysicalDeviceProperties2(device, &props);
  facts.vendorId = basic.vendorID;
  facts.uuid = uuidText(props11.deviceUUID);
  if (hasPci) {
    char bus[32];
    std::snprintf(bus, sizeof bus, "%04x:%02x:%02x.%x", pci.pciDomain, pci.pciBus, pci.pciDevice, pci.pciFunction);
    facts.pciBus = bus;
  }
  facts.driverId = props12.driverID;
  facts.driverName = props12.driverName;
  facts.driverInfo = props12.driverInfo;
  facts.subgroupSize = props11.subgroupSize;
  facts.minSubgroupSize = props13.minSubgroupSize;
  facts.maxSubgroupSize = props13.maxSubgroupSize;

  VkPhysicalDeviceVulkan13Features features13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &features13};
  vkGetPhysicalDeviceFeatures2(device, &features);

  if (!(props11.subgroupSupportedStages & VK_SHADER_STAGE_COMPUTE_BIT)) {
    facts.unmet.push_back("subgroup operations are not supported in compute shaders");
  }
  const VkSubgroupFeatureFlags needed = VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT |
                                        VK_SUBGROUP_FEATURE_ARITHMETIC_BIT | VK_SUBGROUP_FEATURE_SHUFFLE_BIT;
  if ((props11.subgroupSupportedOperations & needed) != needed) {
    facts.unmet.push_back("subgroup basic, ballot, arithmetic and shuffle operations are not all supported");
  }
  if (!features13.subgroupSizeControl) facts.unmet.push_back("feature subgroupSizeControl is missing");
  if (!features13.computeFullSubgroups) facts.unmet.push_back("feature computeFullSubgroups is missing");
  // glslang writes a specialised workgroup size as LocalSizeId, which needs maintenance4.
  if (!features13.maintenance4) facts.unmet.push_back("feature maintenance4 is missing");
  facts.pipelineStatistics = hasExtension(VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
  if (props13.maxSubgroupSize > 128) {
    facts.unmet.push_back("subgroups of " + std::to_string(props13.maxSubgroupSize) + " lanes exceed the 128 snell's ballots hold");
  }
  return facts;
}

bool qualifies(const DeviceFacts& d, DeviceUse use) {
  return d.unmet.empty() && (use == DeviceUse::Compile || d.cannotRun.empty());
}

std::vector<std::string> unmetFor(const DeviceFacts& d, DeviceUse use) {
  std::vector<std::string> unmet = d.unmet;
  if (use == DeviceUse::Run && !d.cannotRun.empty()) unmet.push_back(d.cannotRun);
  return unmet;
}

DeviceChoice chooseDevice(std::span<const DeviceFacts> devices, const std::string& override,
                          const std::string& source, DeviceUse use) {
  DeviceChoice choice;
  uint32_t overrideIndex = 0;
  bool byIndex = isIndex(override, overrideIndex);
  std::string needle = lower(override);

  bool byUuid = !byIndex && looksLikeUuid(override);
  auto named = [&](const DeviceFacts& d) {
    if (override.empty()) return true;
    if (byIndex) return d.index == overrideIndex;
    if (byUuid) return !d.uuid.empty() && d.uuid.rfind(bareUuid(override), 0) == 0;  // a unique prefix will do
    return lower(d.name).find(needle) != std::string::npos;
  };
  // Lower is better: device type first, then more device-local memory.
  auto rank = [](const DeviceFacts& d) { return std::make_pair(typeRank(d.type), ~d.deviceLocalBytes); };

  for (uint32_t i = 0; i < devices.size(); ++i) {
    const DeviceFacts& d = devices[i];
    if (!named(d) || !qualifies(d, use)) continue;
    if (!choice.chosen || rank(d) < rank(devices[*choice.chosen])) choice.chosen = i;
  }

  for (uint32_t i = 0; i < devices.size(); ++i) {
    const DeviceFacts& d = devices[i];
    std::string verdict;
    if (choice.chosen && i == *choice.chosen) {
      verdict = override.empty() ? "chosen: the highest-ranked device that meets every requirement"
                                 : "chosen: named by " + (source.empty() ? "SNELL_DEVICE=" + override : source);
    } else if (!qualifies(d, use)) {
      verdict = "rejected: ";
      std::vector<std::string> unmet = unmetFor(d, use);
      for (size_t u = 0; u < unmet.size(); ++u) verdict += (u ? "; " : "") + unmet[u];
    } else if (!named(d)) {
      verdict = "not chosen: " + (source.empty() ? "SNELL_DEVICE=" + override : source) + " names another device";
    } else {
      const DeviceFacts& best = devices[*choice.chosen];
      verdict = "not chosen: ranks below " + best.name + " (a " + deviceTypeName(best.type) +
                "; the order is discrete, integrated, virtual, CPU, then more device memory)";
    }
    choice.verdicts.push_back(verdict);
  }
  return choice;
}

namespace {

// One entry of a launcher's list: a UUID names itself, an index k is the k-th
// GPU (not CPU device) in PCI bus order, enumeration order where the bus is unknown.
const DeviceFacts& launcherEntry(std::span<const DeviceFacts> devices, const std::string& given,
                                 const std::string& entry) {
  if (entry.empty()) throw VulkanError(given + " has an empty entry");
  if (looksLikeUuid(entry)) {
    for (const DeviceFacts& d : devices) {
      if (!d.uuid.empty() && d.uuid.rfind(bareUuid(entry), 0) == 0) return d;
    }
    throw VulkanError(given + ": no Vulkan device has UUID " + entry + " ('snell info --devices' lists them)");
  }
  uint32_t k = 0;
  if (!isIndex(entry, k)) throw VulkanError(given + ": '" + entry + "' is neither a GPU index nor a UUID");
  std::vector<const DeviceFacts*> gpus;
  for (const DeviceFacts& d : devices) {
    if (d.type != VK_PHYSICAL_DEVICE_TYPE_CPU) gpus.push_back(&d);
  }
  std::stable_sort(gpus.begin(), gpus.end(), [](const DeviceFacts* a, const DeviceFacts* b) {
    if (a->pciBus.empty() || b->pciBus.empty()) return false;
    return a->pciBus < b->pciBus;
  });
  if (k >= gpus.size()) {
    throw VulkanError(given + " names GPU " + entry + ", but Vulkan sees " + std::to_string(gpus.size()) +
                      " GPU(s) ('snell info --devices' lists them)");
  }
  return *gpus[k];
}

std::vector<std::string> commaList(const std::string& text) {
  std::vector<std::string> entries;
  for (size_t start = 0;;) {
    size_t comma = text.find(',', start);
    entries.push_back(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
    if (comma == std::string::npos) return entries;
    start = comma + 1;
  }
}

}  // namespace

std::string launcherOverride(std::span<const DeviceFacts> devices, const std::string& variable,
                             const std::string& value, std::string& why) {
  std::string given = variable + "=" + value;
  std::string first = commaList(value).front();
  const DeviceFacts& d = launcherEntry(devices, given, first);
  why = looksLikeUuid(first) ? given + " names " + d.name + " by its UUID"
                             : given + ": GPU " + first + " in PCI bus order is " + d.name +
                                   (d.pciBus.empty() ? "" : " at " + d.pciBus);
  return std::to_string(d.index);
}

std::vector<uint32_t> launcherDevices(std::span<const DeviceFacts> devices, const std::string& variable,
                                      const std::string& value) {
  std::vector<uint32_t> chosen;
  for (const std::string& entry : commaList(value)) chosen.push_back(launcherEntry(devices, variable + "=" + value, entry).index);
  return chosen;
}

std::vector<uint32_t> chooseDeviceList(std::span<const DeviceFacts> devices, const std::string& list) {
  std::vector<uint32_t> chosen;
  if (list == "all") {
    DeviceChoice best = chooseDevice(devices, "");
    if (!best.chosen) throw VulkanError("--devices all: no Vulkan device meets snell's requirements ('snell info --devices' says why)");
    for (const DeviceFacts& d : devices) {
      if (qualifies(d) && d.type == devices[*best.chosen].type) chosen.push_back(d.index);
    }
    return chosen;
  }
  for (const std::string& entry : commaList(list)) {
    if (entry.empty()) throw std::invalid_argument("--devices " + list + ": an empty entry between commas");
    uint32_t index = 0;
    bool byIndex = isIndex(entry, index);
    if (!byIndex && !looksLikeUuid(entry)) {
      throw std::invalid_argument("--devices " + list + ": '" + entry + "' is neither a device index nor a UUID");
    }
    auto it = std::find_if(devices.begin(), devices.end(), [&](const DeviceFacts& d) {
      return byIndex ? d.index == index : !d.uuid.empty() && d.uuid.rfind(bareUuid(entry), 0) == 0;
    });
    if (it == devices.end()) {
      throw std::invalid_argument("--devices " + list + ": no device " + entry + " ('snell info --devices' lists " +
                        std::to_string(devices.size()) + ")");
    }
    if (!qualifies(*it)) {
      throw std::invalid_argument("--devices " + list + ": " + it->name + " does not qualify: " + unmetFor(*it).front());
    }
    chosen.push_back(it->index);
  }
  return chosen;
}

}  // namespace snell::vk
