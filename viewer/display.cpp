// What a frame asks of the GPU: per viewport shown, a composite view drawn
// with the chosen method (refraction-map's maps baked first when due); then
// the display pass (heat map, film gate, active outline) onto the window
// image, the overlay over it, and the copies to the swapchain image and, for
// a screenshot, to the host.
#include "viewer_state.h"

#include "bake/refraction_bake.h"
#include "render/method.h"
#include "shared/present.h"

#include <imgui.h>

#include <algorithm>
#include <cstddef>
#include <cstdio>

namespace snell::viewer {

// present.comp reads the push constants with std430 rules (the viewer's own
// layout, so its check lives here rather than in render/layout_checks.cpp).
static_assert(sizeof(gpu::PresentPush) == 48 && offsetof(gpu::PresentPush, gate) == 16 &&
              offsetof(gpu::PresentPush, flags) == 32);

// A shown viewport's view in the frame request (frameRequest): viewports
// without a size have none.
static size_t viewIndexOf(const std::vector<Viewport>& viewports, size_t viewport) {
  size_t index = 0;
  for (size_t i = 0; i < viewport; ++i) index += viewports[i].width ? 1 : 0;
  return index;
}

// refraction-map's maps, baked by the trace at the pose and views of now
// for viewports that have none of their size (or all, after B); the renderer
// keeps them, one per view, as the scene and the camera move on.
void Viewer::bakeRefractionMaps() {
  bool wanted = toggles_.refraction && toggles_.method == render::Method::RefractionMap;
  if (!wanted) {
    rebake_ = false;
    return;
  }
  std::vector<size_t> due;
  for (size_t i = 0; i < viewports_.size(); ++i) {
    const Viewport& vp = viewports_[i];
    if (!vp.width) continue;
    const render::RefractionMapBuffer& map = renderer_->refractionMap(viewIndexOf(viewports_, i));
    if (rebake_ || map.width != vp.width || map.height != vp.height) due.push_back(i);
  }
  rebake_ = false;
  if (due.empty()) return;
  if (pendingFrame_) noteFrame(renderer_->wait(pendingFrame_), pendingCpuMs_);
  pendingFrame_ = 0;
  for (size_t i : due) {
    const Viewport& vp = viewports_[i];
    render::FrameSettings settings{vp.width, vp.height, viewOf(vp), glm::vec3(scene::kDefaultBackground), gpu::kDefaultMaxInterfaces};
    render::RefractionBake baked = renderer_->bakeRefractionMap(pose_, settings, viewIndexOf(viewports_, i));
    char when[32];
    std::snprintf(when, sizeof when, "%.2f s", pose_.time);
    message_ = "refraction map baked at " + std::string(when) + ": " + bake::describe(baked, *scene_);
  }
}

// The frame the renderer runs: one composite view per viewport shown, then
// the display pass, the overlay and the copy to the swapchain (or screenshot).
render::FrameRequest Viewer::frameRequest(std::optional<uint32_t> swapImage, bool screenshot) {
  render::FrameRequest request;
  request.pose = &pose_;
  for (const Viewport& vp : viewports_) {
    if (!vp.width) continue;
    render::FrameSettings settings{vp.width, vp.height, viewOf(vp), glm::vec3(scene::kDefaultBackground), gpu::kDefaultMaxInterfaces};
    render::RasterOptions raster;
    raster.wireframe = toggles_.wireframe;
    render::ViewRequest view =
        render::methodViewport(toggles_.refraction ? toggles_.method : render::Method::None, settings, raster);
    // The heat map counts nodes for every pixel, so it traces them all.
    view.masked = view.masked && !toggles_.heatMap;
    view.aov = toggles_.heatMap;
    request.views.push_back(view);
  }
  request.record = [this, swapImage, screenshot](vk::Commands& commands) { recordDisplay(commands, swapImage, screenshot); };
  if (swapImage) {
    request.waitSemaphore = imageReady_;
    request.waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;  // the copy to the swapchain image starts after the acquire
    request.signalSemaphore = swapchain_->renderDone(*swapImage);
  }
  return request;
}

void Viewer::recordDisplay(vk::Commands& commands, std::optional<uint32_t> swapImage, bool screenshot) {
  if (freshImages_) {
    commands.imageLayout(windowImage_, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    freshImages_ = false;
  }
  std::vector<gpu::PresentPush> pushes;
  for (size_t i = 0; i < viewports_.size(); ++i) {
    const Viewport& vp = viewports_[i];
    if (!vp.width) continue;
    scene::View view = viewOf(vp);
    gpu::PresentPush push{};
    push.area = glm::uvec4(vp.x, 0, vp.width, vp.height);
    // The film gate: the camera's frame at zoom 1 (its glTF aspect ratio, else
    // the viewport's), moved and scaled with the film back like the picture.
    double aspect = double(vp.width) / double(vp.height);
    double gateAspect = aspect;
    if (vp.rig.sceneCamera >= 0 && scene_->cameras[size_t(vp.rig.sceneCamera)].aspectRatio > 0.0f) {
      gateAspect = scene_->cameras[size_t(vp.rig.sceneCamera)].aspectRatio;
    }
    double h0 = view.halfHeight * vp.rig.filmZoom;  // the half height at zoom 1
    double gh = h0, gw = h0 * gateAspect;  // the trace keeps the camera's vertical field of view
    auto px = [&](double slope) { return (0.5 + 0.5 * (slope - view.shift.x) / (view.halfHeight * aspect)) * vp.width; };
    auto py = [&](double slope) { return (0.5 - 0.5 * (slope - view.shift.y) / view.halfHeight) * vp.height; };
    push.gate = glm::vec4(float(px(-gw)), float(py(gh)), float(px(gw)), float(py(-gh)));
    push.flags = (toggles_.heatMap ? gpu::kPresentFlagHeatMap : 0u) | (toggles_.gate ? gpu::kPresentFlagGate : 0u) |
                 (toggles_.split && toggles_.ui && i == active_ ? gpu::kPresentFlagActive : 0u);
    push.heatMax = toggles_.heatMax;
    pushes.push_back(push);
  }
  // The composites (raster) and the heat maps' node counts (trace) reach the display pass.
  commands.barrier(VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                   VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                   VK_ACCESS_SHADER_READ_BIT);
  commands.beginPass("display");
  size_t p = 0;
  for (const Viewport& vp : viewports_) {
    if (!vp.width) continue;
    const render::ViewImages& images = renderer_->viewImages(p);
    present_->dispatchThreads(commands,
                              {{gpu::kPresentBindingComposite, nullptr, &images.composite},
                               {gpu::kPresentBindingAov, toggles_.heatMap ? &images.aov : &placeholderAov_},
                               {gpu::kPresentBindingOutput, nullptr, &windowImage_}},
                              pushes[p], uint64_t(vp.width) * vp.height);
    ++p;
  }
  commands.endPass();
  if (toggles_.ui) {
    commands.barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                     VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
    commands.beginPass("ui");
    ui_->render(commands, windowImage_);
    commands.endPass();
  } else {
    ImGui::EndFrame();
  }
  // Whatever wrote the window image last, the copies below read it next.
  if (!screenshot && !swapImage) return;
  commands.imageLayout(windowImage_, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  VkCommandBuffer cmd = commands.handle();
  if (screenshot) {
    VkBufferImageCopy region{};
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.imageExtent = {windowImage_.width(), windowImage_.height(), 1};
    vkCmdCopyImageToBuffer(cmd, windowImage_.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, screenshotBuffer_.handle(),
                           1, &region);
    commands.transferToHost();
  }
  if (swapImage) {
    VkImage target = swapchain_->image(*swapImage);
    // The acquire semaphore is waited for at the transfer stage: the copy starts after it.
    commands.imageBarrier(target, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                          VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_TRANSFER_BIT, 0,
                          VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT);
    VkExtent2D extent = swapchain_->extent();
    VkImageBlit blit{};
    blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    blit.srcOffsets[1] = {int32_t(std::min(extent.width, windowImage_.width())),
                          int32_t(std::min(extent.height, windowImage_.height())), 1};
    blit.dstSubresource = blit.srcSubresource;
    blit.dstOffsets[1] = blit.srcOffsets[1];
    vkCmdBlitImage(cmd, windowImage_.handle(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                   VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_NEAREST);
    commands.imageBarrier(target, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                          VK_IMAGE_LAYOUT_PRESENT_SRC_KHR, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                          VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0);
  }
  commands.imageLayout(windowImage_, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL);
}

}  // namespace snell::viewer
