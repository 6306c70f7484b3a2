// ImGui (Debian's libimgui-dev) drawn over the window image: GLFW input when
// there is a window, a fixed display size when the viewer runs offscreen.
// Sized for the display: fonts and spacing follow the window's content scale
// (HiDPI), read when it opens and again each frame.
#pragma once

#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/context.h"

#include <imgui.h>
#include <vulkan/vulkan.h>

#include <map>

struct GLFWwindow;

namespace snell::viewer {

/// The window image's format: the display pass writes it, ImGui draws on it.
inline constexpr VkFormat kWindowImageFormat = VK_FORMAT_R8G8B8A8_UNORM;

class UiOverlay {
 public:
  /// `window` may be null (offscreen). Installs ImGui's GLFW callbacks after
  /// any the caller set, which it chains to.
  UiOverlay(vk::Context& context, GLFWwindow* window);
  ~UiOverlay();
  UiOverlay(const UiOverlay&) = delete;
  UiOverlay& operator=(const UiOverlay&) = delete;

  /// Starts an ImGui frame for a display of width x height (and follows a
  /// change of the window's content scale, e.g. moved to another monitor).
  void newFrame(uint32_t width, uint32_t height, double seconds);
  /// Ends the frame and records its drawing onto `target` (kWindowImageFormat, GENERAL).
  void render(vk::Commands& commands, const vk::Image& target);
  /// Drops the framebuffers of window images about to be replaced (a new
  /// image's view may reuse an old handle's value).
  void forgetTargets();
  /// Whether ImGui wants the mouse or keyboard (the camera then leaves them alone).
  bool wantsMouse() const;
  bool wantsKeyboard() const;

 private:
  VkFramebuffer framebufferFor(const vk::Image& target);
  void applyScale();
  vk::Context& context_;
  GLFWwindow* window_ = nullptr;
  bool glfw_ = false;
  /// The font atlas's scale (built once, at the content scale the window
  /// opened with) and the scale the sizes follow now.
  float atlasScale_ = 1.0f, scale_ = 0.0f;
  ImGuiStyle baseStyle_;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkRenderPass renderPass_ = VK_NULL_HANDLE;
  std::map<VkImageView, VkFramebuffer> framebuffers_;
};

}  // namespace snell::viewer
