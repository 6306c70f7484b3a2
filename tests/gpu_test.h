// The fixture every GPU test uses: one Vulkan context per test process on the
// device snell would pick (lavapipe in CI), with the Khronos validation layer
// and synchronization validation on. Any validation message fails the test.
#pragma once

#include "vk/context.h"

#include <gtest/gtest.h>

#include <cstdint>

namespace snell::test {

/// The shared context; created on first use, with validation required.
vk::Context& gpuContext();

/// Whether the tests run on SwiftShader (VK_DRIVER_FILES naming its ICD: the
/// test command's SwiftShader.* tests), whose rasteriser decides which face a
/// pixel exactly on a silhouette shows by rules of its own.
inline bool onSwiftShader() { return gpuContext().facts().driverId == VK_DRIVER_ID_GOOGLE_SWIFTSHADER; }

class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  vk::Context& context() { return gpuContext(); }

 private:
  uint64_t messagesBefore_ = 0;
};

}  // namespace snell::test
