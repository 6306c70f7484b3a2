// Compute programs know their layout from SPIR-V and take thread counts.
#include "gpu_test.h"

#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "vk/error.h"

#include "fill_index.spv.h"

#include <vector>

namespace snell::test {
namespace {

using ComputeProgramTest = GpuTest;

struct FillPush {
  uint32_t count;
  uint32_t base;
};

vk::ComputeProgramDesc fillDesc(uint32_t localSize) {
  return {"fill_index", kSpvFillIndex, {{0, localSize}}, false};
}

TEST_F(ComputeProgramTest, ReflectsSpecializedWorkgroupSizeBindingsAndPushConstants) {
  vk::ComputeProgram program(context(), fillDesc(48));
  EXPECT_EQ(program.localSize()[0], 48u);
  EXPECT_EQ(program.localSize()[1], 1u);
  ASSERT_EQ(program.reflection().bindings.size(), 1u);
  EXPECT_EQ(program.reflection().bindings[0].binding, 0u);
  EXPECT_EQ(program.reflection().bindings[0].type, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
  EXPECT_EQ(program.reflection().pushConstantBytes, sizeof(FillPush));
}

TEST_F(ComputeProgramTest, DispatchThreadsCoversExactlyTheCountGiven) {
  vk::ComputeProgram program(context(), fillDesc(64));
  const uint32_t count = 1000;  // not a multiple of 64
  vk::Buffer out(context(), {(count + 24) * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                                                   VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                             vk::MemoryDomain::Device, "fill"});
  vk::Commands commands(context(), "fill");
  commands.begin();
  commands.fillBuffer(out, 0xDEADBEEFu);
  commands.transferToCompute();
  program.dispatchThreads(commands, {{0, &out}}, FillPush{count, 5}, count);
  commands.submitAndWait();
  std::vector<uint32_t> back(count + 24);
  vk::download(context(), out, back.data(), back.size() * 4);
  for (uint32_t i = 0; i < count; ++i) ASSERT_EQ(back[i], 5 + i) << "at " << i;
  for (uint32_t i = count; i < count + 24; ++i) ASSERT_EQ(back[i], 0xDEADBEEFu) << "written past the count at " << i;
}

// The tests' context checks buffer bounds (tests/gpu_test.cpp): a shader
// writing past a buffer's end, as a wrong count or index would make it, leaves
// the memory beyond alone, so the mistake fails a test as wrong values rather
// than corrupting the heap of a CPU driver's process. (lavapipe checks every
// storage buffer access anyway; SwiftShader without the checks writes into its
// heap, and this test dies there.)
TEST_F(ComputeProgramTest, AWritePastTheBuffersEndIsDroppedUnderTheTestsBoundsChecks) {
  ASSERT_FALSE(context().caps().robustAccess.empty()) << "the device offers no robustBufferAccess";
  vk::ComputeProgram program(context(), fillDesc(64));
  const uint32_t size = 64, stray = 4096;
  const VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  vk::Buffer out(context(), {size * 4, usage, vk::MemoryDomain::Device, "short fill"});
  vk::Buffer beyond(context(), {stray * 4, usage, vk::MemoryDomain::Device, "beyond"});
  vk::Commands commands(context(), "stray fill");
  commands.begin();
  commands.fillBuffer(beyond, 0xDEADBEEFu);
  commands.transferToCompute();
  program.dispatchThreads(commands, {{0, &out}}, FillPush{stray, 1}, stray);
  commands.submitAndWait();
  std::vector<uint32_t> inside(size), after(stray);
  vk::download(context(), out, inside.data(), size * 4);
  vk::download(context(), beyond, after.data(), stray * 4);
  for (uint32_t i = 0; i < size; ++i) ASSERT_EQ(inside[i], 1 + i) << "at " << i;
  for (uint32_t i = 0; i < stray; ++i) ASSERT_EQ(after[i], 0xDEADBEEFu) << "the next buffer was written at " << i;
}

TEST_F(ComputeProgramTest, DispatchBeyondTheXLimitIsSplitOverY) {
  vk::ComputeProgram program(context(), fillDesc(8));
  uint64_t limit = context().caps().maxComputeWorkgroupCount[0];
  if (limit > (1u << 20)) {
    // NVIDIA allows 2^31 - 1 groups along x: exceeding that would need 64 GiB.
    // CI's lavapipe allows 65535, so CI always runs this test.
    GTEST_SKIP() << "this device's x limit (" << limit << " groups) is too large to exceed in a test";
  }
  uint64_t groups = limit + 100;
  uint64_t count = groups * 8;
  vk::Buffer out(context(), {count * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                             vk::MemoryDomain::Device, "wide fill"});
  vk::Commands commands(context(), "wide fill");
  commands.begin();
  program.dispatchGroups(commands, {{0, &out}}, FillPush{static_cast<uint32_t>(count), 0}, groups);
  commands.submitAndWait();
  std::vector<uint32_t> back(count);
  vk::download(context(), out, back.data(), count * 4);
  for (uint64_t i = 0; i < count; ++i) ASSERT_EQ(back[i], i) << "at " << i;
}

TEST_F(ComputeProgramTest, WrongPushConstantSizeIsRefusedWithTheProgramName) {
  vk::ComputeProgram program(context(), fillDesc(64));
  vk::Buffer out(context(), {64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryDomain::Device, "out"});
  vk::Commands commands(context(), "bad push");
  commands.begin();
  struct TooBig {
    uint32_t a, b, c;
  };
  try {
    program.dispatchThreads(commands, {{0, &out}}, TooBig{1, 2, 3}, 1);
    FAIL();
  } catch (const vk::VulkanError& e) {
    EXPECT_NE(std::string(e.what()).find("fill_index"), std::string::npos) << e.what();
  }
  commands.submitAndWait();
}

TEST_F(ComputeProgramTest, MissingBindingIsRefused) {
  vk::ComputeProgram program(context(), fillDesc(64));
  vk::Commands commands(context(), "no binding");
  commands.begin();
  EXPECT_THROW(program.dispatchThreads(commands, {}, FillPush{1, 0}, 1), vk::VulkanError);
  commands.submitAndWait();
}

TEST_F(ComputeProgramTest, PassTimesAreReportedInMilliseconds) {
  if (context().caps().timestampValidBits == 0) GTEST_FAIL() << "CI's lavapipe has timestamps";
  vk::ComputeProgram program(context(), fillDesc(64));
  vk::Buffer out(context(), {4096 * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryDomain::Device, "timed"});
  vk::Commands commands(context(), "timed");
  commands.begin();
  commands.beginPass("fill");
  program.dispatchThreads(commands, {{0, &out}}, FillPush{4096, 0}, 4096);
  commands.endPass();
  commands.submitAndWait();
  ASSERT_EQ(commands.passTimes().size(), 1u);
  EXPECT_EQ(commands.passTimes()[0].name, "fill");
  EXPECT_GE(commands.passTimes()[0].milliseconds, 0.0);
  EXPECT_LT(commands.passTimes()[0].milliseconds, 10000.0);
}

TEST(SpirvReflection, RejectsBytesThatAreNotSpirv) {
  std::vector<uint32_t> junk = {1, 2, 3, 4, 5, 6};
  EXPECT_THROW(vk::reflectShader(junk, {}, "junk"), std::runtime_error);
}

TEST(SpirvReflection, RejectsTruncatedModules) {
  std::vector<uint32_t> truncated(std::begin(kSpvFillIndex), std::begin(kSpvFillIndex) + 40);
  truncated.push_back(0xFFFF0000u | 71u);  // claims 65535 words
  EXPECT_THROW(vk::reflectShader(truncated, {}, "truncated"), std::runtime_error);
}

}  // namespace
}  // namespace snell::test
