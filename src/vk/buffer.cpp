// Buffer and image allocation: one VkDeviceMemory each, which is plenty for a
// renderer with a few dozen long-lived resources.
#include "vk/buffer.h"

#include "vk/error.h"

#include <utility>
#include <stdexcept>

namespace snell::vk {

namespace {

VkDeviceMemory allocate(Context& context, const VkMemoryRequirements& needs, MemoryDomain domain, const std::string& name,
                        bool deviceAddress = false, const void* next = nullptr) {
  VkMemoryPropertyFlags required = 0;
  VkMemoryPropertyFlags preferred = 0;
  switch (domain) {
    case MemoryDomain::Device:
      required = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
      break;
    case MemoryDomain::Upload:
      required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
      break;
    case MemoryDomain::Readback:
      required = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
      preferred = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
      break;
  }
  uint32_t type = context.findMemoryType(needs.memoryTypeBits, required, preferred);
  if (type == UINT32_MAX && domain == MemoryDomain::Device) {
    type = context.findMemoryType(needs.memoryTypeBits, 0, 0);  // a device with no device-local heap
  }
  if (type == UINT32_MAX) throw VulkanError("no memory type suits '" + name + "'");
  if (context.caps().maxMemoryAllocationSize && needs.size > context.caps().maxMemoryAllocationSize) {
    throw VulkanError("'" + name + "' needs " + std::to_string(needs.size) + " bytes, more than the device's " +
                      std::to_string(context.caps().maxMemoryAllocationSize) + "-byte allocation limit");
  }
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  flags.pNext = next;
  info.pNext = deviceAddress ? &flags : next;
  info.allocationSize = needs.size;
  info.memoryTypeIndex = type;
  VkDeviceMemory memory = context.allocateMemory(info, name);
  context.setName(VK_OBJECT_TYPE_DEVICE_MEMORY, memory, name);
  return memory;
}

}  // namespace

Buffer::Buffer(Context& context, const BufferDesc& desc)
    : context_(&context), size_(desc.size), domain_(desc.domain), name_(desc.name) {
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = desc.size ? desc.size : 16;  // Vulkan forbids empty buffers
  info.usage = desc.usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkResult created = vkCreateBuffer(context.device(), &info, nullptr, &buffer_);
  if (created != VK_SUCCESS) {
    throw VulkanError("creating buffer '" + desc.name + "' of " + std::to_string(desc.size) + " bytes failed with " +
                          std::string(resultName(created)),
                      created);
  }
  try {
    VkMemoryRequirements needs{};
    vkGetBufferMemoryRequirements(context.device(), buffer_, &needs);
    if (desc.deviceAddress && !context.caps().bufferDeviceAddress) {
      throw VulkanError("buffer '" + desc.name + "' asks for a device address, which this context was created without");
    }
    memory_ = allocate(context, needs, desc.domain, desc.name, desc.deviceAddress);
    VK_CHECK(vkBindBufferMemory(context.device(), buffer_, memory_, 0));
    if (desc.domain != MemoryDomain::Device) VK_CHECK(vkMapMemory(context.device(), memory_, 0, VK_WHOLE_SIZE, 0, &mapped_));
  } catch (...) {
    release();
    throw;
  }
  context.setName(VK_OBJECT_TYPE_BUFFER, buffer_, desc.name);
}

Buffer::~Buffer() { release(); }

Buffer::Buffer(Buffer&& other) noexcept { *this = std::move(other); }

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    release();
    context_ = std::exchange(other.context_, nullptr);
    buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    size_ = std::exchange(other.size_, 0);
    domain_ = other.domain_;
    mapped_ = std::exchange(other.mapped_, nullptr);
    name_ = std::move(other.name_);
    borrowed_ = std::exchange(other.borrowed_, false);
  }
  return *this;
}

Buffer Buffer::borrow(Context& context, VkBuffer buffer, VkDeviceSize size, std::string name) {
  if (!buffer) throw std::invalid_argument("borrowing buffer '" + name + "': the handle is null");
  Buffer b;
  b.context_ = &context;
  b.buffer_ = buffer;
  b.size_ = size;
  b.name_ = std::move(name);
  b.borrowed_ = true;
  return b;
}

void Buffer::release() {
  if (!context_) return;
  if (borrowed_) {  // the host frees its own buffer
    buffer_ = VK_NULL_HANDLE;
    context_ = nullptr;
    borrowed_ = false;
    return;
  }
  VkDevice device = context_->device();
  VkBuffer buffer = std::exchange(buffer_, VK_NULL_HANDLE);
  VkDeviceMemory memory = std::exchange(memory_, VK_NULL_HANDLE);
  mapped_ = nullptr;
  Context* context = context_;
  context_->retire([context, device, buffer, memory] {
    if (buffer) vkDestroyBuffer(device, buffer, nullptr);
    context->freeMemory(memory);  // unmaps implicitly
  });
  context_ = nullptr;
}

VkDeviceAddress Buffer::address() const {
  VkBufferDeviceAddressInfo info{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  info.buffer = buffer_;
  return vkGetBufferDeviceAddress(context_->device(), &info);
}

VkImageAspectFlags aspectOf(VkFormat format) {
  return format == VK_FORMAT_D32_SFLOAT ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
}

Image::Image(Context& context, const ImageDesc& desc)
    : context_(&context), format_(desc.format), width_(desc.width), height_(desc.height), name_(desc.name) {
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = desc.format;
  info.extent = {desc.width, desc.height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = desc.usage;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkExternalMemoryImageCreateInfo external{VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_IMAGE_CREATE_INFO};
  external.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  if (desc.exportable) info.pNext = &external;
  VkImageFormatProperties limits{};
  VkResult supported = vkGetPhysicalDeviceImageFormatProperties(context.physicalDevice(), info.format, info.imageType,
                                                                info.tiling, info.usage, 0, &limits);
  if (supported != VK_SUCCESS || desc.width == 0 || desc.height == 0 || desc.width > limits.maxExtent.width ||
      desc.height > limits.maxExtent.height) {
    throw VulkanError("image '" + desc.name + "' of " + std::to_string(desc.width) + "x" + std::to_string(desc.height) +
                          " is not supported by this device (largest: " + std::to_string(limits.maxExtent.width) + "x" +
                          std::to_string(limits.maxExtent.height) + ")",
                      supported);
  }
  VK_CHECK(vkCreateImage(context.device(), &info, nullptr, &image_));
  try {
    if (desc.exportable) {
      allocateExportable(context, desc.name);
    } else {
      VkMemoryRequirements needs{};
      vkGetImageMemoryRequirements(context.device(), image_, &needs);
      memory_ = allocate(context, needs, MemoryDomain::Device, desc.name);
      memorySize_ = needs.size;
    }
    VK_CHECK(vkBindImageMemory(context.device(), image_, memory_, 0));
    VkImageViewCreateInfo viewInfo{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    viewInfo.image = image_;
    viewInfo.viewType = VK_IMAGE_VIEW_TYPE_2D;
    viewInfo.format = desc.format;
    viewInfo.subresourceRange = {aspectOf(desc.format), 0, 1, 0, 1};
    VK_CHECK(vkCreateImageView(context.device(), &viewInfo, nullptr, &view_));
  } catch (...) {
    release();
    throw;
  }
  context.setName(VK_OBJECT_TYPE_IMAGE, image_, desc.name);
  context.setName(VK_OBJECT_TYPE_IMAGE_VIEW, view_, desc.name + " view");
}

// Exported memory is allocated for export, and on its own where the driver
// prefers it (an importer must say the same of it).
void Image::allocateExportable(Context& context, const std::string& name) {
  VkMemoryDedicatedRequirements dedicatedNeeds{VK_STRUCTURE_TYPE_MEMORY_DEDICATED_REQUIREMENTS};
  VkMemoryRequirements2 needs{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2, &dedicatedNeeds};
  VkImageMemoryRequirementsInfo2 which{VK_STRUCTURE_TYPE_IMAGE_MEMORY_REQUIREMENTS_INFO_2};
  which.image = image_;
  vkGetImageMemoryRequirements2(context.device(), &which, &needs);
  dedicated_ = dedicatedNeeds.prefersDedicatedAllocation || dedicatedNeeds.requiresDedicatedAllocation;
  VkMemoryDedicatedAllocateInfo dedicatedInfo{VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO};
  dedicatedInfo.image = image_;
  VkExportMemoryAllocateInfo exportInfo{VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO, dedicated_ ? &dedicatedInfo : nullptr};
  exportInfo.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  memory_ = allocate(context, needs.memoryRequirements, MemoryDomain::Device, name, false, &exportInfo);
  memorySize_ = needs.memoryRequirements.size;
}

int Image::exportMemory() const {
  auto getFd = context_->deviceFunction<PFN_vkGetMemoryFdKHR>("vkGetMemoryFdKHR");
  VkMemoryGetFdInfoKHR info{VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR};
  info.memory = memory_;
  info.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
  int fd = -1;
  VK_CHECK(getFd(context_->device(), &info, &fd));
  return fd;
}

Image::~Image() { release(); }

Image::Image(Image&& other) noexcept { *this = std::move(other); }

Image& Image::operator=(Image&& other) noexcept {
  if (this != &other) {
    release();
    context_ = std::exchange(other.context_, nullptr);
    image_ = std::exchange(other.image_, VK_NULL_HANDLE);
    view_ = std::exchange(other.view_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    format_ = other.format_;
    width_ = other.width_;
    height_ = other.height_;
    name_ = std::move(other.name_);
    memorySize_ = other.memorySize_;
    dedicated_ = other.dedicated_;
  }
  return *this;
}

void Image::release() {
  if (!context_) return;
  VkDevice device = context_->device();
  VkImage image = std::exchange(image_, VK_NULL_HANDLE);
  VkImageView view = std::exchange(view_, VK_NULL_HANDLE);
  VkDeviceMemory memory = std::exchange(memory_, VK_NULL_HANDLE);
  Context* context = context_;
  context_->retire([context, device, image, view, memory] {
    if (view) vkDestroyImageView(device, view, nullptr);
    if (image) vkDestroyImage(device, image, nullptr);
    context->freeMemory(memory);
  });
  context_ = nullptr;
}

ExportableSemaphore::ExportableSemaphore(Context& context, const std::string& name) : context_(&context) {
  if (!exportsSemaphores(context)) {
    throw VulkanError(context.facts().name + " cannot export semaphores as file descriptors (VK_KHR_external_semaphore_fd)");
  }
  VkExportSemaphoreCreateInfo exportInfo{VK_STRUCTURE_TYPE_EXPORT_SEMAPHORE_CREATE_INFO};
  exportInfo.handleTypes = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
  VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &exportInfo};
  VK_CHECK(vkCreateSemaphore(context.device(), &info, nullptr, &semaphore_));
  context.setName(VK_OBJECT_TYPE_SEMAPHORE, semaphore_, name);
}

ExportableSemaphore::~ExportableSemaphore() { release(); }

ExportableSemaphore::ExportableSemaphore(ExportableSemaphore&& other) noexcept { *this = std::move(other); }

ExportableSemaphore& ExportableSemaphore::operator=(ExportableSemaphore&& other) noexcept {
  if (this != &other) {
    release();
    context_ = std::exchange(other.context_, nullptr);
    semaphore_ = std::exchange(other.semaphore_, VK_NULL_HANDLE);
  }
  return *this;
}

void ExportableSemaphore::release() {
  if (!context_) return;
  VkDevice device = context_->device();
  VkSemaphore semaphore = std::exchange(semaphore_, VK_NULL_HANDLE);
  if (semaphore) context_->retire([device, semaphore] { vkDestroySemaphore(device, semaphore, nullptr); });
  context_ = nullptr;
}

int ExportableSemaphore::exportFd() const {
  auto getFd = context_->deviceFunction<PFN_vkGetSemaphoreFdKHR>("vkGetSemaphoreFdKHR");
  VkSemaphoreGetFdInfoKHR info{VK_STRUCTURE_TYPE_SEMAPHORE_GET_FD_INFO_KHR};
  info.semaphore = semaphore_;
  info.handleType = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
  int fd = -1;
  VK_CHECK(getFd(context_->device(), &info, &fd));
  return fd;
}

bool exportsSemaphores(const Context& context) {
  if (!context.enabled(VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME)) return false;
  VkPhysicalDeviceExternalSemaphoreInfo info{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_SEMAPHORE_INFO};
  info.handleType = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
  VkExternalSemaphoreProperties properties{VK_STRUCTURE_TYPE_EXTERNAL_SEMAPHORE_PROPERTIES};
  vkGetPhysicalDeviceExternalSemaphoreProperties(context.physicalDevice(), &info, &properties);
  return (properties.externalSemaphoreFeatures & VK_EXTERNAL_SEMAPHORE_FEATURE_EXPORTABLE_BIT) != 0;
}

Buffer storageBuffer(Context& context, VkDeviceSize bytes, const std::string& name) {
  return Buffer(context, {std::max<VkDeviceSize>(bytes, 16), BufferDesc{}.usage, MemoryDomain::Device, name});
}

uint32_t formatBytes(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB:
    case VK_FORMAT_B8G8R8A8_UNORM:
    case VK_FORMAT_B8G8R8A8_SRGB:
    case VK_FORMAT_D32_SFLOAT:
    case VK_FORMAT_R32_UINT:
    case VK_FORMAT_R32_SFLOAT:
      return 4;
    case VK_FORMAT_R16G16B16A16_SFLOAT:
      return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT:
      return 16;
    default:
      return 0;
  }
}

uint32_t Image::bytesPerPixel() const {
  uint32_t bytes = formatBytes(format_);
  if (bytes == 0) throw std::invalid_argument("image '" + name_ + "' has a format snell cannot size");
  return bytes;
}

}  // namespace snell::vk
