// A VkPipelineCache kept on disk between processes: a fresh process (a new
// container, a CI machine, a host that embeds snell) skips the driver's
// compile of every pipeline an earlier one made. One file per device and
// driver, named by the device's pipelineCacheUUID, vendor, device and driver
// version, in $SNELL_PIPELINE_CACHE, else $XDG_CACHE_HOME/snell, else
// ~/.cache/snell. SNELL_PIPELINE_CACHE=off keeps nothing on disk. A file whose
// header does not match the device, or that the driver refuses, is ignored
// with a note; a cache that cannot be written is a note, never an error.
#pragma once

#include <vulkan/vulkan.h>

#include <filesystem>
#include <string>

namespace snell::vk {

class PipelineCache {
 public:
  /// Loads the device's file, if there is a good one.
  PipelineCache(VkDevice device, VkPhysicalDevice physicalDevice);
  ~PipelineCache();
  PipelineCache(const PipelineCache&) = delete;
  PipelineCache& operator=(const PipelineCache&) = delete;

  VkPipelineCache handle() const { return cache_; }
  /// Writes the cache back (atomically: a temporary file renamed) when it
  /// grew since it was loaded. Never throws; returns what went wrong, or "".
  std::string save();

  /// The file (empty when the cache stays in memory).
  const std::filesystem::path& path() const { return path_; }
  /// Bytes loaded from the file at start (0: none, or ignored).
  size_t loadedBytes() const { return loaded_; }
  /// What was wrong with the file at start, for the user (empty when nothing was).
  const std::string& warning() const { return warning_; }

  /// Where a device's cache file lives (empty path: caching on disk is off).
  static std::filesystem::path pathFor(const VkPhysicalDeviceProperties& properties);

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  VkPipelineCache cache_ = VK_NULL_HANDLE;
  std::filesystem::path path_;
  size_t loaded_ = 0;
  std::string warning_;
};

}  // namespace snell::vk
