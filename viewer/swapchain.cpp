// Swapchain creation with the surface's own rules for size, format and mode.
#include "swapchain.h"

#include "vk/error.h"

#include <algorithm>

namespace snell::viewer {

Swapchain::Swapchain(vk::Context& context, VkSurfaceKHR surface, bool vsync)
    : context_(context), surface_(surface), vsync_(vsync) {
  VkBool32 supported = VK_FALSE;
  VK_CHECK(vkGetPhysicalDeviceSurfaceSupportKHR(context.physicalDevice(), context.queueFamily(), surface, &supported));
  if (!supported) {
    vkDestroySurfaceKHR(context.instance(), surface, nullptr);
    throw vk::VulkanError(context.facts().name + " cannot present to this window from the queue snell uses; pick "
                          "another device with SNELL_DEVICE (see 'snell info --devices')");
  }
}

Swapchain::~Swapchain() {
  vkDeviceWaitIdle(context_.device());
  destroy();
  vkDestroySurfaceKHR(context_.instance(), surface_, nullptr);
}

void Swapchain::destroy() {
  for (VkSemaphore s : renderDone_) vkDestroySemaphore(context_.device(), s, nullptr);
  renderDone_.clear();
  if (swapchain_) vkDestroySwapchainKHR(context_.device(), swapchain_, nullptr);
  swapchain_ = VK_NULL_HANDLE;
  images_.clear();
}

bool Swapchain::recreate(uint32_t width, uint32_t height) {
  VkPhysicalDevice physical = context_.physicalDevice();
  VkSurfaceCapabilitiesKHR caps{};
  VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(physical, surface_, &caps));
  VkExtent2D extent = caps.currentExtent;
  if (extent.width == UINT32_MAX) {
    extent.width = std::clamp(width, caps.minImageExtent.width, caps.maxImageExtent.width);
    extent.height = std::clamp(height, caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  vkDeviceWaitIdle(context_.device());
  requested_ = {width, height};
  if (extent.width == 0 || extent.height == 0 || width == 0 || height == 0) {
    destroy();
    return false;
  }
  if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT)) {
    throw vk::VulkanError("the window's swapchain images cannot be copied to (no TRANSFER_DST usage)");
  }

  uint32_t count = 0;
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface_, &count, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(count);
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(physical, surface_, &count, formats.data()));
  // UNORM: the display pass writes sRGB-encoded values itself, and ImGui's colours are sRGB already.
  VkSurfaceFormatKHR chosen{VK_FORMAT_UNDEFINED, VK_COLOR_SPACE_SRGB_NONLINEAR_KHR};
  for (const VkSurfaceFormatKHR& f : formats) {
    VkFormatProperties properties{};
    vkGetPhysicalDeviceFormatProperties(physical, f.format, &properties);
    if ((f.format == VK_FORMAT_B8G8R8A8_UNORM || f.format == VK_FORMAT_R8G8B8A8_UNORM) &&
        f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR &&
        (properties.optimalTilingFeatures & VK_FORMAT_FEATURE_BLIT_DST_BIT)) {
      chosen = f;
      break;
    }
  }
  // An sRGB swapchain would encode the display pass's sRGB values a second time.
  if (chosen.format == VK_FORMAT_UNDEFINED) {
    throw vk::VulkanError("the window offers no 8-bit UNORM sRGB-display format snell can copy to; try --offscreen");
  }
  VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(physical, surface_, &count, nullptr));
  std::vector<VkPresentModeKHR> modes(count);
  VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(physical, surface_, &count, modes.data()));
  VkPresentModeKHR mode = VK_PRESENT_MODE_FIFO_KHR;  // always there: vsync
  if (!vsync_) {
    for (VkPresentModeKHR wanted : {VK_PRESENT_MODE_MAILBOX_KHR, VK_PRESENT_MODE_IMMEDIATE_KHR}) {
      if (std::find(modes.begin(), modes.end(), wanted) != modes.end()) {
        mode = wanted;
        break;
      }
    }
  }

  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = surface_;
  info.minImageCount = std::max(caps.minImageCount, 2u);
  if (caps.maxImageCount) info.minImageCount = std::min(info.minImageCount + 1, caps.maxImageCount);
  info.imageFormat = chosen.format;
  info.imageColorSpace = chosen.colorSpace;
  info.imageExtent = extent;
  info.imageArrayLayers = 1;
  info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = (caps.supportedCompositeAlpha & VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR)
                            ? VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR
                            : VkCompositeAlphaFlagBitsKHR(caps.supportedCompositeAlpha & -caps.supportedCompositeAlpha);
  info.presentMode = mode;
  info.clipped = VK_TRUE;
  info.oldSwapchain = swapchain_;
  VkSwapchainKHR created = VK_NULL_HANDLE;
  VK_CHECK(vkCreateSwapchainKHR(context_.device(), &info, nullptr, &created));
  destroy();
  swapchain_ = created;
  VK_CHECK(vkGetSwapchainImagesKHR(context_.device(), swapchain_, &count, nullptr));
  images_.resize(count);
  VK_CHECK(vkGetSwapchainImagesKHR(context_.device(), swapchain_, &count, images_.data()));
  for (uint32_t i = 0; i < count; ++i) {
    VkSemaphoreCreateInfo semaphoreInfo{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore s = VK_NULL_HANDLE;
    VK_CHECK(vkCreateSemaphore(context_.device(), &semaphoreInfo, nullptr, &s));
    renderDone_.push_back(s);
  }
  extent_ = extent;
  format_ = chosen.format;
  ++recreations_;
  return true;
}

std::optional<uint32_t> Swapchain::acquire(VkSemaphore ready) {
  if (!swapchain_) return std::nullopt;
  uint32_t index = 0;
  constexpr uint64_t kTimeoutNs = 10ull * 1000 * 1000 * 1000;
  VkResult result = vkAcquireNextImageKHR(context_.device(), swapchain_, kTimeoutNs, ready, VK_NULL_HANDLE, &index);
  if (result == VK_ERROR_OUT_OF_DATE_KHR || result == VK_TIMEOUT || result == VK_NOT_READY) return std::nullopt;
  if (result != VK_SUBOPTIMAL_KHR) VK_CHECK(result);  // suboptimal still signals `ready`: use it, recreate after
  return index;
}

bool Swapchain::present(uint32_t index) {
  VkPresentInfoKHR info{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
  info.waitSemaphoreCount = 1;
  info.pWaitSemaphores = &renderDone_[index];
  info.swapchainCount = 1;
  info.pSwapchains = &swapchain_;
  info.pImageIndices = &index;
  VkResult result = vkQueuePresentKHR(context_.queue(), &info);
  if (result == VK_ERROR_OUT_OF_DATE_KHR || result == VK_SUBOPTIMAL_KHR) return false;
  VK_CHECK(result);
  return true;
}

}  // namespace snell::viewer
