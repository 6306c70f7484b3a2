// The Viewer class: everything one run of snell-view holds, declared once for
// the files that implement it. Where each part lives:
//   viewer.cpp   construction, the window and its title, scene switching,
//                viewports and cameras, the frame loop
//   input.cpp    keys (layout-aware), mouse, wheel, dropped files, scripted
//                input (--script), and the controls' help text
//   panel.cpp    the overlay's panel: timings, the frame-time graph, the
//                switches and the controls' help
//   display.cpp  what a frame asks of the GPU: a view per viewport,
//                refraction-map bakes, the display pass, the overlay and the
//                copies to the swapchain and the screenshot buffer
//   report.cpp   frame records, memory samples, the summary on standard
//                output and --json, screenshots (--screenshot and F12)
#pragma once

#include "viewer.h"

#include "camera_rig.h"
#include "script.h"
#include "swapchain.h"
#include "ui_overlay.h"

#include "render/raster_pass.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/scene.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "vk/context.h"
#include "vk/error.h"

#include <vulkan/vulkan.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

struct GLFWwindow;

namespace snell::viewer {

using Clock = std::chrono::steady_clock;

// One viewport: its camera and where it sits in the window. The renderer
// owns its images (view index = viewport index among those shown).
struct Viewport {
  CameraRig rig;
  uint32_t x = 0, width = 0, height = 0;
};

struct Toggles {
  render::Method method = render::Method::Masked;  ///< how glass is drawn while refraction is on
  bool refraction = true, wireframe = false, heatMap = false, gate = true, split = false, ui = true;
  bool playing = false, loop = true, filmMode = false, vsync = true;
  float heatMax = 128.0f;
};

struct FrameRecord {
  double cpuMs = 0;
  std::map<std::string, double> gpuMs;  ///< per pass name, summed over viewports
  render::FrameStats stats;
};

struct MemorySample {
  uint64_t frame, hostBytes, deviceBytes;
  std::string scene;
};

class Viewer {
 public:
  explicit Viewer(const ViewerOptions& options);
  ~Viewer();
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;
  int run();

 private:
  // viewer.cpp: the window, scenes, viewports and the frame loop.
  int runFrames();
  int reportGpuFailure(const vk::VulkanError& error);
  void openWindow();
  void useScene(std::unique_ptr<scene::Scene> scene, int camera);
  bool cameraResolves(int camera) const;
  void layoutViewports(uint32_t width, uint32_t height);
  scene::View viewOf(const Viewport& vp) const;
  void frameScene();
  void leaveSceneCamera(Viewport& vp);
  Viewport* viewportAt(double x, double y);
  /// The window's title: the scene, and a notice while one is fresh.
  void updateTitle();
  /// Shows `text` for a few seconds in the title and the overlay.
  void notify(const std::string& text);

  // input.cpp: GLFW callbacks, routed through the window's user pointer, and the script.
  static void onKey(GLFWwindow* w, int key, int scancode, int action, int mods);
  static void onMouseButton(GLFWwindow* w, int button, int action, int mods);
  static void onCursor(GLFWwindow* w, double x, double y);
  static void onScroll(GLFWwindow* w, double dx, double dy);
  static void onDrop(GLFWwindow* w, int count, const char** paths);
  void applyScript(uint64_t frame);

  // panel.cpp: the overlay's panel.
  void drawUi(double frameSeconds);
  void noteFrameTime(double seconds);

  // display.cpp: the GPU's part of a frame.
  render::FrameRequest frameRequest(std::optional<uint32_t> swapImage, bool screenshot);
  void recordDisplay(vk::Commands& commands, std::optional<uint32_t> swapImage, bool screenshot);
  void bakeRefractionMaps();

  // report.cpp: what a run records and writes.
  void noteFrame(const render::FrameResult& result, double cpuMs);
  void sampleMemory(uint64_t frame);
  void report(double seconds) const;
  /// Writes the screenshot buffer (the last frame copied out) to `path` as PNG.
  void writeScreenshot(const std::string& path) const;
  /// The screenshot key's: snell-view-YYYYMMDD-HHMMSS.png here; a failure is shown, not fatal.
  void saveScreenshot();

  ViewerOptions options_;
  Toggles toggles_;
  GLFWwindow* window_ = nullptr;
  std::unique_ptr<vk::Context> context_;
  std::unique_ptr<Swapchain> swapchain_;
  std::unique_ptr<UiOverlay> ui_;
  std::unique_ptr<vk::ComputeProgram> present_;
  std::unique_ptr<scene::Scene> scene_;
  std::unique_ptr<render::Renderer> renderer_;
  scene::Pose pose_;
  glm::dvec3 boundsLo_{0.0}, boundsHi_{0.0};
  double duration_ = 0.0, time_ = 0.0;
  std::string sceneName_;
  std::string message_;                  ///< the latest problem, shown in the overlay until replaced
  std::string notice_;                   ///< what just happened (a screenshot written), shown a few seconds
  Clock::time_point noticeUntil_{};
  std::string title_;                    ///< the window's title as last set
  std::vector<Viewport> viewports_;
  size_t active_ = 0;
  vk::Image windowImage_;
  vk::Buffer placeholderAov_, screenshotBuffer_;
  bool freshImages_ = true;
  VkSemaphore imageReady_ = VK_NULL_HANDLE;
  std::vector<ScriptAction> script_;
  size_t nextAction_ = 0;
  bool quit_ = false;
  bool shotWritten_ = false;             ///< --screenshot's file was written
  bool shotRequested_ = false;           ///< the screenshot key (or script action) asked for one
  std::string pendingLoad_;
  // Mouse state for camera drags.
  double lastX_ = 0, lastY_ = 0;
  int buttons_ = 0;  ///< bit per GLFW mouse button held
  int dragMods_ = 0;
  // The latest frames' records (the JSON's medians): bounded, so a long run's
  // memory stays flat.
  static constexpr size_t kKeptRecords = 512;
  std::deque<FrameRecord> records_;
  uint64_t framesDrawn_ = 0;
  std::vector<MemorySample> memorySamples_;  ///< before each scene switch, and at the end
  std::vector<vk::PassTime> lastPasses_;
  render::FrameStats lastStats_;
  uint64_t pendingFrame_ = 0;  ///< the renderer's frame submitted last, not yet waited for
  double pendingCpuMs_ = 0;
  bool rebake_ = false;
  double fps_ = 0;
  /// The overlay's frame-time graph: the latest frames' times in ms, a ring.
  static constexpr size_t kGraphFrames = 240;
  std::array<float, kGraphFrames> frameTimes_{};
  size_t frameTimeCount_ = 0, frameTimeNext_ = 0;
};

}  // namespace snell::viewer
