// Device choice as a pure function of device facts: ranking, SNELL_DEVICE, and
// the reasons given for every device not chosen.
#include "vk/device_selection.h"

#include <gtest/gtest.h>

#include <vector>

namespace snell::vk {
namespace {

DeviceFacts device(uint32_t index, const char* name, VkPhysicalDeviceType type, uint64_t memoryMiB = 1024) {
  DeviceFacts d;
  d.index = index;
  d.name = name;
  d.type = type;
  d.apiVersion = VK_API_VERSION_1_3;
  d.deviceLocalBytes = memoryMiB << 20;
  return d;
}

std::vector<DeviceFacts> laptop() {
  return {device(0, "llvmpipe (LLVM 15.0.6, 256 bits)", VK_PHYSICAL_DEVICE_TYPE_CPU),
          device(1, "Intel(R) UHD Graphics 630", VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU),
          device(2, "NVIDIA GeForce RTX 3080", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU)};
}

TEST(DeviceSelection, PrefersDiscreteOverIntegratedOverCpu) {
  auto devices = laptop();
  DeviceChoice choice = chooseDevice(devices, "");
  ASSERT_TRUE(choice.chosen);
  EXPECT_EQ(*choice.chosen, 2u);
  devices.pop_back();
  EXPECT_EQ(*chooseDevice(devices, "").chosen, 1u);
}

TEST(DeviceSelection, FallsBackToLavapipeWhenItIsAlone) {
  auto devices = laptop();
  devices.resize(1);
  DeviceChoice choice = chooseDevice(devices, "");
  ASSERT_TRUE(choice.chosen);
  EXPECT_EQ(*choice.chosen, 0u);
  EXPECT_NE(choice.verdicts[0].find("chosen"), std::string::npos);
}

TEST(DeviceSelection, OverrideByIndexWinsOverRanking) {
  DeviceChoice choice = chooseDevice(laptop(), "0");
  ASSERT_TRUE(choice.chosen);
  EXPECT_EQ(*choice.chosen, 0u);
  EXPECT_NE(choice.verdicts[2].find("SNELL_DEVICE=0 names another device"), std::string::npos);
}

TEST(DeviceSelection, OverrideByNameIsACaseInsensitiveSubstring) {
  DeviceChoice choice = chooseDevice(laptop(), "uhd graphics");
  ASSERT_TRUE(choice.chosen);
  EXPECT_EQ(*choice.chosen, 1u);
}

TEST(DeviceSelection, OverrideThatNamesNothingChoosesNothingAndSaysWhy) {
  DeviceChoice choice = chooseDevice(laptop(), "radeon");
  EXPECT_FALSE(choice.chosen);
  ASSERT_EQ(choice.verdicts.size(), 3u);
  for (const std::string& verdict : choice.verdicts) {
    EXPECT_NE(verdict.find("SNELL_DEVICE=radeon names another device"), std::string::npos) << verdict;
  }
}

TEST(DeviceSelection, RejectedDeviceListsItsUnmetRequirements) {
  auto devices = laptop();
  devices[2].unmet = {"Vulkan 1.2.0 is below the required 1.3", "feature computeFullSubgroups is missing"};
  DeviceChoice choice = chooseDevice(devices, "");
  EXPECT_EQ(*choice.chosen, 1u);
  EXPECT_EQ(choice.verdicts[2], "rejected: Vulkan 1.2.0 is below the required 1.3; feature computeFullSubgroups is missing");
}

TEST(DeviceSelection, NotChosenDevicesNameTheOneThatOutranksThem) {
  DeviceChoice choice = chooseDevice(laptop(), "");
  EXPECT_NE(choice.verdicts[0].find("ranks below NVIDIA GeForce RTX 3080"), std::string::npos) << choice.verdicts[0];
}

TEST(DeviceSelection, TiesGoToMoreDeviceMemory) {
  std::vector<DeviceFacts> devices = {device(0, "small", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, 4096),
                                      device(1, "large", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, 81920)};
  EXPECT_EQ(*chooseDevice(devices, "").chosen, 1u);
}

TEST(DeviceSelection, NoDevicesMeansNoChoice) {
  EXPECT_FALSE(chooseDevice({}, "").chosen);
}

}  // namespace
}  // namespace snell::vk
