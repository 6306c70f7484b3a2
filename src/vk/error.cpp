// Names of VkResult codes; Debian 12's headers lack vk_enum_string_helper.h.
#include "vk/error.h"

#include <sstream>

namespace snell::vk {

std::string_view resultName(VkResult result) {
  switch (result) {
#define SNELL_RESULT(name) \
  case name:               \
    return #name;
    SNELL_RESULT(VK_SUCCESS)
    SNELL_RESULT(VK_NOT_READY)
    SNELL_RESULT(VK_TIMEOUT)
    SNELL_RESULT(VK_EVENT_SET)
    SNELL_RESULT(VK_EVENT_RESET)
    SNELL_RESULT(VK_INCOMPLETE)
    SNELL_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
    SNELL_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    SNELL_RESULT(VK_ERROR_INITIALIZATION_FAILED)
    SNELL_RESULT(VK_ERROR_DEVICE_LOST)
    SNELL_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
    SNELL_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
    SNELL_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
    SNELL_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
    SNELL_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
    SNELL_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
    SNELL_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
    SNELL_RESULT(VK_ERROR_FRAGMENTED_POOL)
    SNELL_RESULT(VK_ERROR_UNKNOWN)
    SNELL_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
    SNELL_RESULT(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    SNELL_RESULT(VK_ERROR_FRAGMENTATION)
    SNELL_RESULT(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
    SNELL_RESULT(VK_PIPELINE_COMPILE_REQUIRED)
    SNELL_RESULT(VK_ERROR_SURFACE_LOST_KHR)
    SNELL_RESULT(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
    SNELL_RESULT(VK_SUBOPTIMAL_KHR)
    SNELL_RESULT(VK_ERROR_OUT_OF_DATE_KHR)
    SNELL_RESULT(VK_ERROR_INCOMPATIBLE_DISPLAY_KHR)
    SNELL_RESULT(VK_ERROR_VALIDATION_FAILED_EXT)
    SNELL_RESULT(VK_ERROR_INVALID_SHADER_NV)
#undef SNELL_RESULT
    default:
      return "VK_RESULT_UNRECOGNISED";
  }
}

void check(VkResult result, const char* expression, const char* file, int line) {
  if (result >= 0) return;  // non-negative codes are statuses, not errors
  std::ostringstream message;
  message << expression << " failed with " << resultName(result) << " (" << static_cast<int>(result)
          << ") at " << file << ":" << line;
  throw VulkanError(message.str(), result);
}

}  // namespace snell::vk
