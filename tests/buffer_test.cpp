// Buffers and images in every memory domain: round trips through staging, and
// destruction deferred while the GPU may still use a handle.
#include "gpu_test.h"

#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/error.h"

#include <cstring>
#include <numeric>
#include <vector>

namespace snell::test {
namespace {

using BufferTest = GpuTest;
constexpr VkBufferUsageFlags kUsage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

std::vector<uint32_t> ramp(size_t n) {
  std::vector<uint32_t> v(n);
  std::iota(v.begin(), v.end(), 7u);
  return v;
}

TEST_F(BufferTest, DeviceBufferRoundTripsThroughStaging) {
  std::vector<uint32_t> data = ramp(10000);
  vk::Buffer buffer(context(), {data.size() * 4, kUsage, vk::MemoryDomain::Device, "device round trip"});
  EXPECT_TRUE(buffer.mapped().empty());
  vk::upload(context(), buffer, data.data(), data.size() * 4);
  std::vector<uint32_t> back(data.size());
  vk::download(context(), buffer, back.data(), back.size() * 4);
  EXPECT_EQ(back, data);
}

TEST_F(BufferTest, UploadAndReadbackBuffersAreMapped) {
  vk::Buffer upload(context(), {256, kUsage, vk::MemoryDomain::Upload, "upload"});
  vk::Buffer readback(context(), {256, kUsage, vk::MemoryDomain::Readback, "readback"});
  ASSERT_EQ(upload.mapped().size(), 256u);
  ASSERT_EQ(readback.mapped().size(), 256u);
  std::vector<uint32_t> data = ramp(64);
  vk::upload(context(), upload, data.data(), 256);
  vk::Commands commands(context(), "copy");
  commands.begin();
  commands.copyBuffer(upload, readback, 256);
  commands.transferToHost();
  commands.submitAndWait();
  EXPECT_EQ(std::memcmp(readback.mapped().data(), data.data(), 256), 0);
}

TEST_F(BufferTest, EmptyBufferIsAllowed) {
  vk::Buffer empty(context(), {0, kUsage, vk::MemoryDomain::Device, "empty"});
  EXPECT_EQ(empty.size(), 0u);
  EXPECT_NE(empty.handle(), VK_NULL_HANDLE);
}

TEST_F(BufferTest, UploadPastTheEndIsAnErrorThatNamesTheBuffer) {
  vk::Buffer small(context(), {16, kUsage, vk::MemoryDomain::Device, "small one"});
  std::vector<uint32_t> data = ramp(8);
  try {
    vk::upload(context(), small, data.data(), 32);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("small one"), std::string::npos) << e.what();
  }
}

TEST_F(BufferTest, AbsurdAllocationFailsWithAClearError) {
  try {
    vk::Buffer huge(context(), {uint64_t(1) << 50, kUsage, vk::MemoryDomain::Device, "one petabyte"});
    FAIL() << "allocated a petabyte";
  } catch (const vk::VulkanError& e) {
    EXPECT_NE(std::string(e.what()).find("one petabyte"), std::string::npos) << e.what();
  }
}

TEST_F(BufferTest, DestroyingABufferInFlightWaitsForTheGpu) {
  vk::Buffer target(context(), {4096, kUsage, vk::MemoryDomain::Device, "target"});
  vk::Commands commands(context(), "in flight");
  {
    vk::Buffer source(context(), {4096, kUsage, vk::MemoryDomain::Upload, "doomed source"});
    std::vector<uint32_t> data = ramp(1024);
    vk::upload(context(), source, data.data(), 4096);
    commands.begin();
    commands.copyBuffer(source, target, 4096);
    commands.submit();
  }  // `source` is released here while the copy may still run; validation would object to an early destroy
  commands.wait();
  std::vector<uint32_t> back(1024);
  vk::download(context(), target, back.data(), 4096);
  EXPECT_EQ(back, ramp(1024));
}

TEST_F(BufferTest, MovedBufferOwnsTheHandleOnce) {
  vk::Buffer a(context(), {64, kUsage, vk::MemoryDomain::Device, "moved"});
  VkBuffer handle = a.handle();
  vk::Buffer b(std::move(a));
  EXPECT_EQ(b.handle(), handle);
  EXPECT_EQ(a.handle(), VK_NULL_HANDLE);
}

TEST_F(BufferTest, ImageRoundTripsThroughStaging) {
  vk::Image image(context(), {5, 3, VK_FORMAT_R32_UINT,
                              VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
                              "odd image"});
  std::vector<uint32_t> pixels = ramp(15);
  vk::uploadImage(context(), image, pixels.data());
  std::vector<uint32_t> back(15);
  vk::downloadImage(context(), image, back.data());
  EXPECT_EQ(back, pixels);
}

TEST_F(BufferTest, ImageBeyondTheDeviceLimitIsAClearError) {
  try {
    vk::Image image(context(), {1u << 20, 1u << 20, VK_FORMAT_R16G16B16A16_SFLOAT,
                                VK_IMAGE_USAGE_STORAGE_BIT, "enormous"});
    FAIL();
  } catch (const vk::VulkanError& e) {
    EXPECT_NE(std::string(e.what()).find("enormous"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not supported"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace snell::test
