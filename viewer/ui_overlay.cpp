// ImGui's Vulkan backend of 1.86 draws through a render pass; this owns it,
// the framebuffers of the window images, the font upload and the scaling
// for HiDPI displays.
#include "ui_overlay.h"

#include "vk/error.h"

#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_vulkan.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace snell::viewer {

namespace {

// ImGui calls this from C; a failure there cannot be thrown through it.
void checkImguiResult(VkResult result) {
  if (result == VK_SUCCESS) return;
  std::fprintf(stderr, "snell-view: error: ImGui's Vulkan backend failed with %s\n", std::string(vk::resultName(result)).c_str());
  std::exit(1);
}

// The window's content scale: 1 on a 96 dpi display, 2 on most HiDPI ones
// (X11 reads it from Xft.dpi); 1 offscreen.
float contentScale(GLFWwindow* window) {
  if (!window) return 1.0f;
  float x = 1.0f, y = 1.0f;
  glfwGetWindowContentScale(window, &x, &y);
  float scale = std::max(x, y);
  return std::isfinite(scale) && scale > 0.0f ? std::clamp(scale, 0.5f, 4.0f) : 1.0f;
}

}  // namespace

UiOverlay::UiOverlay(vk::Context& context, GLFWwindow* window) : context_(context), window_(window) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no imgui.ini left in the user's working directory
  ImGui::StyleColorsDark();
  ImGui::GetStyle().WindowRounding = 4.0f;
  baseStyle_ = ImGui::GetStyle();
  // The font drawn at the pixel size the display needs, so text stays sharp:
  // ImGui's default font is 13 pixels at scale 1.
  atlasScale_ = contentScale(window);
  ImFontConfig font;
  font.OversampleH = font.OversampleV = 1;  // as AddFontDefault() without a config: a pixel font
  font.PixelSnapH = true;
  font.SizePixels = std::round(13.0f * atlasScale_);
  io.Fonts->AddFontDefault(&font);
  if (window) glfw_ = ImGui_ImplGlfw_InitForVulkan(window, true);

  VkDescriptorPoolSize sizes[] = {{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 4}};
  VkDescriptorPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  poolInfo.flags = VK_DESCRIPTOR_POOL_CREATE_FREE_DESCRIPTOR_SET_BIT;
  poolInfo.maxSets = 4;
  poolInfo.poolSizeCount = 1;
  poolInfo.pPoolSizes = sizes;
  VK_CHECK(vkCreateDescriptorPool(context.device(), &poolInfo, nullptr, &pool_));

  VkAttachmentDescription attachment{};
  attachment.format = kWindowImageFormat;
  attachment.samples = VK_SAMPLE_COUNT_1_BIT;
  attachment.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;  // over the display pass's picture
  attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  attachment.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  attachment.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  attachment.initialLayout = VK_IMAGE_LAYOUT_GENERAL;
  attachment.finalLayout = VK_IMAGE_LAYOUT_GENERAL;
  VkAttachmentReference reference{0, VK_IMAGE_LAYOUT_GENERAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &reference;
  VkRenderPassCreateInfo passInfo{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  passInfo.attachmentCount = 1;
  passInfo.pAttachments = &attachment;
  passInfo.subpassCount = 1;
  passInfo.pSubpasses = &subpass;
  VK_CHECK(vkCreateRenderPass(context.device(), &passInfo, nullptr, &renderPass_));

  ImGui_ImplVulkan_InitInfo info{};
  info.Instance = context.instance();
  info.PhysicalDevice = context.physicalDevice();
  info.Device = context.device();
  info.QueueFamily = context.queueFamily();
  info.Queue = context.queue();
  info.DescriptorPool = pool_;
  info.MinImageCount = 2;
  info.ImageCount = 2;  // one frame in flight: its buffers are free again two frames on
  info.MSAASamples = VK_SAMPLE_COUNT_1_BIT;
  info.CheckVkResultFn = checkImguiResult;
  ImGui_ImplVulkan_Init(&info, renderPass_);

  vk::Commands upload(context, "ImGui fonts");
  upload.begin();
  ImGui_ImplVulkan_CreateFontsTexture(upload.handle());
  upload.submitAndWait();
  ImGui_ImplVulkan_DestroyFontUploadObjects();
}

UiOverlay::~UiOverlay() {
  vkDeviceWaitIdle(context_.device());
  ImGui_ImplVulkan_Shutdown();
  if (glfw_) ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  for (auto& [view, framebuffer] : framebuffers_) vkDestroyFramebuffer(context_.device(), framebuffer, nullptr);
  vkDestroyRenderPass(context_.device(), renderPass_, nullptr);
  vkDestroyDescriptorPool(context_.device(), pool_, nullptr);
}

void UiOverlay::newFrame(uint32_t width, uint32_t height, double seconds) {
  ImGui_ImplVulkan_NewFrame();
  if (glfw_) {
    ImGui_ImplGlfw_NewFrame();
  } else {
    ImGuiIO& io = ImGui::GetIO();
    io.DisplaySize = ImVec2(float(width), float(height));
    io.DeltaTime = float(seconds > 0.0 ? seconds : 1.0 / 60.0);
  }
  applyScale();
  ImGui::NewFrame();
}

// ImGui lays out in window units and the GLFW backend magnifies by the
// framebuffer scale (pixels per unit: 2 on Wayland or macOS HiDPI, 1 on X11).
// What is left of the content scale, ours: the style's sizes and the font,
// whose atlas was drawn at the scale the window opened with. Polled each
// frame, which also follows the window to a monitor of another scale.
void UiOverlay::applyScale() {
  ImGuiIO& io = ImGui::GetIO();
  float content = contentScale(window_);
  float perUnit = glfw_ && io.DisplayFramebufferScale.x > 0.0f ? io.DisplayFramebufferScale.x : 1.0f;
  float scale = content / perUnit;
  float fontScale = content / atlasScale_ / perUnit;
  if (scale == scale_ && fontScale == io.FontGlobalScale) return;
  scale_ = scale;
  ImGuiStyle& style = ImGui::GetStyle();
  style = baseStyle_;
  style.ScaleAllSizes(scale);
  io.FontGlobalScale = fontScale;
}

VkFramebuffer UiOverlay::framebufferFor(const vk::Image& target) {
  auto found = framebuffers_.find(target.view());
  if (found != framebuffers_.end()) return found->second;
  forgetTargets();
  VkImageView view = target.view();
  VkFramebufferCreateInfo info{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  info.renderPass = renderPass_;
  info.attachmentCount = 1;
  info.pAttachments = &view;
  info.width = target.width();
  info.height = target.height();
  info.layers = 1;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  VK_CHECK(vkCreateFramebuffer(context_.device(), &info, nullptr, &framebuffer));
  framebuffers_[view] = framebuffer;
  return framebuffer;
}

void UiOverlay::forgetTargets() {
  // Their images are going: the framebuffers go too, once the GPU is done with them.
  for (auto& [view, framebuffer] : framebuffers_) {
    VkDevice device = context_.device();
    VkFramebuffer old = framebuffer;
    context_.retire([device, old] { vkDestroyFramebuffer(device, old, nullptr); });
  }
  framebuffers_.clear();
}

void UiOverlay::render(vk::Commands& commands, const vk::Image& target) {
  ImGui::Render();
  VkRenderPassBeginInfo begin{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  begin.renderPass = renderPass_;
  begin.framebuffer = framebufferFor(target);
  begin.renderArea = {{0, 0}, {target.width(), target.height()}};
  vkCmdBeginRenderPass(commands.handle(), &begin, VK_SUBPASS_CONTENTS_INLINE);
  ImGui_ImplVulkan_RenderDrawData(ImGui::GetDrawData(), commands.handle());
  vkCmdEndRenderPass(commands.handle());
}

bool UiOverlay::wantsMouse() const { return ImGui::GetIO().WantCaptureMouse; }
bool UiOverlay::wantsKeyboard() const { return ImGui::GetIO().WantCaptureKeyboard; }

}  // namespace snell::viewer
