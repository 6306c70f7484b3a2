// The shared GPU test context and the validation-message check.
#include "gpu_test.h"

#include <memory>

namespace snell::test {

vk::Context& gpuContext() {
  static std::unique_ptr<vk::Context> context = [] {
    vk::ContextDesc desc;
    desc.applicationName = "snell tests";
    desc.validation = true;
    desc.synchronizationValidation = true;
    desc.robustBufferAccess = true;  // a shader's stray write fails a test, not the heap
    return vk::Context::create(desc);
  }();
  return *context;
}

void GpuTest::SetUp() { messagesBefore_ = gpuContext().validationMessageCount(); }

void GpuTest::TearDown() {
  EXPECT_EQ(gpuContext().validationMessageCount(), messagesBefore_)
      << "the validation layer reported messages during this test (printed above)";
}

}  // namespace snell::test
