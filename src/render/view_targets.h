// What each view of a frame draws into: its images at the view's size, its
// ray list, and the host buffers its pixels come back in. They are made when
// a frame first needs them and kept for the next; what a frame would add is
// refused whole, before any of it is allocated, where the device cannot hold it.
#pragma once

#include "render/frame_request.h"
#include "shared/trace.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"

#include <cstdint>
#include <vector>

namespace snell::render {

/// The trace image's format: what the trace writes and the raster pass reads.
inline constexpr VkFormat kTraceFormat = VK_FORMAT_R16G16B16A16_SFLOAT;

/// The images of one view; they keep the last frame's result until the next frame that renders the view.
struct ViewImages {
  uint32_t width = 0, height = 0;
  vk::Image trace;           ///< kTraceFormat, storage
  vk::Image composite;       ///< kCompositeFormat (composite views)
  vk::Image depth, mask;     ///< the pre-pass's (composite views)
  vk::Buffer pixels;         ///< the masked trace's pixel list
  vk::Buffer aov;            ///< gpu::TraceAov per pixel, when asked for
};

/// A view's images on their way back to the host, in a buffer of the frame.
struct PendingReadback {
  ReadbackRequest request;
  uint32_t width = 0, height = 0;
  bool trace = false, composite = false, aov = false;
  VkDeviceSize compositeAt = 0, aovAt = 0;  ///< where they lie in `buffer` (the trace image at 0)
  vk::Buffer buffer;
};

/// Checks a requested image size against the device: throws
/// std::invalid_argument saying what is wrong.
void checkImageSize(const vk::Context& context, uint32_t width, uint32_t height);

class ViewTargets {
 public:
  explicit ViewTargets(vk::Context& context) : context_(context) {}

  /// Makes what each view draws into at its size (a view whose size changed
  /// starts afresh). Returns, per view, whether what it last drew is gone
  /// (new images, or an AOV buffer it did not have): it must be drawn again.
  std::vector<bool> prepare(const std::vector<ViewRequest>& views);
  ViewImages& images(size_t view) { return views_.at(view).images; }
  const ViewImages& images(size_t view) const { return views_.at(view).images; }
  const vk::Buffer& rays(size_t view) const { return views_.at(view).rays; }
  /// Images made since the last call: they start UNDEFINED, and the frame moves them to GENERAL.
  std::vector<const vk::Image*> takeNewImages();

  /// Records the copies of view `index`'s images (and AOV) into a host
  /// buffer; the frame's writes to them must already be visible to transfers.
  PendingReadback recordReadback(vk::Commands& commands, size_t index, const ViewRequest& view,
                                 const ReadbackRequest& request);
  /// The pixels of a readback whose frame is done; its buffer is kept for later frames.
  ViewPixels finishReadback(PendingReadback&& readback);

 private:
  struct View {
    ViewImages images;
    vk::Buffer rays;
    bool fresh = false;  ///< images made since the last takeNewImages
  };
  vk::Context& context_;
  /// A host buffer of at least `bytes` for a readback; one given back earlier is reused.
  vk::Buffer takeReadbackBuffer(VkDeviceSize bytes, size_t view);
  /// A readback buffer whose frame is done, for later frames.
  void giveBack(vk::Buffer buffer);

  std::vector<View> views_;
  /// A fresh mapped allocation a frame costs the host more than the copy: spare ones are kept.
  std::vector<vk::Buffer> spareReadbacks_;
};

}  // namespace snell::render
