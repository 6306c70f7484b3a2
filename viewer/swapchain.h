// The window's swapchain: created for the framebuffer's size, recreated when
// the window resizes or the surface reports it out of date, skipped while the
// window is minimised (a zero-sized framebuffer has no swapchain).
#pragma once

#include "vk/context.h"

#include <vulkan/vulkan.h>

#include <cstdint>
#include <optional>
#include <vector>

namespace snell::viewer {

class Swapchain {
 public:
  /// Takes ownership of `surface`.
  Swapchain(vk::Context& context, VkSurfaceKHR surface, bool vsync);
  ~Swapchain();
  Swapchain(const Swapchain&) = delete;
  Swapchain& operator=(const Swapchain&) = delete;

  /// Builds the swapchain for a framebuffer of width x height (the surface's
  /// own extent wins where it states one). False when there is nothing to
  /// draw to (minimised).
  bool recreate(uint32_t width, uint32_t height);
  bool valid() const { return swapchain_ != VK_NULL_HANDLE; }
  /// The next image, signalling `ready` when it may be written; nothing when
  /// the swapchain is out of date or no image came within 10 s (`ready` is
  /// then left alone: recreate, or skip the frame, and try again).
  std::optional<uint32_t> acquire(VkSemaphore ready);
  /// Queues image `index` once `renderDone(index)` is signalled. False when
  /// the swapchain should be recreated.
  bool present(uint32_t index);

  VkImage image(uint32_t index) const { return images_[index]; }
  VkSemaphore renderDone(uint32_t index) const { return renderDone_[index]; }
  VkExtent2D extent() const { return extent_; }
  /// The framebuffer size the swapchain was last built for (the surface may have chosen another extent).
  VkExtent2D requested() const { return requested_; }
  VkFormat format() const { return format_; }
  uint32_t imageCount() const { return uint32_t(images_.size()); }
  int recreations() const { return recreations_; }

 private:
  void destroy();
  vk::Context& context_;
  VkSurfaceKHR surface_;
  bool vsync_;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  std::vector<VkImage> images_;
  std::vector<VkSemaphore> renderDone_;  ///< one per image: present waits on the one its image signalled
  VkExtent2D extent_{0, 0}, requested_{0, 0};
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  int recreations_ = 0;
};

}  // namespace snell::viewer
