// Each view's images, ray list and readback buffers (see view_targets.h).
#include "render/view_targets.h"

#include "render/raster_pass.h"

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

namespace snell::render {

namespace {

constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

// The masked trace's list: a header, then one word a pixel.
VkDeviceSize pixelListBytes(uint64_t pixels) { return sizeof(gpu::TracePixelListHeader) + pixels * 4; }

// Readback buffers that sizes left behind, kept for the next frames.
constexpr size_t kSpareReadbacks = 4;

std::vector<glm::vec4> unpackHalves(const uint16_t* halves, size_t pixels) {
  std::vector<glm::vec4> rgba(pixels);
  for (size_t i = 0; i < pixels; ++i) {
    for (int c = 0; c < 4; ++c) rgba[i][c] = glm::unpackHalf1x16(halves[4 * i + size_t(c)]);
  }
  return rgba;
}

}  // namespace

std::vector<bool> ViewTargets::prepare(const std::vector<ViewRequest>& requests) {
  if (views_.size() < requests.size()) views_.resize(requests.size());
  std::vector<bool> lost(requests.size(), false);
  for (size_t i = 0; i < requests.size(); ++i) {
    const ViewRequest& r = requests[i];
    View& v = views_[i];
    ViewImages& im = v.images;
    const uint32_t w = r.settings.width, h = r.settings.height;
    if (im.width != w || im.height != h) v = View{};
    const bool composite = r.output == ViewOutput::Composite, rays = !r.settings.rays.empty();
    const std::string name = "view " + std::to_string(i);
    const uint64_t pixels = uint64_t(w) * h;
    uint64_t needed = 0;
    if (!im.trace.handle()) needed += pixels * vk::formatBytes(kTraceFormat);
    if (composite && !im.composite.handle()) {
      needed += pixels * (vk::formatBytes(kCompositeFormat) + vk::formatBytes(kDepthFormat) +
                          vk::formatBytes(kMaskFormat)) + pixelListBytes(pixels);
    }
    if (r.aov && !im.aov.handle()) needed += pixels * sizeof(gpu::TraceAov);
    if (rays && !v.rays.handle()) needed += pixels * sizeof(gpu::GpuRay);
    if (needed) context_.checkFits(needed, name + " at " + std::to_string(w) + "x" + std::to_string(h));
    im.width = w;
    im.height = h;
    if (!im.trace.handle()) {
      // A colour attachment too: the screen-space methods draw what lies behind the glass into it.
      im.trace = vk::Image(context_, {w, h, kTraceFormat,
                                      VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                          VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT,
                                      name + " trace"});
      v.fresh = lost[i] = true;
    }
    if (composite && !im.composite.handle()) {
      im.composite = vk::Image(context_, {w, h, kCompositeFormat,
                                          VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                              VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                          name + " composite"});
      im.depth = vk::Image(context_, {w, h, kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, name + " depth"});
      im.mask = vk::Image(context_, {w, h, kMaskFormat,
                                     VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                         VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                     name + " transmissive mask"});
      im.pixels = vk::Buffer(context_, {pixelListBytes(pixels), kStorage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT,
                                        vk::MemoryDomain::Device, name + " pixels to trace"});
      v.fresh = lost[i] = true;
    }
    if (r.aov && !im.aov.handle()) {
      im.aov = vk::Buffer(context_, {pixels * sizeof(gpu::TraceAov), kStorage, vk::MemoryDomain::Device, name + " AOV"});
      lost[i] = true;
    }
    if (rays && !v.rays.handle()) {
      v.rays = vk::Buffer(context_, {pixels * sizeof(gpu::GpuRay), kStorage, vk::MemoryDomain::Device, name + " rays"});
    }
  }
  return lost;
}

std::vector<const vk::Image*> ViewTargets::takeNewImages() {
  std::vector<const vk::Image*> images;
  for (View& v : views_) {
    if (!v.fresh) continue;
    for (const vk::Image* image : {&v.images.trace, &v.images.composite, &v.images.depth, &v.images.mask}) {
      if (image->handle()) images.push_back(image);
    }
    v.fresh = false;
  }
  return images;
}

PendingReadback ViewTargets::recordReadback(vk::Commands& commands, size_t index, const ViewRequest& view,
                                            const ReadbackRequest& request) {
  PendingReadback r;
  r.request = request;
  r.width = view.settings.width;
  r.height = view.settings.height;
  r.composite = view.output == ViewOutput::Composite;
  r.trace = !r.composite || request.trace;
  r.aov = view.aov;
  const VkDeviceSize pixels = VkDeviceSize(r.width) * r.height;
  r.compositeAt = r.trace ? pixels * vk::formatBytes(kTraceFormat) : 0;
  r.aovAt = r.compositeAt + (r.composite ? pixels * vk::formatBytes(kCompositeFormat) : 0);
  r.buffer = takeReadbackBuffer(r.aovAt + (r.aov ? pixels * sizeof(gpu::TraceAov) : 0), index);
  const ViewImages& im = images(index);
  if (r.trace) commands.copyImageToBuffer(im.trace, r.buffer, 0);
  if (r.composite) commands.copyImageToBuffer(im.composite, r.buffer, r.compositeAt);
  if (r.aov) commands.copyBuffer(im.aov, r.buffer, pixels * sizeof(gpu::TraceAov), 0, r.aovAt);
  return r;
}

ViewPixels ViewTargets::finishReadback(PendingReadback&& r) {
  ViewPixels v;
  v.width = r.width;
  v.height = r.height;
  const size_t pixels = size_t(r.width) * r.height;
  const std::byte* bytes = r.buffer.mapped().data();
  const auto* trace = reinterpret_cast<const uint16_t*>(bytes);
  const auto* composite = reinterpret_cast<const uint16_t*>(bytes + r.compositeAt);
  if (r.request.half) {
    if (r.trace) v.traceHalf.assign(trace, trace + 4 * pixels);
    if (r.composite) v.compositeHalf.assign(composite, composite + 4 * pixels);
  } else {
    if (r.trace) v.trace = unpackHalves(trace, pixels);
    if (r.composite) v.composite = unpackHalves(composite, pixels);
  }
  if (r.aov) {
    v.aov.resize(pixels);
    std::memcpy(v.aov.data(), bytes + r.aovAt, pixels * sizeof(gpu::TraceAov));
  }
  giveBack(std::move(r.buffer));
  return v;
}

vk::Buffer ViewTargets::takeReadbackBuffer(VkDeviceSize bytes, size_t view) {
  auto spare = std::find_if(spareReadbacks_.begin(), spareReadbacks_.end(),
                            [&](const vk::Buffer& b) { return b.size() >= bytes; });
  if (spare != spareReadbacks_.end()) {
    vk::Buffer buffer = std::move(*spare);
    spareReadbacks_.erase(spare);
    return buffer;
  }
  return vk::Buffer(context_, {bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryDomain::Readback,
                               "view " + std::to_string(view) + " readback"});
}

void ViewTargets::giveBack(vk::Buffer buffer) {
  spareReadbacks_.push_back(std::move(buffer));
  if (spareReadbacks_.size() > kSpareReadbacks) {
    spareReadbacks_.erase(spareReadbacks_.begin(), spareReadbacks_.end() - kSpareReadbacks);
  }
}

void checkImageSize(const vk::Context& context, uint32_t width, uint32_t height) {
  if (width == 0 || height == 0) throw std::invalid_argument("the image size must be at least 1x1");
  uint32_t limit = 16384;  // maxImageDimension2D every Vulkan 1.3 device offers at least 4096; snell caps here
  VkPhysicalDeviceProperties properties;
  vkGetPhysicalDeviceProperties(context.physicalDevice(), &properties);
  limit = std::min(limit, properties.limits.maxImageDimension2D);
  if (width > limit || height > limit) {
    throw std::invalid_argument("the image size " + std::to_string(width) + "x" + std::to_string(height) +
                                " exceeds this device's limit of " + std::to_string(limit) + " pixels a side");
  }
}

}  // namespace snell::render
