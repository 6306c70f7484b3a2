// Errors of the Vulkan layer: every VkResult is checked, and a failure says which
// call failed, where, and the VkResult's name.
#pragma once

#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>
#include <string_view>

namespace snell::vk {

/// The VkResult's enumerant name, e.g. "VK_ERROR_OUT_OF_DEVICE_MEMORY".
std::string_view resultName(VkResult result);

/// Thrown for a failed Vulkan call or an unmet device requirement.
class VulkanError : public std::runtime_error {
 public:
  explicit VulkanError(const std::string& message, VkResult result = VK_ERROR_UNKNOWN)
      : std::runtime_error(message), result_(result) {}
  /// The VkResult that failed, or VK_ERROR_UNKNOWN for requirement errors.
  VkResult result() const { return result_; }

 private:
  VkResult result_;
};

/// Throws VulkanError naming `expression`, file:line and the result's name unless
/// `result` is VK_SUCCESS (or another non-error status code).
void check(VkResult result, const char* expression, const char* file, int line);

/// The fault switch, for tests of what a failing GPU does to snell:
///   SNELL_FAULT=CALL:RESULT[:N]
/// makes the Nth call (default the first) of the Vulkan function CALL, and
/// every later one, fail with RESULT without being made, e.g.
/// SNELL_FAULT=vkQueueSubmit:VK_ERROR_DEVICE_LOST or
/// SNELL_FAULT=vkAllocateMemory:VK_ERROR_OUT_OF_DEVICE_MEMORY:5. Returns the
/// result to fail with, or VK_SUCCESS to make the call. A malformed setting
/// throws VulkanError saying what is wrong with it.
VkResult injectedFault(const char* call);
/// SNELL_FAULT_WORKER=K narrows the fault to the calls of one worker of a
/// render over several devices (render --devices): the threads that called
/// setFaultWorker(K). Every thread is worker 0 until it says otherwise.
void setFaultWorker(int worker);
/// SNELL_FAULT=validation-message: a context with validation on reports one
/// validation message as it is created (through the layer's messenger), so
/// tests can see every command fail on one.
extern const char* const kFaultValidationMessage;

/// `call()`, unless the fault switch fails it; `expression` is the call's text.
template <typename Call>
VkResult callUnlessFaulted(const char* expression, Call&& call) {
  VkResult fault = injectedFault(expression);
  return fault != VK_SUCCESS ? fault : call();
}

}  // namespace snell::vk

/// Always-on check of a Vulkan call; never compiled out in release builds.
#define VK_CHECK(expression)                                                                                 \
  ::snell::vk::check(::snell::vk::callUnlessFaulted(#expression, [&]() -> VkResult { return (expression); }), \
                     #expression, __FILE__, __LINE__)
