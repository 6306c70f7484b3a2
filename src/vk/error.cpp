// Names of VkResult codes; Debian 12's headers lack vk_enum_string_helper.h.
#include "vk/error.h"

#include <atomic>
#include <cstdlib>
#include <mutex>
#include <sstream>
#include <string>

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

namespace {

struct FaultSwitch {
  bool armed = false;
  std::string call;
  VkResult result = VK_SUCCESS;
  unsigned long long from = 1;
  int worker = -1;  // SNELL_FAULT_WORKER; -1: every thread's calls
  std::atomic<unsigned long long> calls{0};
};

thread_local int faultWorker = 0;

VkResult resultFromName(const std::string& name) {
  for (int code = 0; code >= -1000; --code) {  // the core error codes
    if (resultName(VkResult(code)) == name) return VkResult(code);
  }
  for (VkResult r : {VK_ERROR_OUT_OF_POOL_MEMORY, VK_ERROR_INVALID_EXTERNAL_HANDLE, VK_ERROR_FRAGMENTATION,
                     VK_ERROR_SURFACE_LOST_KHR, VK_ERROR_OUT_OF_DATE_KHR, VK_ERROR_VALIDATION_FAILED_EXT}) {
    if (resultName(r) == name) return r;
  }
  return VK_SUCCESS;
}

}  // namespace

const char* const kFaultValidationMessage = "validation-message";

namespace {

// Read once: the setting belongs to the process, as SNELL_DEVICE does.
FaultSwitch& faultSwitch() {
  static FaultSwitch* instance = [] {
    auto* f = new FaultSwitch;  // never freed: calls may come from static destructors
    const char* setting = std::getenv("SNELL_FAULT");
    // "validation-message" is the context's to act on (context.cpp), not a call's.
    if (!setting || !*setting || std::string(setting) == kFaultValidationMessage) return f;
    std::string text(setting);
    size_t first = text.find(':');
    size_t second = first == std::string::npos ? first : text.find(':', first + 1);
    std::string call = text.substr(0, first);
    std::string result = first == std::string::npos ? "" : text.substr(first + 1, second - first - 1);
    f->result = resultFromName(result);
    if (call.rfind("vk", 0) != 0 || f->result >= 0) {
      throw VulkanError("SNELL_FAULT=" + text + ": expected vkCALL:VK_ERROR_...[:N], e.g. vkQueueSubmit:VK_ERROR_DEVICE_LOST, or " +
                        kFaultValidationMessage);
    }
    if (second != std::string::npos) {
      char* end = nullptr;
      f->from = std::strtoull(text.c_str() + second + 1, &end, 10);
      if (*end != '\0' || f->from == 0) throw VulkanError("SNELL_FAULT=" + text + ": N must be a whole number from 1");
    }
    if (const char* worker = std::getenv("SNELL_FAULT_WORKER"); worker && *worker) {
      char* end = nullptr;
      f->worker = int(std::strtol(worker, &end, 10));
      if (*end != '\0' || f->worker < 0) {
        throw VulkanError(std::string("SNELL_FAULT_WORKER=") + worker + ": expected a worker number from 0");
      }
    }
    f->call = call;
    f->armed = true;
    return f;
  }();
  return *instance;
}

}  // namespace

VkResult injectedFault(const char* expression) {
  FaultSwitch& f = faultSwitch();
  if (!f.armed || (f.worker >= 0 && f.worker != faultWorker)) return VK_SUCCESS;
  // The call is the expression's first word: "vkQueueSubmit(queue, ...)".
  std::string_view text(expression);
  if (text.substr(0, f.call.size()) != f.call || (text.size() > f.call.size() && text[f.call.size()] != '(')) {
    return VK_SUCCESS;
  }
  return f.calls.fetch_add(1) + 1 >= f.from ? f.result : VK_SUCCESS;
}

void setFaultWorker(int worker) { faultWorker = worker; }

}  // namespace snell::vk
