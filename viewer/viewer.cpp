// The viewer's spine: opening the window and the device, switching scenes,
// laying out viewports and moving between glTF cameras and the orbit rig, the
// window's title, and the frame loop that ties input, the overlay, the GPU
// and the reports together. The other parts are listed in viewer_state.h.
#include "viewer_state.h"

#include "io/environment.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "scene/view.h"

#include "present.spv.h"

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <thread>
#include <utility>

namespace snell::viewer {

namespace {

// How long a notice (a screenshot written) stays in the title and the overlay.
constexpr std::chrono::seconds kNoticeTime{4};

}  // namespace

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
  if (!options.quiet) {
    for (const std::string& w : initial->warnings) std::fprintf(stderr, "snell-view: note: %s\n", w.c_str());
  }
  if (options.camera >= 0 && size_t(options.camera) >= initial->cameras.size()) {
    throw OptionError{"--camera " + std::to_string(options.camera) + ": the scene has " +
                      std::to_string(initial->cameras.size()) + " camera(s)"};
  }

  vk::ContextDesc desc = io::contextDescFromEnvironment();
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
      scene::resolveView(*scene, pose, {c, std::nullopt, kDefaultYfov});
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
  updateTitle();
}

// "eye.glb — snell-view" (the file's name without its folder, or "procedural
// eye"), with a fresh notice after it.
void Viewer::updateTitle() {
  if (!window_) return;
  std::string scene = std::filesystem::path(sceneName_).filename().string();
  std::string title = (scene.empty() ? sceneName_ : scene) + " \u2014 snell-view";
  if (!notice_.empty() && Clock::now() < noticeUntil_) title += " \u2014 " + notice_;
  if (title == title_) return;
  glfwSetWindowTitle(window_, title.c_str());
  title_ = title;
}

void Viewer::notify(const std::string& text) {
  notice_ = text;
  noticeUntil_ = Clock::now() + kNoticeTime;
  updateTitle();
}

bool Viewer::cameraResolves(int camera) const {
  if (camera < 0 || size_t(camera) >= scene_->cameras.size()) return false;
  try {
    scene::resolveView(*scene_, pose_, {camera, std::nullopt, kDefaultYfov});
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

// The viewport under the window pixel x (it becomes the active one).
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

// One pass per frame: events and the script, a scene dropped since the last
// frame, the clock, the window's size, the overlay, then the GPU's frame. Two
// frames are in flight; the one before is waited for and recorded.
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
    updateTitle();  // a notice's time may be up
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
    if (frame > 0) noteFrameTime(frameSeconds);

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
    bool lastFrame = options_.frames != 0 && frame + 1 == options_.frames;
    bool shotForOption = lastFrame && !options_.screenshot.empty();
    bool shotForKey = std::exchange(shotRequested_, false);  // asked for since the last frame drawn
    bool screenshot = shotForOption || shotForKey;
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
      if (shotForOption) {
        writeScreenshot(options_.screenshot);
        shotWritten_ = true;
      }
      if (shotForKey) saveScreenshot();
    }
  }
  if (pendingFrame_) noteFrame(renderer_->wait(pendingFrame_), pendingCpuMs_);
  pendingFrame_ = 0;
  double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  sampleMemory(framesDrawn_);
  std::printf("%llu frames in %.2f s on %s%s\n", (unsigned long long)framesDrawn_, seconds, context_->facts().name.c_str(),
              swapchain_ ? (", swapchain recreated " + std::to_string(swapchain_->recreations() - 1) + " time(s)").c_str()
                         : ", offscreen");
  report(seconds);
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

int runViewer(const ViewerOptions& options) {
  Viewer viewer(options);
  return viewer.run();
}

}  // namespace snell::viewer
