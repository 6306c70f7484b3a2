// Context creation on the real device, SNELL_DEVICE errors, and adoption of a
// device that a host application created by hand.
#include "gpu_test.h"

#include "render/prefix_sum.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/error.h"

#include <gtest/gtest.h>

#include <numeric>
#include <vector>

namespace snell::test {
namespace {

using ContextTest = GpuTest;

TEST_F(ContextTest, PicksADeviceThatMeetsEveryRequirement) {
  const vk::DeviceFacts& facts = context().facts();
  EXPECT_TRUE(facts.unmet.empty());
  EXPECT_GE(facts.apiVersion, VK_API_VERSION_1_3);
  EXPECT_GT(context().caps().maxSubgroupSize, 0u);
  EXPECT_TRUE(context().validationEnabled());
}

TEST(DeviceSurvey, ListsEveryDeviceWithAVerdict) {
  vk::DeviceReport report = vk::surveyDevices("");
  ASSERT_FALSE(report.devices.empty()) << "CI always has lavapipe";
  ASSERT_TRUE(report.choice.chosen);
  EXPECT_EQ(report.choice.verdicts.size(), report.devices.size());
  EXPECT_NE(report.table().find("chosen"), std::string::npos);
}

TEST(DeviceSurvey, UnknownOverrideFailsWithTheListOfDevices) {
  try {
    vk::ContextDesc desc;
    desc.deviceOverride = "no-such-gpu-anywhere";
    vk::Context::create(desc);
    FAIL() << "a device was created for an override that names none";
  } catch (const vk::VulkanError& e) {
    std::string message = e.what();
    EXPECT_NE(message.find("SNELL_DEVICE=no-such-gpu-anywhere"), std::string::npos) << message;
    EXPECT_NE(message.find(vk::surveyDevices("").devices[0].name), std::string::npos) << message;
  }
}

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

  explicit HandMadeDevice(bool enableSnellFeatures) {
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
    while (!(props[family].queueFlags & VK_QUEUE_COMPUTE_BIT)) ++family;
    float priority = 1;
    VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queueInfo.queueFamilyIndex = family;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;
    features13.subgroupSizeControl = enableSnellFeatures;
    features13.computeFullSubgroups = enableSnellFeatures;
    features13.maintenance4 = enableSnellFeatures;
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

TEST(Adoption, RunsADispatchOnTheHostsDeviceAndLeavesItAlive) {
  HandMadeDevice host(true);
  {
    auto context = vk::Context::adopt(host.adopted());
    EXPECT_FALSE(context->ownsDevice());
    EXPECT_EQ(context->device(), host.device);
    render::PrefixSum scan(*context);
    std::vector<uint32_t> data(5000, 1u);
    vk::Buffer buffer(*context, {data.size() * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                                      VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                 vk::MemoryDomain::Device, "adopted scan data"});
    vk::upload(*context, buffer, data.data(), data.size() * 4);
    auto scratch = scan.makeScratch(data.size());
    vk::Commands commands(*context, "adopted");
    commands.begin();
    commands.transferToCompute();
    scan.record(commands, buffer, data.size(), scratch);
    commands.submitAndWait();
    vk::download(*context, buffer, data.data(), data.size() * 4);
    for (uint32_t i = 0; i < data.size(); ++i) ASSERT_EQ(data[i], i);
  }
  // The context is gone; the host's device must still work.
  EXPECT_EQ(vkDeviceWaitIdle(host.device), VK_SUCCESS);
  VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  ASSERT_EQ(vkCreateFence(host.device, &info, nullptr, &fence), VK_SUCCESS);
  vkDestroyFence(host.device, fence, nullptr);
  EXPECT_EQ(host.validationMessages, 0);
}

TEST(Adoption, RefusesADeviceWithoutFullSubgroupsAndSaysWhichFeature) {
  HandMadeDevice host(false);
  try {
    vk::Context::adopt(host.adopted());
    FAIL() << "adopted a device that lacks computeFullSubgroups";
  } catch (const vk::VulkanError& e) {
    EXPECT_NE(std::string(e.what()).find("computeFullSubgroups"), std::string::npos) << e.what();
  }
}

TEST(VulkanErrors, NameTheCallTheLocationAndTheResult) {
  try {
    VK_CHECK(VK_ERROR_OUT_OF_DEVICE_MEMORY);
    FAIL();
  } catch (const vk::VulkanError& e) {
    std::string message = e.what();
    EXPECT_NE(message.find("VK_ERROR_OUT_OF_DEVICE_MEMORY"), std::string::npos) << message;
    EXPECT_NE(message.find("context_test.cpp"), std::string::npos) << message;
    EXPECT_EQ(e.result(), VK_ERROR_OUT_OF_DEVICE_MEMORY);
  }
}

}  // namespace
}  // namespace snell::test
