#include "vk/pipeline_cache.h"

#include "vk/error.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

namespace snell::vk {

namespace {

// The header every VkPipelineCache's data starts with (VK_PIPELINE_CACHE_HEADER_VERSION_ONE).
struct Header {
  uint32_t size;
  uint32_t version;
  uint32_t vendorID;
  uint32_t deviceID;
  uint8_t uuid[VK_UUID_SIZE];
};

std::string hex(const uint8_t* bytes, size_t count) {
  static const char digits[] = "0123456789abcdef";
  std::string out;
  for (size_t i = 0; i < count; ++i) out += {digits[bytes[i] >> 4], digits[bytes[i] & 15]};
  return out;
}

// Why `data` is not this device's cache, or "" when it is.
std::string mismatch(const std::vector<char>& data, const VkPhysicalDeviceProperties& properties) {
  Header header{};
  if (data.size() < sizeof(Header)) return "it is " + std::to_string(data.size()) + " bytes, shorter than a header";
  std::memcpy(&header, data.data(), sizeof(Header));
  if (header.size < sizeof(Header) || header.size > data.size()) return "its header size is wrong";
  if (header.version != VK_PIPELINE_CACHE_HEADER_VERSION_ONE) return "its header version is unknown";
  if (header.vendorID != properties.vendorID || header.deviceID != properties.deviceID ||
      std::memcmp(header.uuid, properties.pipelineCacheUUID, VK_UUID_SIZE) != 0) {
    return "it was made by another device or driver";
  }
  return "";
}

}  // namespace

std::filesystem::path PipelineCache::pathFor(const VkPhysicalDeviceProperties& properties) {
  std::filesystem::path folder;
  const char* chosen = std::getenv("SNELL_PIPELINE_CACHE");
  if (chosen && std::string(chosen) == "off") return {};
  if (chosen && *chosen) {
    folder = chosen;
  } else if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
    folder = std::filesystem::path(xdg) / "snell";
  } else if (const char* home = std::getenv("HOME"); home && *home) {
    folder = std::filesystem::path(home) / ".cache" / "snell";
  } else {
    return {};
  }
  char name[96];
  std::snprintf(name, sizeof name, "pipelines-%04x-%04x-%08x-", properties.vendorID, properties.deviceID,
                properties.driverVersion);
  return folder / (name + hex(properties.pipelineCacheUUID, VK_UUID_SIZE) + ".bin");
}

PipelineCache::PipelineCache(VkDevice device, VkPhysicalDevice physicalDevice) : device_(device) {
  VkPhysicalDeviceProperties properties{};
  vkGetPhysicalDeviceProperties(physicalDevice, &properties);
  path_ = pathFor(properties);
  std::vector<char> data;
  if (!path_.empty()) {
    std::ifstream in(path_, std::ios::binary);
    if (in) data.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    if (!data.empty()) {
      if (std::string why = mismatch(data, properties); !why.empty()) {
        warning_ = "ignored the pipeline cache " + path_.string() + ": " + why;
        data.clear();
      }
    }
  }
  VkPipelineCacheCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
  info.initialDataSize = data.size();
  info.pInitialData = data.empty() ? nullptr : data.data();
  if (vkCreatePipelineCache(device, &info, nullptr, &cache_) != VK_SUCCESS && !data.empty()) {
    warning_ = "ignored the pipeline cache " + path_.string() + ": the driver refused its contents";
    data.clear();
    info.initialDataSize = 0;
    info.pInitialData = nullptr;
    cache_ = VK_NULL_HANDLE;
  }
  if (!cache_) VK_CHECK(vkCreatePipelineCache(device, &info, nullptr, &cache_));
  loaded_ = data.size();
}

PipelineCache::~PipelineCache() {
  if (cache_) vkDestroyPipelineCache(device_, cache_, nullptr);
}

std::string PipelineCache::save() {
  if (path_.empty() || !cache_) return "";
  size_t size = 0;
  if (vkGetPipelineCacheData(device_, cache_, &size, nullptr) != VK_SUCCESS || size <= loaded_) return "";
  std::vector<char> data(size);
  if (vkGetPipelineCacheData(device_, cache_, &size, data.data()) != VK_SUCCESS) return "";
  data.resize(size);
  std::error_code error;
  std::filesystem::create_directories(path_.parent_path(), error);
  // Another process may write the same file: each writes its own temporary, the last rename wins whole.
  std::filesystem::path temporary = path_;
  temporary += ".tmp" + std::to_string(::getpid());
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out.write(data.data(), std::streamsize(data.size()));
    if (!out) {
      std::filesystem::remove(temporary, error);
      return "could not write the pipeline cache " + path_.string() + " (the next process compiles again)";
    }
  }
  std::filesystem::rename(temporary, path_, error);
  if (error) {
    std::string why = error.message();
    std::filesystem::remove(temporary, error);
    return "could not write the pipeline cache " + path_.string() + ": " + why;
  }
  loaded_ = data.size();
  return "";
}

}  // namespace snell::vk
