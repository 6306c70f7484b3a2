// Device choice as a pure function of device facts: ranking, SNELL_DEVICE, and
// the reasons given for every device not chosen.
#include "vk/device_selection.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include <string>
#include <vector>

#include "vk/error.h"

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

// RADV's null device (RADV_FORCE_FAMILY): a discrete GPU with no memory,
// as readDeviceFacts describes it.
DeviceFacts nullDevice(uint32_t index) {
  DeviceFacts d = device(index, "Null hardware (RADV GFX1100)", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, 0);
  d.cannotRun = "it has no device-local memory";
  return d;
}

TEST(DeviceSelection, ADeviceWithoutMemoryIsPassedOverForWorkAndTakenToCompile) {
  std::vector<DeviceFacts> devices = {device(0, "llvmpipe (LLVM 15.0.6, 256 bits)", VK_PHYSICAL_DEVICE_TYPE_CPU),
                                      nullDevice(1)};
  DeviceChoice run = chooseDevice(devices, "");
  ASSERT_TRUE(run.chosen);
  EXPECT_EQ(*run.chosen, 0u);
  EXPECT_NE(run.verdicts[1].find("rejected: it has no device-local memory"), std::string::npos) << run.verdicts[1];
  DeviceChoice compile = chooseDevice(devices, "", "", DeviceUse::Compile);
  ASSERT_TRUE(compile.chosen);
  EXPECT_EQ(*compile.chosen, 1u);
}

TEST(DeviceSelection, ADeviceWithoutMemoryNamedForWorkIsRefusedWithTheReason) {
  std::vector<DeviceFacts> devices = {nullDevice(0)};
  DeviceChoice choice = chooseDevice(devices, "0");
  EXPECT_FALSE(choice.chosen);
  EXPECT_NE(choice.verdicts[0].find("no device-local memory"), std::string::npos) << choice.verdicts[0];
  EXPECT_THROW(chooseDeviceList(devices, "0"), std::invalid_argument);
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

// A node as a driver may enumerate it: not in PCI bus order, lavapipe among the GPUs.
std::vector<DeviceFacts> fourGpuNode() {
  std::vector<DeviceFacts> devices;
  const char* buses[] = {"0000:c1:00.0", "0000:41:00.0", "0000:81:00.0", "0000:01:00.0"};
  for (uint32_t i = 0; i < 4; ++i) {
    devices.push_back(device(i, "NVIDIA H200", VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU, 143771));
    devices.back().pciBus = buses[i];
    devices.back().uuid = "0" + std::to_string(i) + "c0ffee-1234-5678-9abc-def012345678";
  }
  devices.push_back(device(4, "llvmpipe (LLVM 15.0.6, 256 bits)", VK_PHYSICAL_DEVICE_TYPE_CPU));
  return devices;
}

TEST(DeviceSelection, OverrideByUuidTakesNvidiaSmisSpelling) {
  auto devices = fourGpuNode();
  EXPECT_EQ(*chooseDevice(devices, "GPU-02C0FFEE-1234-5678-9abc-def012345678").chosen, 2u);
  EXPECT_EQ(*chooseDevice(devices, "03c0ffee-1234").chosen, 3u) << "a unique prefix is enough";
}

TEST(LauncherOverride, AnIndexCountsGpusInPciBusOrder) {
  std::string why;
  // Bus order: [3] 01, [1] 41, [2] 81, [0] c1.
  EXPECT_EQ(launcherOverride(fourGpuNode(), "CUDA_VISIBLE_DEVICES", "0", why), "3");
  EXPECT_EQ(launcherOverride(fourGpuNode(), "CUDA_VISIBLE_DEVICES", "2", why), "2");
  EXPECT_EQ(launcherOverride(fourGpuNode(), "CUDA_VISIBLE_DEVICES", "3,1", why), "0") << "the first entry is taken";
  EXPECT_NE(why.find("CUDA_VISIBLE_DEVICES=3,1"), std::string::npos) << why;
  EXPECT_NE(why.find("0000:c1:00.0"), std::string::npos) << why;
}

TEST(LauncherOverride, AUuidNamesItsGpuWhereverItIsEnumerated) {
  std::string why;
  EXPECT_EQ(launcherOverride(fourGpuNode(), "CUDA_VISIBLE_DEVICES", "GPU-01c0ffee-1234-5678-9abc-def012345678", why),
            "1");
}

TEST(LauncherOverride, AnIndexPastTheGpusFailsNamingTheVariable) {
  std::string why;
  try {
    launcherOverride(fourGpuNode(), "GPU_DEVICE_ORDINAL", "4", why);
    FAIL() << "lavapipe was counted as a GPU";
  } catch (const VulkanError& e) {
    EXPECT_NE(std::string(e.what()).find("GPU_DEVICE_ORDINAL=4"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("4 GPU(s)"), std::string::npos) << e.what();
  }
  EXPECT_THROW(launcherOverride(fourGpuNode(), "CUDA_VISIBLE_DEVICES", "GPU-ffffffff-0000", why), VulkanError);
  EXPECT_THROW(launcherOverride(fourGpuNode(), "CUDA_VISIBLE_DEVICES", "gpu", why), VulkanError);
}

TEST(LauncherOverride, VerdictsNameTheLauncherVariable) {
  auto devices = fourGpuNode();
  std::string why;
  std::string override = launcherOverride(devices, "CUDA_VISIBLE_DEVICES", "1", why);
  DeviceChoice choice = chooseDevice(devices, override, why);
  EXPECT_EQ(*choice.chosen, 1u);
  EXPECT_NE(choice.verdicts[0].find("CUDA_VISIBLE_DEVICES=1"), std::string::npos) << choice.verdicts[0];
}

TEST(DeviceList, AllIsEveryQualifyingDeviceOfTheBestKind) {
  auto devices = fourGpuNode();
  devices[2].unmet = {"feature maintenance4 is missing"};
  EXPECT_EQ(chooseDeviceList(devices, "all"), (std::vector<uint32_t>{0, 1, 3})) << "no lavapipe beside GPUs";
  auto cpuOnly = laptop();
  cpuOnly.resize(1);
  EXPECT_EQ(chooseDeviceList(cpuOnly, "all"), (std::vector<uint32_t>{0}));
}

TEST(DeviceList, IndicesAndUuidsMayNameOneDeviceTwice) {
  auto devices = fourGpuNode();
  EXPECT_EQ(chooseDeviceList(devices, "3,01c0ffee-1234,3"), (std::vector<uint32_t>{3, 1, 3}));
  EXPECT_EQ(chooseDeviceList(devices, "4,4"), (std::vector<uint32_t>{4, 4})) << "two workers on lavapipe";
}

TEST(DeviceList, AMissingOrUnqualifiedDeviceIsAnErrorNamingIt) {
  auto devices = fourGpuNode();
  devices[1].unmet = {"feature maintenance4 is missing"};
  auto message = [&](const std::string& list) {
    try {
      chooseDeviceList(devices, list);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(message("0,7").find("no device 7"), std::string::npos) << message("0,7");
  EXPECT_NE(message("1").find("maintenance4"), std::string::npos) << message("1");
  EXPECT_NE(message("gpu0").find("neither a device index nor a UUID"), std::string::npos) << message("gpu0");
  EXPECT_NE(message("0,,1").find("empty entry"), std::string::npos) << message("0,,1");
}

TEST(LauncherOverride, EveryGpuOfAListMapsForDevicesAll) {
  EXPECT_EQ(launcherDevices(fourGpuNode(), "CUDA_VISIBLE_DEVICES", "0,2"), (std::vector<uint32_t>{3, 2}));
}

}  // namespace
}  // namespace snell::vk
