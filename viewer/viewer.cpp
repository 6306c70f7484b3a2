// The viewer's frame loop, input and user interface.
#include "viewer.h"

#include "camera_rig.h"
#include "script.h"
#include "swapchain.h"
#include "ui_overlay.h"

#include "cli/cli.h"
#include "cli/image_file.h"
#include "bake/refraction_bake.h"
#include "render/raster_pass.h"
#include "render/method.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/procedural_eye.h"
#include "scene/view.h"
#include "shared/present.h"
#include "vk/compute_program.h"
#include "vk/error.h"

#include "present.spv.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <deque>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <thread>
#include <utility>

namespace snell::viewer {

namespace {

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

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

class Viewer {
 public:
  explicit Viewer(const ViewerOptions& options);
  ~Viewer();
  int run();

 private:
  int runFrames();
  int reportGpuFailure(const vk::VulkanError& error);
  void openWindow();
  void useScene(std::unique_ptr<scene::Scene> scene, int camera);
  bool cameraResolves(int camera) const;
  void layoutViewports(uint32_t width, uint32_t height);
  void applyScript(uint64_t frame);
  void drawUi(double frameSeconds);
  render::FrameRequest frameRequest(std::optional<uint32_t> swapImage, bool screenshot);
  void recordDisplay(vk::Commands& commands, std::optional<uint32_t> swapImage, bool screenshot);
  void noteFrame(const render::FrameResult& result, double cpuMs);
  scene::View viewOf(const Viewport& vp) const;
  void frameScene();
  void writeScreenshot();
  void writeJson(double seconds) const;
  void leaveSceneCamera(Viewport& vp);
  Viewport* viewportAt(double x, double y);

  // GLFW callbacks, routed through the window's user pointer.
  static void onKey(GLFWwindow* w, int key, int scancode, int action, int mods);
  static void onMouseButton(GLFWwindow* w, int button, int action, int mods);
  static void onCursor(GLFWwindow* w, double x, double y);
  static void onScroll(GLFWwindow* w, double dx, double dy);
  static void onDrop(GLFWwindow* w, int count, const char** paths);

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
  std::string sceneName_, message_;
  std::vector<Viewport> viewports_;
  size_t active_ = 0;
  vk::Image windowImage_;
  vk::Buffer placeholderAov_, screenshotBuffer_;
  bool freshImages_ = true;
  VkSemaphore imageReady_ = VK_NULL_HANDLE;
  std::vector<ScriptAction> script_;
  size_t nextAction_ = 0;
  bool quit_ = false;
  bool shotWritten_ = false;
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
  struct MemorySample {
    uint64_t frame, hostBytes, deviceBytes;
    std::string scene;
  };
  std::vector<MemorySample> memorySamples_;  ///< before each scene switch, and at the end
  void sampleMemory(uint64_t frame);
  std::vector<vk::PassTime> lastPasses_;
  render::FrameStats lastStats_;
  uint64_t pendingFrame_ = 0;  ///< the renderer's frame submitted last, not yet waited for
  /// refraction-map: per viewport, the map the trace baked when the method was
  /// picked (or B pressed); it stays as the scene and the camera move on.
  std::vector<std::unique_ptr<render::RefractionMapBuffer>> maps_;
  bool rebake_ = false;
  void bakeRefractionMaps();
  double pendingCpuMs_ = 0;
  double fps_ = 0;
};

Viewer::Viewer(const ViewerOptions& options) : options_(options) {
  toggles_.split = options.split;
  toggles_.ui = !options.hideUi;
  toggles_.gate = !options.hideUi;
  toggles_.playing = options.play;
  toggles_.refraction = options.method != render::Method::None;
  if (toggles_.refraction) toggles_.method = options.method;
  toggles_.vsync = options.vsync;
  time_ = options.time;
  if (!options.script.empty()) script_ = loadScript(options.script);

  // The scene first: a bad file is reported before any window opens.
  std::unique_ptr<scene::Scene> initial;
  if (options.scene.empty()) {
    initial = std::make_unique<scene::Scene>(scene::makeEye());
    initial->source = "procedural eye";
  } else {
    initial = std::make_unique<scene::Scene>(scene::loadGltf(options.scene, options.load));
  }
  for (const std::string& w : initial->warnings) std::fprintf(stderr, "snell-view: note: %s\n", w.c_str());
  if (options.camera >= 0 && size_t(options.camera) >= initial->cameras.size()) {
    throw cli::UsageError{"--camera " + std::to_string(options.camera) + ": the scene has " +
                          std::to_string(initial->cameras.size()) + " camera(s)"};
  }

  vk::ContextDesc desc = cli::contextDescFromEnvironment();
  desc.applicationName = "snell-view";
  if (!options.offscreen) {
    openWindow();
    uint32_t count = 0;
    const char** extensions = glfwGetRequiredInstanceExtensions(&count);
    if (!extensions) throw std::runtime_error("GLFW finds no Vulkan surface support on this display");
    for (uint32_t i = 0; i < count; ++i) desc.instanceExtensions.emplace_back(extensions[i]);
    desc.deviceExtensions.emplace_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
  }
  context_ = vk::Context::create(desc);
  if (window_) {
    VkSurfaceKHR surface = VK_NULL_HANDLE;
    VK_CHECK(glfwCreateWindowSurface(context_->instance(), window_, nullptr, &surface));
    swapchain_ = std::make_unique<Swapchain>(*context_, surface, toggles_.vsync);
    VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VK_CHECK(vkCreateSemaphore(context_->device(), &info, nullptr, &imageReady_));
  }
  ui_ = std::make_unique<UiOverlay>(*context_, window_);
  present_ = std::make_unique<vk::ComputeProgram>(*context_, vk::ComputeProgramDesc{"display", kSpvPresent, {}, false});
  placeholderAov_ = vk::Buffer(*context_, {sizeof(gpu::TraceAov), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                           vk::MemoryDomain::Device, "no heat map"});
  useScene(std::move(initial), options.camera);
}

Viewer::~Viewer() {
  if (context_) vkDeviceWaitIdle(context_->device());
  ui_.reset();
  swapchain_.reset();
  if (imageReady_) vkDestroySemaphore(context_->device(), imageReady_, nullptr);
  if (window_) glfwDestroyWindow(window_);
  if (!options_.offscreen) glfwTerminate();
}

void Viewer::openWindow() {
  glfwSetErrorCallback([](int, const char* text) { std::fprintf(stderr, "snell-view: GLFW: %s\n", text); });
  if (!glfwInit()) {
    throw std::runtime_error("cannot open a window (no X display? run under xvfb-run, or use --offscreen)");
  }
  if (!glfwVulkanSupported()) throw std::runtime_error("GLFW finds no Vulkan loader for windows");
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  window_ = glfwCreateWindow(int(options_.width), int(options_.height), "snell-view", nullptr, nullptr);
  if (!window_) throw std::runtime_error("cannot create a window of " + std::to_string(options_.width) + "x" +
                                         std::to_string(options_.height));
  glfwSetWindowUserPointer(window_, this);
  // Ours first: ImGui's backend chains to them when it installs its own.
  glfwSetKeyCallback(window_, onKey);
  glfwSetMouseButtonCallback(window_, onMouseButton);
  glfwSetCursorPosCallback(window_, onCursor);
  glfwSetScrollCallback(window_, onScroll);
  glfwSetDropCallback(window_, onDrop);
}

// Switches to `scene`, seen from its glTF camera `camera` (-1: camera 0 when
// a node places it, else the view `snell render` frames the scene with).
// Everything new is built before anything old is let go: a scene that fails
// at any step throws and leaves the current one as it was.
void Viewer::useScene(std::unique_ptr<scene::Scene> scene, int camera) {
  double duration = scene::animationDuration(*scene);
  double time = std::clamp(time_, 0.0, duration);
  scene::Pose pose = scene::evaluate(*scene, time);
  glm::dvec3 lo, hi;
  scene::sceneBounds(*scene, pose, lo, hi);
  auto resolves = [&](int c) {
    try {
      scene::resolveView(*scene, pose, {c, std::nullopt, 0.6981317});
      return true;
    } catch (const std::invalid_argument&) {
      return false;
    }
  };
  if (camera >= 0 && !resolves(camera)) {
    throw std::runtime_error(scene->source + ": camera " + std::to_string(camera) + " is not placed by any node");
  }
  if (camera < 0 && !scene->cameras.empty() && resolves(0)) camera = 0;
  std::vector<Viewport> viewports(2);
  Viewport& main = viewports[0];
  glm::dvec3 centre = 0.5 * (lo + hi);
  if (camera >= 0) {
    main.rig.sceneCamera = camera;
  } else {
    // No placed camera: the view `snell render` frames the scene with, so the two agree.
    main.rig.adopt(scene::resolveView(*scene, pose, {}), centre);
  }
  // The second viewport: the same subject from 50 degrees to the side.
  viewports[1].rig.adopt(main.rig.view(*scene, pose), centre);
  viewports[1].rig.orbit(-50.0 / 0.008 * 3.14159265358979 / 180.0, 0.0);
  auto renderer = std::make_unique<render::Renderer>(*context_, *scene, pose);

  if (renderer_) vkDeviceWaitIdle(context_->device());
  pendingFrame_ = 0;  // its numbers belong to the renderer that goes
  maps_.clear();
  renderer_ = std::move(renderer);  // the old renderer goes before the scene it refers to
  scene_ = std::move(scene);
  pose_ = std::move(pose);
  boundsLo_ = lo;
  boundsHi_ = hi;
  duration_ = duration;
  time_ = time;
  sceneName_ = scene_->source.empty() ? "scene" : scene_->source;
  viewports_ = std::move(viewports);  // sized on the next frame
  active_ = 0;
  freshImages_ = true;
}

bool Viewer::cameraResolves(int camera) const {
  if (camera < 0 || size_t(camera) >= scene_->cameras.size()) return false;
  try {
    scene::resolveView(*scene_, pose_, {camera, std::nullopt, 0.6981317});
    return true;
  } catch (const std::invalid_argument&) {
    return false;
  }
}

void Viewer::layoutViewports(uint32_t width, uint32_t height) {
  uint32_t count = toggles_.split && width >= 2 ? 2 : 1;
  for (uint32_t i = 0; i < viewports_.size(); ++i) {
    Viewport& vp = viewports_[i];
    uint32_t x = i == 0 ? 0 : width / 2;
    uint32_t w = count == 1 ? (i == 0 ? width : 0) : (i == 0 ? width / 2 : width - width / 2);
    if (vp.width == w && vp.height == height && vp.x == x) continue;
    vp.x = x;
    vp.width = w;
    vp.height = height;
    if (w) render::checkImageSize(*context_, w, height);
  }
  if (windowImage_.width() != width || windowImage_.height() != height) {
    ui_->forgetTargets();
    windowImage_ = vk::Image(*context_, {width, height, kWindowImageFormat,
                                         VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                                             VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                         "window image"});
    screenshotBuffer_ = vk::Buffer(*context_, {uint64_t(width) * height * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                               vk::MemoryDomain::Readback, "screenshot"});
    freshImages_ = true;
  }
  if (active_ >= count) active_ = 0;
}

scene::View Viewer::viewOf(const Viewport& vp) const { return vp.rig.view(*scene_, pose_); }

void Viewer::frameScene() {
  Viewport& vp = viewports_[active_];
  if (vp.rig.sceneCamera >= 0) leaveSceneCamera(vp);
  vp.rig.frame(boundsLo_, boundsHi_);
}

// A glTF camera the user moves becomes the orbit rig, starting where it was.
void Viewer::leaveSceneCamera(Viewport& vp) {
  if (vp.rig.sceneCamera < 0) return;
  CameraRig film = vp.rig;
  vp.rig.adopt(scene::resolveView(*scene_, pose_, {vp.rig.sceneCamera, std::nullopt, vp.rig.yfov}),
               0.5 * (boundsLo_ + boundsHi_));
  vp.rig.filmPan = film.filmPan;
  vp.rig.filmZoom = film.filmZoom;
}

Viewport* Viewer::viewportAt(double x, double) {
  for (size_t i = 0; i < viewports_.size(); ++i) {
    const Viewport& vp = viewports_[i];
    if (vp.width && x >= vp.x && x < vp.x + vp.width) {
      active_ = i;
      return &viewports_[i];
    }
  }
  return &viewports_[active_];
}

void Viewer::onKey(GLFWwindow* w, int key, int, int action, int mods) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
  if (action != GLFW_PRESS || self->ui_->wantsKeyboard()) return;
  Toggles& t = self->toggles_;
  Viewport& vp = self->viewports_[self->active_];
  switch (key) {
    case GLFW_KEY_F: self->frameScene(); break;
    case GLFW_KEY_SPACE: t.playing = !t.playing; break;
    case GLFW_KEY_R: t.refraction = !t.refraction; break;
    case GLFW_KEY_W: t.wireframe = !t.wireframe && self->context_->caps().fillModeNonSolid; break;
    case GLFW_KEY_H: t.heatMap = !t.heatMap; break;
    case GLFW_KEY_B: self->rebake_ = true; break;
    case GLFW_KEY_G: t.gate = !t.gate; break;
    case GLFW_KEY_2: t.split = !t.split; break;
    case GLFW_KEY_TAB: t.ui = !t.ui; break;
    case GLFW_KEY_BACKSLASH: t.filmMode = !t.filmMode; break;
    case GLFW_KEY_BACKSPACE: vp.rig.resetFilm(); break;
    case GLFW_KEY_HOME: self->time_ = 0.0; break;
    case GLFW_KEY_LEFT: self->time_ = std::max(0.0, self->time_ - 1.0 / 24.0); break;
    case GLFW_KEY_RIGHT: self->time_ = std::min(self->duration_, self->time_ + 1.0 / 24.0); break;
    case GLFW_KEY_ESCAPE: self->quit_ = true; break;
    default: break;
  }
  (void)mods;
}

// Cursor positions come in window units; viewports are laid out in framebuffer
// pixels, which differ on scaled (HiDPI) displays.
double pixelsPerUnit(GLFWwindow* w) {
  int windowWidth = 0, windowHeight = 0, pixelWidth = 0, pixelHeight = 0;
  glfwGetWindowSize(w, &windowWidth, &windowHeight);
  glfwGetFramebufferSize(w, &pixelWidth, &pixelHeight);
  return windowWidth > 0 && pixelWidth > 0 ? double(pixelWidth) / double(windowWidth) : 1.0;
}

void Viewer::onMouseButton(GLFWwindow* w, int button, int action, int mods) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
  if (button < 0 || button > 2) return;
  if (action == GLFW_PRESS) {
    if (self->ui_->wantsMouse()) return;
    glfwGetCursorPos(w, &self->lastX_, &self->lastY_);
    double scale = pixelsPerUnit(w);
    self->lastX_ *= scale;
    self->lastY_ *= scale;
    self->viewportAt(self->lastX_, self->lastY_);
    self->buttons_ |= 1 << button;
    self->dragMods_ = mods;
  } else {
    self->buttons_ &= ~(1 << button);
  }
}

// Maya: Alt + left tumbles, Alt + middle tracks, Alt + right dollies. Without
// a middle button or where Alt-drag moves windows: left tumbles, Shift + left
// tracks, Ctrl + left dollies. In film mode (\) left drag pans the film back.
void Viewer::onCursor(GLFWwindow* w, double x, double y) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
  double scale = pixelsPerUnit(w);
  x *= scale;
  y *= scale;
  double dx = x - self->lastX_, dy = y - self->lastY_;
  self->lastX_ = x;
  self->lastY_ = y;
  if (!self->buttons_) return;
  Viewport& vp = self->viewports_[self->active_];
  bool left = self->buttons_ & 1, right = self->buttons_ & 2, middle = self->buttons_ & 4;
  int mods = self->dragMods_;
  if (self->toggles_.filmMode && left) {
    vp.rig.panFilm(dx, dy, vp.height);
    return;
  }
  self->leaveSceneCamera(vp);
  if (middle || (left && (mods & GLFW_MOD_SHIFT))) {
    vp.rig.pan(dx, dy, vp.height);
  } else if (right || (left && (mods & GLFW_MOD_CONTROL))) {
    vp.rig.dolly((dx - dy) * 0.05);
  } else if (left) {
    vp.rig.orbit(dx, dy);
  }
}

void Viewer::onScroll(GLFWwindow* w, double, double dy) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
  if (self->ui_->wantsMouse()) return;
  double x = 0, y = 0;
  glfwGetCursorPos(w, &x, &y);
  Viewport& vp = *self->viewportAt(x * pixelsPerUnit(w), y);
  if (self->toggles_.filmMode) {
    vp.rig.zoomFilm(dy);
  } else {
    self->leaveSceneCamera(vp);
    vp.rig.dolly(dy);
  }
}

void Viewer::onDrop(GLFWwindow* w, int count, const char** paths) {
  auto* self = static_cast<Viewer*>(glfwGetWindowUserPointer(w));
  if (count > 0) self->pendingLoad_ = paths[0];  // loaded between frames, not inside GLFW's callback
}

void Viewer::applyScript(uint64_t frame) {
  while (nextAction_ < script_.size() && script_[nextAction_].frame <= frame) {
    const ScriptAction& a = script_[nextAction_++];
    auto number = [&](size_t i) { return std::stod(a.args[i]); };
    auto on = [&](size_t i) { return a.args[i] == "on"; };
    Viewport& vp = viewports_[active_];
    std::printf("frame %llu: %s", static_cast<unsigned long long>(frame), a.action.c_str());
    for (const std::string& arg : a.args) std::printf(" %s", arg.c_str());
    std::printf("\n");
    if (a.action == "resize") {
      int w = std::max(1, int(number(0))), h = std::max(1, int(number(1)));
      if (window_) {
        glfwSetWindowSize(window_, w, h);
      } else {
        options_.width = uint32_t(w);
        options_.height = uint32_t(h);
      }
    } else if (a.action == "orbit") {
      leaveSceneCamera(vp);
      vp.rig.orbit(number(0), number(1));
    } else if (a.action == "pan") {
      leaveSceneCamera(vp);
      vp.rig.pan(number(0), number(1), vp.height);
    } else if (a.action == "dolly") {
      leaveSceneCamera(vp);
      vp.rig.dolly(number(0));
    } else if (a.action == "filmpan") {
      vp.rig.panFilm(number(0), number(1), vp.height);
    } else if (a.action == "filmzoom") {
      vp.rig.zoomFilm(number(0));
    } else if (a.action == "filmreset") {
      vp.rig.resetFilm();
    } else if (a.action == "frame") {
      frameScene();
    } else if (a.action == "camera") {
      if (a.args[0] == "orbit") {
        leaveSceneCamera(vp);
      } else if (number(0) >= 0.0 && cameraResolves(int(number(0)))) {
        vp.rig.sceneCamera = int(number(0));
      } else {
        message_ = "script line " + std::to_string(a.line) + ": no camera " + a.args[0] + " placed in the scene";
      }
    } else if (a.action == "play") {
      toggles_.playing = true;
    } else if (a.action == "pause") {
      toggles_.playing = false;
    } else if (a.action == "scrub") {
      time_ = std::clamp(number(0), 0.0, duration_);
    } else if (a.action == "loop") {
      toggles_.loop = on(0);
    } else if (a.action == "refraction") {
      toggles_.refraction = on(0);
    } else if (a.action == "method") {
      std::optional<render::Method> m = a.args.empty() ? std::nullopt : render::methodFromName(a.args[0]);
      if (m) {
        toggles_.method = *m;
      } else {
        message_ = "script line " + std::to_string(a.line) + ": method takes one of " + render::methodNames();
      }
    } else if (a.action == "wireframe") {
      toggles_.wireframe = on(0) && context_->caps().fillModeNonSolid;
    } else if (a.action == "heatmap") {
      toggles_.heatMap = on(0);
    } else if (a.action == "gate") {
      toggles_.gate = on(0);
    } else if (a.action == "split") {
      toggles_.split = on(0);
    } else if (a.action == "ui") {
      toggles_.ui = on(0);
    } else if (a.action == "minimise") {
      if (window_) glfwIconifyWindow(window_);
    } else if (a.action == "restore") {
      if (window_) glfwRestoreWindow(window_);
    } else if (a.action == "load") {
      pendingLoad_ = a.args[0];
    } else if (a.action == "quit") {
      quit_ = true;
    }
  }
}

void Viewer::drawUi(double frameSeconds) {
  ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowBgAlpha(0.8f);
  ImGui::Begin("snell", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
  ImGui::Text("%s", sceneName_.c_str());
  ImGui::Text("%.1f fps, %.2f ms a frame (CPU and GPU)", fps_, 1000.0 * frameSeconds);
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
    int current = 0;
    for (size_t i = 0; i < all.size(); ++i) current = all[i].method == toggles_.method ? int(i) : current;
    if (ImGui::BeginCombo("method", all[size_t(current)].name)) {
      for (size_t i = 0; i < all.size(); ++i) {
        if (all[i].method == render::Method::None) continue;  // that is refraction off
        if (ImGui::Selectable(all[i].name, int(i) == current)) toggles_.method = all[i].method;
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
  if (!message_.empty()) ImGui::TextColored(ImVec4(1, 0.4f, 0.3f, 1), "%s", message_.c_str());
  if (ImGui::CollapsingHeader("controls")) {
    ImGui::TextUnformatted(
        "Alt+left drag  tumble      (or left drag)\n"
        "Alt+middle     track       (or Shift+left)\n"
        "Alt+right      dolly       (or Ctrl+left, wheel)\n"
        "\\              2D pan/zoom of the film back\n"
        "F frame  Space play  Left/Right step  Home start\n"
        "R refraction  W wireframe  H heat map  G gate\n"
        "B bake the refraction map again (refraction-map)\n"
        "2 two viewports  Tab hide this  Esc quit\n"
        "drop a .gltf/.glb on the window to open it");
  }
  ImGui::End();
}

// refraction-map's maps, baked by the trace at the pose and views of now
// for viewports that have none of their size (or all, after B). The frames in
// flight finish first: they may read the maps replaced.
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
    const render::RefractionMapBuffer* map = i < maps_.size() ? maps_[i].get() : nullptr;
    if (rebake_ || !map || map->width != vp.width || map->height != vp.height) due.push_back(i);
  }
  rebake_ = false;
  if (due.empty()) return;
  if (pendingFrame_) noteFrame(renderer_->wait(pendingFrame_), pendingCpuMs_);
  pendingFrame_ = 0;
  renderer_->finish();
  if (maps_.size() < viewports_.size()) maps_.resize(viewports_.size());
  for (size_t i : due) {
    const Viewport& vp = viewports_[i];
    render::FrameSettings settings{vp.width, vp.height, viewOf(vp), {0.02f, 0.02f, 0.025f}, gpu::kDefaultMaxInterfaces};
    bake::RefractionBake baked = bake::bakeRefraction(*context_, *renderer_, pose_, settings);
    maps_[i] = std::make_unique<render::RefractionMapBuffer>(bake::uploadRefractionMap(*context_, baked));
    char when[32];
    std::snprintf(when, sizeof when, "%.2f s", pose_.time);
    message_ = "refraction map baked at " + std::string(when) + ": " + bake::describe(baked, *scene_);
  }
  renderer_->invalidateViews();
}

// The frame the renderer runs: one composite view per viewport shown, then
// the display pass, the overlay and the copy to the swapchain (or screenshot).
render::FrameRequest Viewer::frameRequest(std::optional<uint32_t> swapImage, bool screenshot) {
  render::FrameRequest request;
  request.pose = &pose_;
  for (const Viewport& vp : viewports_) {
    if (!vp.width) continue;
    render::FrameSettings settings{vp.width, vp.height, viewOf(vp), {0.02f, 0.02f, 0.025f}, gpu::kDefaultMaxInterfaces};
    render::RasterOptions raster;
    raster.wireframe = toggles_.wireframe;
    render::fitDepthRange(settings.view, boundsLo_, boundsHi_, raster);
    size_t index = size_t(&vp - viewports_.data());
    if (index < maps_.size()) raster.refractionMap = maps_[index].get();
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

void Viewer::writeScreenshot() {
  cli::Rgb8Image image{windowImage_.width(), windowImage_.height(), {}};
  size_t pixels = size_t(image.width) * image.height;
  image.rgb.resize(pixels * 3);
  const auto* rgba = reinterpret_cast<const uint8_t*>(screenshotBuffer_.mapped().data());
  for (size_t i = 0; i < pixels; ++i) {
    for (int c = 0; c < 3; ++c) image.rgb[3 * i + size_t(c)] = rgba[4 * i + size_t(c)];
  }
  cli::writeRgb8(options_.screenshot, image);
  std::printf("wrote %s: %ux%u\n", options_.screenshot.c_str(), image.width, image.height);
}

void Viewer::sampleMemory(uint64_t frame) {
  // The frames before are finished, so what they retired is freed first.
  if (pendingFrame_) noteFrame(renderer_->wait(pendingFrame_), pendingCpuMs_);
  pendingFrame_ = 0;
  context_->collectRetired();
  MemorySample s{frame, cli::hostResidentBytes(), context_->memoryInUse(), scene_->source};
  memorySamples_.push_back(s);
  std::printf("memory at frame %llu (%s): host %.1f MiB resident, GPU %.1f MiB in use\n", (unsigned long long)frame,
              s.scene.c_str(), double(s.hostBytes) / 1048576.0, double(s.deviceBytes) / 1048576.0);
}

void Viewer::writeJson(double seconds) const {
  std::vector<double> cpu;
  std::map<std::string, std::vector<double>> gpu;
  std::vector<double> gpuTotal, pixels, dispatches;
  uint64_t deformed = 0, refit = 0, rebuilt = 0, viewsDrawn = 0, viewsKept = 0;
  // The first frames build the tree and warm caches: the medians skip them.
  size_t skip = std::min<size_t>(records_.size() / 10, 10);
  for (size_t i = skip; i < records_.size(); ++i) {
    const render::FrameStats& st = records_[i].stats;
    pixels.push_back(double(st.pixelsTraced));
    dispatches.push_back(st.dispatches);
    deformed += st.itemsDeformed;
    refit += st.treesRefit;
    rebuilt += st.treesBuilt;
    viewsDrawn += st.viewsRendered;
    viewsKept += st.viewsSkipped;
    cpu.push_back(records_[i].cpuMs);
    double total = 0;
    for (const auto& [name, ms] : records_[i].gpuMs) {
      gpu[name].push_back(ms);
      total += ms;
    }
    gpuTotal.push_back(total);
  }
  std::printf("\n%-12s %10s\n", "pass", "median ms");
  for (const auto& [name, v] : gpu) std::printf("%-12s %10.3f\n", name.c_str(), median(v));
  std::printf("%-12s %10.3f\n%-12s %10.3f\n", "GPU total", median(gpuTotal), "frame (CPU)", median(cpu));
  std::printf("over %zu frames: %llu items deformed, %llu trees refit, %llu rebuilt, views drawn %llu, kept %llu; "
              "median %.0f pixels traced, %.0f dispatches a frame\n",
              cpu.size(), static_cast<unsigned long long>(deformed), static_cast<unsigned long long>(refit),
              static_cast<unsigned long long>(rebuilt), static_cast<unsigned long long>(viewsDrawn),
              static_cast<unsigned long long>(viewsKept), median(pixels), median(dispatches));
  if (options_.json.empty()) return;
  std::string text = "{\n  \"device\": \"" + context_->facts().name + "\",\n  \"scene\": \"" + sceneName_ +
                     "\",\n  \"width\": " + std::to_string(windowImage_.width()) +
                     ",\n  \"height\": " + std::to_string(windowImage_.height()) +
                     ",\n  \"viewports\": " + std::to_string(toggles_.split ? 2 : 1) +
                     ",\n  \"refraction\": " + (toggles_.refraction ? "true" : "false") +
                     ",\n  \"ui\": " + (toggles_.ui ? "true" : "false") +
                     ",\n  \"frames\": " + std::to_string(framesDrawn_) +
                     ",\n  \"frames_in_medians\": " + std::to_string(cpu.size()) +
                     ",\n  \"wall_seconds\": " + std::to_string(seconds) +
                     ",\n  \"median_frame_ms\": " + std::to_string(median(cpu)) +
                     ",\n  \"median_gpu_total_ms\": " + std::to_string(median(gpuTotal)) +
                     ",\n  \"items_deformed\": " + std::to_string(deformed) + ",\n  \"trees_refit\": " +
                     std::to_string(refit) + ",\n  \"trees_rebuilt\": " + std::to_string(rebuilt) +
                     ",\n  \"views_drawn\": " + std::to_string(viewsDrawn) + ",\n  \"views_kept\": " +
                     std::to_string(viewsKept) + ",\n  \"median_pixels_traced\": " + std::to_string(median(pixels)) +
                     ",\n  \"median_dispatches\": " + std::to_string(median(dispatches)) + ",\n  \"median_pass_ms\": {";
  bool firstPass = true;
  for (const auto& [name, v] : gpu) {
    text += std::string(firstPass ? "\n" : ",\n") + "    \"" + name + "\": " + std::to_string(median(v));
    firstPass = false;
  }
  text += "\n  },\n  \"memory_samples\": [";
  for (size_t i = 0; i < memorySamples_.size(); ++i) {
    const MemorySample& m = memorySamples_[i];
    text += std::string(i ? "," : "") + "\n    {\"frame\": " + std::to_string(m.frame) + ", \"scene\": \"" +
            cli::jsonEscape(m.scene) + "\", \"host_resident_bytes\": " + std::to_string(m.hostBytes) +
            ", \"device_bytes\": " + std::to_string(m.deviceBytes) + "}";
  }
  text += "\n  ]\n}\n";
  cli::writeTextFile(options_.json, text);
  std::printf("wrote %s\n", options_.json.c_str());
}

void Viewer::noteFrame(const render::FrameResult& result, double cpuMs) {
  lastPasses_ = result.passes;
  lastStats_ = result.stats;
  FrameRecord record;
  record.cpuMs = cpuMs;
  record.stats = result.stats;
  for (const vk::PassTime& p : lastPasses_) record.gpuMs[p.name] += p.milliseconds;
  if (records_.size() == kKeptRecords) records_.pop_front();
  records_.push_back(record);
  ++framesDrawn_;
}

int Viewer::run() {
  try {
    return runFrames();
  } catch (const vk::VulkanError& e) {
    return reportGpuFailure(e);
  }
}

// A lost device or a failed submission ends the drawing, not the viewer: the
// window stays up with the failure in its title until the user closes it,
// and nothing half-drawn is written.
int Viewer::reportGpuFailure(const vk::VulkanError& error) {
  std::fprintf(stderr, "snell-view: error: the GPU failed, so nothing more is drawn: %s\n", error.what());
  if (window_ && options_.frames == 0) {
    std::string title = "snell-view: GPU failure (" + std::string(vk::resultName(error.result())) +
                        "); see the terminal, close to quit";
    glfwSetWindowTitle(window_, title.c_str());
    while (!glfwWindowShouldClose(window_)) glfwWaitEventsTimeout(0.1);
  }
  return 1;
}

int Viewer::runFrames() {
  auto start = Clock::now(), last = start;
  double frameSeconds = 0.0;
  for (uint64_t frame = 0; !quit_ && (options_.frames == 0 || frame < options_.frames); ++frame) {
    if (window_) {
      glfwPollEvents();
      if (glfwWindowShouldClose(window_)) break;
    }
    applyScript(frame);
    if (!pendingLoad_.empty()) {
      sampleMemory(frame);
      std::string path = std::exchange(pendingLoad_, {});
      try {
        useScene(std::make_unique<scene::Scene>(scene::loadGltf(path, options_.load)), -1);
        message_.clear();
        std::printf("opened %s: %u triangles\n", path.c_str(), renderer_->sceneGpu().triangleCount);
      } catch (const std::exception& e) {
        message_ = e.what();  // the current scene stays
        std::fprintf(stderr, "snell-view: %s\n", e.what());
      }
    }
    auto now = Clock::now();
    frameSeconds = std::chrono::duration<double>(now - last).count();
    last = now;
    if (frame > 0) fps_ = fps_ == 0 ? 1.0 / std::max(frameSeconds, 1e-6) : 0.9 * fps_ + 0.1 / std::max(frameSeconds, 1e-6);
    if (toggles_.playing && duration_ > 0.0) {
      time_ += frameSeconds;
      if (time_ > duration_) {
        if (toggles_.loop) {
          time_ = std::fmod(time_, duration_);
        } else {
          time_ = duration_;
          toggles_.playing = false;
        }
      }
    }

    uint32_t width = options_.width, height = options_.height;
    if (window_) {
      int w = 0, h = 0;
      glfwGetFramebufferSize(window_, &w, &h);
      if (w <= 0 || h <= 0 || glfwGetWindowAttrib(window_, GLFW_ICONIFIED)) {
        std::this_thread::sleep_for(std::chrono::milliseconds(16));  // minimised: nothing to draw to
        continue;
      }
      VkExtent2D asked = swapchain_->requested();
      if (!swapchain_->valid() || asked.width != uint32_t(w) || asked.height != uint32_t(h)) {
        if (!swapchain_->recreate(uint32_t(w), uint32_t(h))) continue;
      }
      width = swapchain_->extent().width;
      height = swapchain_->extent().height;
    }
    layoutViewports(width, height);
    if (pose_.time != time_) pose_ = scene::evaluate(*scene_, time_);

    ui_->newFrame(width, height, frameSeconds);
    if (toggles_.ui) drawUi(frameSeconds);

    std::optional<uint32_t> image;
    if (swapchain_) {
      image = swapchain_->acquire(imageReady_);
      if (!image) {
        ImGui::EndFrame();
        swapchain_->recreate(width, height);
        continue;
      }
    }
    bakeRefractionMaps();
    bool last_frame = options_.frames != 0 && frame + 1 == options_.frames;
    bool screenshot = last_frame && !options_.screenshot.empty();
    uint64_t submitted = renderer_->submit(frameRequest(image, screenshot));
    if (image && !swapchain_->present(*image)) swapchain_->recreate(width, height);
    // Two frames in flight: the GPU runs this one while the host waits only
    // for the one before, whose timings the overlay shows.
    if (pendingFrame_) noteFrame(renderer_->wait(pendingFrame_), pendingCpuMs_);
    pendingFrame_ = submitted;
    pendingCpuMs_ = 1000.0 * frameSeconds;
    if (screenshot) {
      noteFrame(renderer_->wait(submitted), pendingCpuMs_);
      pendingFrame_ = 0;
      writeScreenshot();
      shotWritten_ = true;
    }
  }
  if (pendingFrame_) noteFrame(renderer_->wait(pendingFrame_), pendingCpuMs_);
  pendingFrame_ = 0;
  double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  sampleMemory(framesDrawn_);
  std::printf("%llu frames in %.2f s on %s%s\n", (unsigned long long)framesDrawn_, seconds, context_->facts().name.c_str(),
              swapchain_ ? (", swapchain recreated " + std::to_string(swapchain_->recreations() - 1) + " time(s)").c_str()
                         : ", offscreen");
  writeJson(seconds);
  if (!options_.screenshot.empty() && !shotWritten_) {
    std::fprintf(stderr, "snell-view: error: the last frame was not drawn (window minimised or its swapchain out of "
                         "date), so %s was not written\n", options_.screenshot.c_str());
    return 1;
  }
  if (context_->validationMessageCount() > 0) {
    std::fprintf(stderr, "snell-view: the validation layer reported %llu message(s)\n",
                 static_cast<unsigned long long>(context_->validationMessageCount()));
    return 1;
  }
  return 0;
}

}  // namespace

int runViewer(const ViewerOptions& options) {
  Viewer viewer(options);
  return viewer.run();
}

}  // namespace snell::viewer
