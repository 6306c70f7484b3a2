// RAII buffers and images with memory domains, and the exportable semaphores
// a host shares frames by. Destruction is deferred until the GPU has finished
// every submission made before it.
#pragma once

#include "vk/context.h"

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace snell::vk {

/// Where a resource's memory lives.
enum class MemoryDomain {
  Device,    ///< GPU-local, not mapped: every pass's working data
  Upload,    ///< host-visible and coherent, mapped: host writes, GPU reads
  Readback,  ///< host-visible, cached where possible, mapped: GPU writes, host reads
};

struct BufferDesc {
  VkDeviceSize size = 0;  ///< bytes; 0 is allowed and allocates a small placeholder
  VkBufferUsageFlags usage =
      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  MemoryDomain domain = MemoryDomain::Device;
  std::string name;  ///< shown by validation messages and debuggers
  /// Its memory can give the buffer a device address (needs DeviceCaps::bufferDeviceAddress
  /// and VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT in `usage`).
  bool deviceAddress = false;
};

/// A VkBuffer with its own memory.
class Buffer {
 public:
  Buffer() = default;
  Buffer(Context& context, const BufferDesc& desc);
  ~Buffer();
  Buffer(Buffer&& other) noexcept;
  Buffer& operator=(Buffer&& other) noexcept;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  /// A host application's buffer that snell reads in place and never frees
  /// (the embedding API's vertex buffers): no memory of its own, not mapped.
  static Buffer borrow(Context& context, VkBuffer buffer, VkDeviceSize size, std::string name);

  VkBuffer handle() const { return buffer_; }
  VkDeviceSize size() const { return size_; }
  MemoryDomain domain() const { return domain_; }
  const std::string& name() const { return name_; }
  /// Host view of a mapped (Upload or Readback) buffer; empty for Device.
  std::span<std::byte> mapped() const { return {static_cast<std::byte*>(mapped_), mapped_ ? size_ : 0}; }
  /// The buffer's device address (BufferDesc::deviceAddress).
  VkDeviceAddress address() const;

 private:
  void release();
  Context* context_ = nullptr;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize size_ = 0;
  MemoryDomain domain_ = MemoryDomain::Device;
  void* mapped_ = nullptr;
  std::string name_;
  bool borrowed_ = false;
};

struct ImageDesc {
  uint32_t width = 1;
  uint32_t height = 1;
  VkFormat format = VK_FORMAT_R16G16B16A16_SFLOAT;
  VkImageUsageFlags usage =
      VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  std::string name;
  /// Its memory can be handed to another API (OpenGL, another Vulkan) as an
  /// opaque file descriptor (VK_KHR_external_memory_fd, which the context
  /// must have enabled): Image::exportMemory.
  bool exportable = false;
};

/// A device-local storage buffer (transfers both ways) of `bytes`, or of 16
/// where there are none: Vulkan has no empty buffers.
Buffer storageBuffer(Context& context, VkDeviceSize bytes, const std::string& name);

/// The aspect of an image of `format`: depth for D32_SFLOAT, else colour.
VkImageAspectFlags aspectOf(VkFormat format);

/// Bytes one pixel takes in a format snell uses (0 for one it does not).
uint32_t formatBytes(VkFormat format);

/// A 2D VkImage in device memory with a view of its one mip level.
class Image {
 public:
  Image() = default;
  Image(Context& context, const ImageDesc& desc);
  ~Image();
  Image(Image&& other) noexcept;
  Image& operator=(Image&& other) noexcept;
  Image(const Image&) = delete;
  Image& operator=(const Image&) = delete;

  VkImage handle() const { return image_; }
  VkImageView view() const { return view_; }
  VkFormat format() const { return format_; }
  uint32_t width() const { return width_; }
  uint32_t height() const { return height_; }
  const std::string& name() const { return name_; }
  /// Bytes one pixel takes in the formats snell uses.
  uint32_t bytesPerPixel() const;

  /// An exportable image's memory as a new file descriptor the caller owns
  /// (an importer takes it over); its size and whether it is a dedicated
  /// allocation, which an importer must state to match.
  int exportMemory() const;
  VkDeviceSize memorySize() const { return memorySize_; }
  bool dedicatedMemory() const { return dedicated_; }

 private:
  void allocateExportable(Context& context, const std::string& name);
  void release();
  Context* context_ = nullptr;
  VkImage image_ = VK_NULL_HANDLE;
  VkImageView view_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  uint32_t width_ = 0;
  uint32_t height_ = 0;
  std::string name_;
  VkDeviceSize memorySize_ = 0;
  bool dedicated_ = false;
};

/// A binary semaphore another API (OpenGL, another Vulkan) can wait on and
/// signal: exportable as an opaque file descriptor (VK_KHR_external_semaphore_fd).
class ExportableSemaphore {
 public:
  ExportableSemaphore() = default;
  /// Throws VulkanError where the context cannot export semaphores (exportsSemaphores).
  ExportableSemaphore(Context& context, const std::string& name);
  ~ExportableSemaphore();
  ExportableSemaphore(ExportableSemaphore&& other) noexcept;
  ExportableSemaphore& operator=(ExportableSemaphore&& other) noexcept;
  ExportableSemaphore(const ExportableSemaphore&) = delete;
  ExportableSemaphore& operator=(const ExportableSemaphore&) = delete;

  VkSemaphore handle() const { return semaphore_; }
  /// A new file descriptor the caller owns, which an importer takes over.
  int exportFd() const;

 private:
  void release();
  Context* context_ = nullptr;
  VkSemaphore semaphore_ = VK_NULL_HANDLE;
};

/// Whether `context` can export semaphores as opaque file descriptors: the
/// extension is enabled and the driver exports that handle type.
bool exportsSemaphores(const Context& context);

}  // namespace snell::vk
