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

}  // namespace snell::vk

/// Always-on check of a Vulkan call; never compiled out in release builds.
#define VK_CHECK(expression) ::snell::vk::check((expression), #expression, __FILE__, __LINE__)
