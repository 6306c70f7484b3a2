// Context creation on the real device, SNELL_DEVICE errors, and adoption of a
// device that a host application created by hand.
#include "gpu_test.h"
#include "hand_made_device.h"

#include "io/environment.h"
#include "render/prefix_sum.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/error.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <string>

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
  vk::DeviceReport report = vk::surveyDevices("", io::deviceEnvironment());
  ASSERT_FALSE(report.devices.empty()) << "CI always has lavapipe";
  ASSERT_TRUE(report.choice.chosen);
  EXPECT_EQ(report.choice.verdicts.size(), report.devices.size());
  EXPECT_NE(report.table().find("chosen"), std::string::npos);
}

// Sets an environment variable for one scope, as it was after.
class ScopedEnvironment {
 public:
  ScopedEnvironment(const char* name, const char* value) : name_(name) {
    const char* old = std::getenv(name);
    if (old) old_ = old;
    value ? ::setenv(name, value, 1) : ::unsetenv(name);
  }
  ~ScopedEnvironment() { old_ ? ::setenv(name_, old_->c_str(), 1) : ::unsetenv(name_); }

 private:
  const char* name_;
  std::optional<std::string> old_;
};

TEST(DeviceSurvey, SlurmsStepGpusNameTheDeviceWhenNoCudaListIsSet) {
  // Slurm's GPU plugin sets CUDA_VISIBLE_DEVICES beside SLURM_STEP_GPUS; without it the step's list still counts.
  ScopedEnvironment cuda("CUDA_VISIBLE_DEVICES", nullptr), ordinal("GPU_DEVICE_ORDINAL", nullptr);
  ScopedEnvironment step("SLURM_STEP_GPUS", "0");
  std::string why;
  try {
    why = vk::surveyDevices("", io::deviceEnvironment()).why;
  } catch (const vk::VulkanError& e) {
    why = e.what();  // a machine without a GPU (lavapipe only): GPU 0 is not there, and the error says so
  }
  EXPECT_NE(why.find("SLURM_STEP_GPUS=0"), std::string::npos) << why;
}

TEST(DeviceSurvey, UnknownOverrideFailsWithTheListOfDevices) {
  try {
    vk::ContextDesc desc;
    desc.deviceOverride = "no-such-gpu-anywhere";
    vk::Context::create(desc);
    FAIL() << "a device was created for an override that names none";
  } catch (const vk::VulkanError& e) {
    std::string message = e.what();
    EXPECT_NE(message.find("device=no-such-gpu-anywhere names another device"), std::string::npos) << message;
    EXPECT_NE(message.find(vk::surveyDevices("", io::deviceEnvironment()).devices[0].name), std::string::npos) << message;
  }
}

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
