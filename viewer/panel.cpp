// The overlay's panel (ImGui, drawn each frame while the overlay is shown):
// the scene and device, the frame-time graph of the latest frames, the GPU
// passes of the last finished frame, the camera, the animation, the ways of
// drawing glass, the display switches and the controls' help.
#include "viewer_state.h"

#include "io/json.h"
#include "render/method.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <cstdio>
#include <map>

namespace snell::viewer {

void Viewer::noteFrameTime(double seconds) {
  frameTimes_[frameTimeNext_] = float(1000.0 * seconds);
  frameTimeNext_ = (frameTimeNext_ + 1) % kGraphFrames;
  frameTimeCount_ = std::min(frameTimeCount_ + 1, kGraphFrames);
}

void Viewer::drawUi(double frameSeconds) {
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.8f);
  ImGui::Begin("snell", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::Text("%s", sceneName_.c_str());
  ImGui::Text("%.1f fps, %.2f ms a frame (CPU and GPU)", fps_, 1000.0 * frameSeconds);

  // The latest frames' times, oldest on the left; the ring starts at its oldest.
  if (frameTimeCount_ > 0) {
    std::vector<double> times(frameTimes_.begin(), frameTimes_.begin() + long(frameTimeCount_));
    auto [lo, hi] = std::minmax_element(times.begin(), times.end());
    double least = *lo, most = *hi, middle = io::median(times);
    ImGui::Text("last %zu frames: min %.2f, median %.2f, max %.2f ms", frameTimeCount_, least, middle, most);
    int offset = frameTimeCount_ == kGraphFrames ? int(frameTimeNext_) : 0;
    float font = ImGui::GetFontSize();
    ImGui::PlotLines("##frame times", frameTimes_.data(), int(frameTimeCount_), offset, nullptr, 0.0f,
                     float(std::max(most * 1.1, 1.0)), ImVec2(font * 24.0f, font * 4.0f));
  }

  double gpuTotal = 0;
  std::map<std::string, double> byName;
  std::vector<std::string> order;
  for (const vk::PassTime& p : lastPasses_) {
    if (!byName.count(p.name)) order.push_back(p.name);
    byName[p.name] += p.milliseconds;
    gpuTotal += p.milliseconds;
  }
  if (ImGui::BeginTable("passes", 2, ImGuiTableFlags_SizingFixedFit)) {
    for (const std::string& name : order) {
      ImGui::TableNextRow();
      ImGui::TableNextColumn();
      ImGui::Text("%s", name.c_str());
      ImGui::TableNextColumn();
      ImGui::Text("%7.3f ms", byName[name]);
    }
    ImGui::TableNextRow();
    ImGui::TableNextColumn();
    ImGui::Text("GPU total");
    ImGui::TableNextColumn();
    ImGui::Text("%7.3f ms", gpuTotal);
    ImGui::EndTable();
  }
  // What the last finished frame did and skipped.
  const render::FrameStats& st = lastStats_;
  ImGui::Text("deformed %u, skipped %u; trees refit %u, rebuilt %u, skipped %u", st.itemsDeformed,
              st.itemsDeformSkipped, st.treesRefit, st.treesBuilt, st.treesSkipped);
  ImGui::Text("top level %s; views drawn %u, kept %u; %llu pixels traced; %u dispatches",
              st.topLevelBuilt ? "built" : st.topLevelRefit ? "refit" : "kept", st.viewsRendered, st.viewsSkipped,
              static_cast<unsigned long long>(st.pixelsTraced), st.dispatches);
  uint64_t imageBytes = uint64_t(windowImage_.width()) * windowImage_.height() * 4;
  for (const Viewport& vp : viewports_) imageBytes += uint64_t(vp.width) * vp.height * (8 + 8 + 4 + 4 + 4);
  ImGui::Text("%u triangles, %.1f MiB of GPU memory", renderer_->sceneGpu().triangleCount,
              double(renderer_->memoryBytes() + imageBytes) / 1048576.0);
  ImGui::Text("%s", context_->facts().name.c_str());
  ImGui::Separator();

  Viewport& vp = viewports_[active_];
  std::string current = vp.rig.sceneCamera >= 0 ? "camera " + std::to_string(vp.rig.sceneCamera) : "orbit";
  if (ImGui::BeginCombo("camera", current.c_str())) {
    if (ImGui::Selectable("orbit", vp.rig.sceneCamera < 0)) leaveSceneCamera(vp);
    for (size_t c = 0; c < scene_->cameras.size(); ++c) {
      std::string label = std::to_string(c) + " " + scene_->cameras[c].name;
      if (ImGui::Selectable(label.c_str(), vp.rig.sceneCamera == int(c))) {
        if (cameraResolves(int(c))) {
          vp.rig.sceneCamera = int(c);
        } else {
          message_ = "camera " + std::to_string(c) + " is not placed by any node";
        }
      }
    }
    ImGui::EndCombo();
  }
  if (ImGui::Button("frame (F)")) frameScene();
  ImGui::SameLine();
  if (ImGui::Button("reset film back")) vp.rig.resetFilm();
  ImGui::Checkbox("2D pan/zoom (\\)", &toggles_.filmMode);

  if (duration_ > 0.0) {
    if (ImGui::Button(toggles_.playing ? "pause" : "play")) toggles_.playing = !toggles_.playing;
    ImGui::SameLine();
    ImGui::Checkbox("loop", &toggles_.loop);
    float t = float(time_);
    if (ImGui::SliderFloat("time", &t, 0.0f, float(duration_), "%.2f s")) time_ = t;
  } else {
    ImGui::TextDisabled("no animation");
  }
  ImGui::Separator();
  ImGui::Checkbox("refraction (R)", &toggles_.refraction);
  if (toggles_.refraction) {
    const std::vector<render::MethodInfo>& all = render::methods();
    int chosen = 0;
    for (size_t i = 0; i < all.size(); ++i) chosen = all[i].method == toggles_.method ? int(i) : chosen;
    if (ImGui::BeginCombo("method", all[size_t(chosen)].name)) {
      for (size_t i = 0; i < all.size(); ++i) {
        if (all[i].method == render::Method::None) continue;  // that is refraction off
        if (ImGui::Selectable(all[i].name, int(i) == chosen)) toggles_.method = all[i].method;
        if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", all[i].summary);
      }
      ImGui::EndCombo();
    }
    if (toggles_.method == render::Method::RefractionMap && ImGui::Button("bake again here (B)")) rebake_ = true;
  }
  if (context_->caps().fillModeNonSolid) ImGui::Checkbox("wireframe (W)", &toggles_.wireframe);
  ImGui::Checkbox("BVH cost heat map (H)", &toggles_.heatMap);
  if (toggles_.heatMap) ImGui::SliderFloat("hottest", &toggles_.heatMax, 8.0f, 1024.0f, "%.0f nodes");
  ImGui::Checkbox("film gate (G)", &toggles_.gate);
  ImGui::Checkbox("two viewports (2)", &toggles_.split);
  if (swapchain_ && ImGui::Checkbox("vsync", &toggles_.vsync)) {
    swapchain_ = nullptr;  // rebuilt below with the new present mode
    VkSurfaceKHR surface = VK_NULL_HANDLE;
    VK_CHECK(glfwCreateWindowSurface(context_->instance(), window_, nullptr, &surface));
    swapchain_ = std::make_unique<Swapchain>(*context_, surface, toggles_.vsync);
  }
  if (ImGui::Button("screenshot (F12)")) shotRequested_ = true;
  if (!notice_.empty() && Clock::now() < noticeUntil_) {
    ImGui::SameLine();
    ImGui::TextColored(ImVec4(0.5f, 1.0f, 0.5f, 1.0f), "%s", notice_.c_str());
  }
  if (!message_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "%s", message_.c_str());
  if (ImGui::CollapsingHeader("controls")) ImGui::TextUnformatted(kControlsHelp);
  ImGui::End();
}

}  // namespace snell::viewer
