#include "render/frame_request.h"

#include "render/view_targets.h"

#include <stdexcept>
#include <string>

namespace snell::render {

void FrameRequest::check(const vk::Context& context, size_t drawItems) const {
  if (!pose) throw std::invalid_argument("renderer: a frame needs a pose");
  if (pose->items.size() != drawItems) {
    throw std::invalid_argument("renderer: the pose has " + std::to_string(pose->items.size()) +
                                " draw items; it was built for " + std::to_string(drawItems));
  }
  for (const ViewRequest& v : views) {
    checkImageSize(context, v.settings.width, v.settings.height);
    if (!v.settings.rays.empty() && v.settings.rays.size() != size_t(v.settings.width) * v.settings.height) {
      throw std::invalid_argument("renderer: " + std::to_string(v.settings.rays.size()) + " rays for " +
                                  std::to_string(size_t(v.settings.width) * v.settings.height) + " pixels");
    }
    if (!v.settings.rays.empty() && v.output != ViewOutput::Trace) {
      throw std::invalid_argument("renderer: ray lists have no raster image");
    }
  }
  for (const ReadbackRequest& r : readbacks) {
    if (r.view >= views.size()) {
      throw std::invalid_argument("renderer: a readback of view " + std::to_string(r.view) + " of " +
                                  std::to_string(views.size()));
    }
  }
}

}  // namespace snell::render
