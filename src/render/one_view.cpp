// One view rendered and read back (see one_view.h).
#include "render/one_view.h"

namespace snell::render {

namespace {

// One view, read back: what the two convenience calls below share.
RenderedFrame renderOneView(Renderer& renderer, const scene::Pose& pose, const ViewRequest& view,
                            std::vector<glm::vec4>* composite) {
  FrameRequest request;
  request.pose = &pose;
  request.views.push_back(view);
  request.readbacks.push_back({.view = 0});
  const FrameResult& result = renderer.wait(renderer.submit(request));
  RenderedFrame frame;
  frame.width = view.settings.width;
  frame.height = view.settings.height;
  frame.rgba = result.views.at(0).trace;
  frame.aov = result.views.at(0).aov;
  frame.droppedTriangles = result.stats.droppedTriangles;
  frame.passes = result.passes;
  frame.stats = result.stats;
  if (composite) *composite = result.views.at(0).composite;
  return frame;
}

}  // namespace

RenderedFrame renderFrame(Renderer& renderer, const scene::Pose& pose, const FrameSettings& settings, bool withAov) {
  ViewRequest view;
  view.settings = settings;
  view.aov = withAov;
  return renderOneView(renderer, pose, view, nullptr);
}

CompositeFrame renderComposite(Renderer& renderer, const scene::Pose& pose, const FrameSettings& settings,
                               const RasterOptions& options, bool withAov, bool masked) {
  ViewRequest view;
  view.settings = settings;
  view.output = ViewOutput::Composite;
  view.raster = options;
  view.masked = masked;
  view.aov = withAov;
  CompositeFrame frame;
  frame.trace = renderOneView(renderer, pose, view, &frame.rgba);
  return frame;
}

RefractionBake bakeRefraction(Renderer& renderer, const scene::Pose& pose, const FrameSettings& settings) {
  RenderedFrame frame = renderFrame(renderer, pose, settings, true);
  return bakeFromAov(frame.width, frame.height, frame.aov, renderer.scene());
}

}  // namespace snell::render
