// A Vulkan device made by hand, as a host application makes its own, for the
// tests of adoption and embedding. Its validation messages fail the test.
#pragma once

#include "vk/context.h"
#include "vk/error.h"

#include <gtest/gtest.h>
#include <vulkan/vulkan.h>

#include <vector>

namespace snell::test {

/// A device created by hand, as a host application would, with the Vulkan 1.3
/// features snell documents for adoption.
struct HandMadeDevice {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t family = 0;
  VkPhysicalDeviceVulkan13Features features13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  int validationMessages = 0;

  static VkBool32 VKAPI_PTR count(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT types,
                                  const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    if (types & VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT) {
      ++static_cast<HandMadeDevice*>(user)->validationMessages;
      ADD_FAILURE() << "validation on the host's device: " << data->pMessage;
    }
    return VK_FALSE;
  }

  /// `enableSnellFeatures`: the features snell documents (and dynamic
  /// rendering, which its viewport needs). `synchronization`: the layer checks
  /// synchronisation too.
  explicit HandMadeDevice(bool enableSnellFeatures, bool synchronization = false) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.apiVersion = VK_API_VERSION_1_3;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    info.pApplicationInfo = &app;
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = &layer;
    const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = &extension;
    VkValidationFeatureEnableEXT enables[] = {VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
    VkValidationFeaturesEXT validationFeatures{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
    validationFeatures.enabledValidationFeatureCount = 1;
    validationFeatures.pEnabledValidationFeatures = enables;
    if (synchronization) info.pNext = &validationFeatures;
    VK_CHECK(vkCreateInstance(&info, nullptr, &instance));
    VkDebugUtilsMessengerCreateInfoEXT messengerInfo{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    messengerInfo.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messengerInfo.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    messengerInfo.pfnUserCallback = &HandMadeDevice::count;
    messengerInfo.pUserData = this;
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    VK_CHECK(create(instance, &messengerInfo, nullptr, &messenger));
    uint32_t count = 1;
    VkResult result = vkEnumeratePhysicalDevices(instance, &count, &physical);
    if (result != VK_INCOMPLETE) VK_CHECK(result);
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, nullptr);
    std::vector<VkQueueFamilyProperties> props(families);
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, props.data());
    const VkQueueFlags needs = VK_QUEUE_COMPUTE_BIT | VK_QUEUE_GRAPHICS_BIT;
    while ((props[family].queueFlags & needs) != needs) ++family;
    float priority = 1;
    VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queueInfo.queueFamilyIndex = family;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;
    features13.subgroupSizeControl = enableSnellFeatures;
    features13.computeFullSubgroups = enableSnellFeatures;
    features13.maintenance4 = enableSnellFeatures;
    features13.dynamicRendering = enableSnellFeatures;
    VkDeviceCreateInfo deviceInfo{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    deviceInfo.pNext = &features13;
    deviceInfo.queueCreateInfoCount = 1;
    deviceInfo.pQueueCreateInfos = &queueInfo;
    VK_CHECK(vkCreateDevice(physical, &deviceInfo, nullptr, &device));
    vkGetDeviceQueue(device, family, 0, &queue);
  }
  ~HandMadeDevice() {
    vkDestroyDevice(device, nullptr);
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
    destroy(instance, messenger, nullptr);
    vkDestroyInstance(instance, nullptr);
  }
  vk::AdoptedDevice adopted() const {
    vk::AdoptedDevice a;
    a.instance = instance;
    a.physicalDevice = physical;
    a.device = device;
    a.queueFamily = family;
    a.queue = queue;
    a.enabled13 = features13;
    a.enabled13.pNext = nullptr;
    return a;
  }
};

}  // namespace snell::test
