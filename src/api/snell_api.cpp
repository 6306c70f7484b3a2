// The public API (include/snell/snell.h) over the layers below: a Device is a
// vk::Context, a Scene a scene::Scene (a host's data turned into one), a
// Renderer a render::Renderer with the pose it draws. Every exception from
// below leaves as snell::Error.
#include "snell/snell.h"

#include "api/api_internal.h"

#include "bake/refraction_bake.h"
#include "io/environment.h"
#include "render/method.h"
#include "render/pixel_aovs.h"
#include "render/raster_pass.h"
#include "render/renderer.h"
#include "render/shot.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/optics.h"
#include "scene/subdivision.h"
#include "scene/view.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/error.h"

#include <glm/gtc/packing.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <utility>

namespace snell {

using api::guarded;
using api::toMatrix;
using api::toVec;

namespace {

// Every IEEE half's float: a table lookup converts a frame's pixels several times faster than bit arithmetic.
const std::array<float, 65536>& halfTable() {
  static const std::array<float, 65536> table = [] {
    std::array<float, 65536> t{};
    for (uint32_t h = 0; h < t.size(); ++h) t[h] = glm::unpackHalf1x16(uint16_t(h));
    return t;
  }();
  return table;
}

}  // namespace

const char* version() { return SNELL_VERSION; }

std::vector<MethodDescription> methods() {
  std::vector<MethodDescription> all;
  for (const render::MethodInfo& m : render::methods()) all.push_back({m.name, m.summary});
  return all;
}

// ---------------------------------------------------------------- Device


Device::Device(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Device::~Device() = default;
Device::Device(Device&&) noexcept = default;
Device& Device::operator=(Device&&) noexcept = default;

namespace {

vk::ContextDesc contextDesc(const DeviceOptions& options) {
  vk::ContextDesc desc;
  desc.applicationName = "snell (embedded)";
  desc.deviceOverride = options.device;
  desc.environment = io::deviceEnvironment();  // SNELL_DEVICE, or the GPUs a launcher gave the process
  desc.validation = options.validation;
  desc.synchronizationValidation = options.synchronizationValidation;
  desc.robustBufferAccess = options.validation;
  desc.driverRayTracing = options.driverRayTracing;
  if (options.interop) {
    desc.deviceExtensions = {VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME};
    desc.optionalDeviceExtensions = {VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME};  // lavapipe lacks it
  }
  return desc;
}

}  // namespace

Device Device::create(const DeviceOptions& options) {
  return guarded([&] {
    auto impl = std::make_unique<Impl>();
    impl->context = vk::Context::create(contextDesc(options));
    return Device(std::move(impl));
  });
}

Device Device::adopt(const HostDevice& host) {
  return guarded([&] {
    vk::AdoptedDevice adopted;
    static_cast<HostDevice&>(adopted) = host;
    adopted.enabled13.pNext = nullptr;
    auto impl = std::make_unique<Impl>();
    impl->context = vk::Context::adopt(adopted);
    return Device(std::move(impl));
  });
}

VkInstance Device::instance() const { return impl_->context->instance(); }
VkPhysicalDevice Device::physicalDevice() const { return impl_->context->physicalDevice(); }
VkDevice Device::device() const { return impl_->context->device(); }
VkQueue Device::queue() const { return impl_->context->queue(); }
uint32_t Device::queueFamily() const { return impl_->context->queueFamily(); }
std::string Device::name() const { return impl_->context->facts().name; }
uint64_t Device::validationMessages() const { return impl_->context->validationMessageCount(); }

bool Device::exportsSemaphores() const {
  // Enabled only when DeviceOptions::interop asked for it and the device has it.
  return vk::exportsSemaphores(*impl_->context);
}

void Device::waitIdle() {
  guarded([&] { VK_CHECK(vkDeviceWaitIdle(device())); });
}

// ---------------------------------------------------------------- Scene


Scene::Scene(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

Scene Scene::load(const std::string& path) {
  return guarded([&] {
    auto impl = std::make_unique<Impl>();
    impl->scene = scene::loadGltf(path);
    return Scene(std::move(impl));
  });
}

std::string Scene::name() const { return impl_->scene.source; }
size_t Scene::meshCount() const { return api::meshCount(impl_->scene); }
size_t Scene::cameraCount() const { return impl_->scene.cameras.size(); }
uint32_t Scene::vertexCount(int mesh) const {
  if (mesh < 0 || size_t(mesh) >= meshCount()) {
    throw Error("vertexCount: no mesh " + std::to_string(mesh) + " of " + std::to_string(meshCount()));
  }
  return uint32_t(impl_->scene.shapes[size_t(mesh)].writtenVertexCount());
}
uint32_t Scene::drawnVertexCount(int mesh) const {
  vertexCount(mesh);  // the same check
  return uint32_t(impl_->scene.shapes[size_t(mesh)].vertexCount());
}
uint32_t Scene::drawnTriangleCount(int mesh) const {
  vertexCount(mesh);
  size_t triangles = 0;
  for (const scene::Shape& s : impl_->scene.shapes) {
    if (&s - impl_->scene.shapes.data() == mesh || s.vertexSource == mesh) triangles += s.triangleCount();
  }
  return uint32_t(triangles);
}
std::vector<std::string> Scene::warnings() const { return impl_->scene.warnings; }
bool Scene::keepsVertices() const { return impl_->keep; }
double Scene::duration() const { return scene::animationDuration(impl_->scene); }

// ---------------------------------------------------------------- Environment

// The core's environment itself: the trace keys its upload by this object, so
// every View that holds the same Environment shares one buffer.
struct Environment::Impl : scene::Environment {};

Environment::Environment(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

Environment Environment::fromPixels(uint32_t width, uint32_t height, const float* rgb, const std::string& name) {
  return guarded([&] {
    if (width == 0 || height == 0 || !rgb) {
      throw Error(name + ": an environment of " + std::to_string(width) + "x" + std::to_string(height) +
                  " texels has nothing to show");
    }
    auto impl = std::make_shared<Impl>();
    impl->source = name;
    impl->width = width;
    impl->height = height;
    impl->texels.resize(size_t(width) * height);
    for (size_t i = 0; i < impl->texels.size(); ++i) impl->texels[i] = glm::vec3(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]);
    scene::fitEnvironment(*impl);
    return Environment(std::move(impl));
  });
}

uint32_t Environment::width() const { return impl_->width; }
uint32_t Environment::height() const { return impl_->height; }
std::string Environment::name() const { return impl_->source; }

Camera Camera::framing(const Vec3& lo, const Vec3& hi, float yfov) {
  const scene::LookAt at = scene::framedLookAt(glm::dvec3(toVec(lo)), glm::dvec3(toVec(hi)), double(yfov));
  Camera camera;
  camera.eye = {float(at.eye.x), float(at.eye.y), float(at.eye.z)};
  camera.target = {float(at.target.x), float(at.target.y), float(at.target.z)};
  camera.up = {float(at.up.x), float(at.up.y), float(at.up.z)};
  camera.yfov = yfov;
  return camera;
}

// ---------------------------------------------------------------- Renderer

namespace {

scene::View viewFromMatrices(const CameraMatrices& m, uint32_t width, uint32_t height) {
  return scene::viewFromMatrices(toMatrix(m.view), toMatrix(m.projection), width, height);
}

// The camera `view` names, at the pose.
scene::View cameraOf(const View& view, const scene::Scene& model, const scene::Pose& pose) {
  if (view.sceneCamera >= 0) {
    scene::ViewRequest which;
    which.camera = view.sceneCamera;
    return scene::resolveView(model, pose, which);
  }
  if (view.matrices) return viewFromMatrices(*view.matrices, view.width, view.height);
  const Camera& c = view.camera;
  scene::ViewRequest which;
  which.lookAt = scene::LookAt{glm::dvec3(toVec(c.eye)), glm::dvec3(toVec(c.target)), glm::dvec3(toVec(c.up))};
  which.yfov = c.yfov;
  return scene::resolveView(model, pose, which);
}

// The frame settings of `view` at the pose (its method apart).
render::FrameSettings frameSettings(const View& view, const scene::Scene& model, const scene::Pose& pose) {
  render::FrameSettings settings;
  settings.width = view.width;
  settings.height = view.height;
  settings.view = cameraOf(view, model, pose);
  settings.background = toVec(view.background);
  if (view.maxInterfaces > 1024) throw Error("view: maxInterfaces " + std::to_string(view.maxInterfaces) + " is past 1024");
  settings.maxInterfaces = view.maxInterfaces;
  settings.optics.fresnel = view.fresnel;
  settings.optics.dispersion = view.dispersion;
  settings.optics.volume = view.volume;
  if (view.environment) settings.optics.environment = view.environment->impl();
  settings.transparentBackground = view.transparentBackground;
  return settings;
}

}  // namespace

struct Renderer::Impl {
  std::recursive_mutex& mutex;  ///< the Device's
  vk::Context& context;
  Scene::Impl& scene;
  scene::Pose pose;
  std::map<size_t, glm::dmat4> transforms;  ///< setTransform's, kept over setTime
  std::unique_ptr<render::Renderer> renderer;
  FrameInfo last;
  std::optional<render::MethodChoice> choice;  ///< the last request's (auto keeps timing while it stays)
  render::Method drawn = render::Method::Trace;  ///< the last request's method

  Impl(Device& device, Scene& s, const RendererOptions& options)
      : mutex(device.impl().mutex), context(*device.impl().context), scene(s.impl()),
        pose(scene::evaluate(scene.scene, 0.0)) {
    std::lock_guard lock(mutex);
    render::RendererOptions o;
    o.framesInFlight = options.framesInFlight;
    o.passTimes = options.passTimes;
    o.compactTrees = options.compactTrees;
    o.host = scene.host;
    o.keepVertices = scene.keep;
    renderer = std::make_unique<render::Renderer>(context, scene.scene, pose, o);
  }

  // The renderer's request for a view of the current pose.
  render::ViewRequest request(const View& view) {
    render::FrameSettings settings = frameSettings(view, scene.scene, pose);
    const std::string name = view.method.empty() ? "auto" : view.method;
    const bool viewportOutput = view.output == View::Output::Viewport;
    if (!choice || choice->name() != name || viewportOutput != choice->viewport()) {
      try {
        choice.emplace(name, context.caps().driverRayTracing, viewportOutput);
      } catch (const std::invalid_argument& e) {
        throw Error(std::string("view: ") + e.what() +
                    (name == "driver-rt" ? " (make the Device with DeviceOptions::driverRayTracing)" : ""));
      }
    }
    drawn = choice->next();
    if (drawn == render::Method::RefractionMap) renderer->keepRefractionMap(pose, settings);  // at this pose
    return choice->view(drawn, settings, render::RasterOptions{});
  }

  void note(const render::FrameResult& result) {
    if (choice) choice->note(drawn, result.passes);
    const render::FrameStats& s = result.stats;
    last = FrameInfo{};
    last.frame = s.frame;
    last.treesRefit = s.treesRefit, last.treesBuilt = s.treesBuilt, last.treesSkipped = s.treesSkipped;
    last.pixelsTraced = s.pixelsTraced;
    last.skipped = s.viewsSkipped > 0;
    last.itemsDeformed = s.itemsDeformed;
    last.meshesUploaded = s.shapesCopied;
    last.meshesRefined = s.shapesRefined;
    last.verticesRefined = s.verticesRefined;
    last.topLevelBuilt = s.topLevelBuilt > 0, last.topLevelRefit = s.topLevelRefit > 0;
    last.dispatches = s.dispatches, last.draws = s.draws;
    last.method = render::methodName(drawn);
    for (const vk::PassTime& p : result.passes) last.passes.push_back(PassTime{p.name, p.milliseconds});
  }
};

Renderer::Renderer(Device& device, Scene& scene, const RendererOptions& options)
    : impl_(guarded([&] { return std::make_unique<Impl>(device, scene, options); })) {}
Renderer::~Renderer() {
  if (!impl_) return;  // moved from
  std::lock_guard lock(impl_->mutex);
  impl_->renderer.reset();
}
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

void Renderer::setTime(double seconds) {
  guarded([&] {
    if (!std::isfinite(seconds)) throw Error("setTime: the time is not finite");
    impl_->pose = scene::evaluate(impl_->scene.scene, seconds);
    for (const auto& [instance, world] : impl_->transforms) impl_->pose.items[instance].world = world;
  });
}

size_t Renderer::instanceCount() const { return impl_->pose.items.size(); }

void Renderer::setTransform(size_t instance, const Mat4& transform) {
  if (instance >= impl_->pose.items.size()) {
    throw Error("setTransform: no instance " + std::to_string(instance) + " of " +
                std::to_string(impl_->pose.items.size()));
  }
  for (float f : transform) {
    if (!std::isfinite(f)) throw Error("setTransform: instance " + std::to_string(instance) + "'s matrix is not finite");
  }
  impl_->transforms[instance] = toMatrix(transform);
  impl_->pose.items[instance].world = toMatrix(transform);
}

void Renderer::markDirty(int mesh) {
  guarded([&] {
    std::lock_guard lock(impl_->mutex);
    const size_t meshes = api::meshCount(impl_->scene.scene);
    if (mesh < 0 || size_t(mesh) >= meshes) {
      throw Error("markDirty: no mesh " + std::to_string(mesh) + " of " + std::to_string(meshes));
    }
    impl_->renderer->markDirty(mesh);
  });
}

Vertices Renderer::vertices(int mesh) {
  return guarded([&] {
    std::lock_guard lock(impl_->mutex);
    if (!impl_->scene.keep) throw Error("vertices: the scene's vertices are the host's own (only a HostScene without buffers has kept ones)");
    const size_t meshes = api::meshCount(impl_->scene.scene);
    if (mesh < 0 || size_t(mesh) >= meshes) {
      throw Error("vertices: no mesh " + std::to_string(mesh) + " of " + std::to_string(meshes));
    }
    render::KeptVertices kept = impl_->renderer->keptVertices(mesh);  // waits for the frames that read them
    return Vertices{kept.positions, kept.normals, kept.count};
  });
}

uint64_t Renderer::render(const View& view, const Target& target, const Sync& sync) {
  return guarded([&] {
    std::lock_guard lock(impl_->mutex);
    if (!target.image) throw Error("render: the target image is null");
    if (target.width != view.width || target.height != view.height) {
      throw Error("render: the target is " + std::to_string(target.width) + "x" + std::to_string(target.height) +
                  ", the view " + std::to_string(view.width) + "x" + std::to_string(view.height));
    }
    render::Renderer& renderer = *impl_->renderer;
    render::FrameRequest frame;
    frame.pose = &impl_->pose;
    frame.views.push_back(impl_->request(view));
    const bool composite = frame.views.back().output == render::ViewOutput::Composite;
    frame.record = [&](vk::Commands& commands) {
      const render::ViewImages& images = renderer.viewImages(0);
      commands.blitToImage(composite ? images.composite : images.trace,
                           {target.image, target.width, target.height, target.layoutBefore, target.layoutAfter});
    };
    frame.waitSemaphore = sync.wait;
    frame.waitStage = sync.wait ? sync.waitStage : 0;
    frame.signalSemaphore = sync.signal;
    return renderer.submit(frame);
  });
}

void Renderer::wait(uint64_t frame) {
  guarded([&] {
    std::lock_guard lock(impl_->mutex);
    impl_->note(impl_->renderer->wait(frame));
  });
}

std::vector<float> Renderer::read(const View& view) {
  std::vector<float> out(size_t(view.width) * view.height * 4);
  read(view, out.data());
  return out;
}

void Renderer::read(const View& view, float* rgba) {
  guarded([&] {
    std::lock_guard lock(impl_->mutex);
    if (!rgba) throw Error("read: the output is null");
    render::FrameRequest frame;
    frame.pose = &impl_->pose;
    frame.views.push_back(impl_->request(view));
    // Half floats, converted once, straight into the host's memory; a
    // composite's own picture is all the host asked for.
    frame.readbacks.push_back({.view = 0, .half = true, .trace = false});
    bool composite = frame.views.back().output == render::ViewOutput::Composite;
    const render::FrameResult& result = impl_->renderer->wait(impl_->renderer->submit(frame));
    impl_->note(result);
    const render::ViewPixels& pixels = result.views.at(0);
    const std::vector<uint16_t>& halves = composite ? pixels.compositeHalf : pixels.traceHalf;
    const std::array<float, 65536>& toFloat = halfTable();
    for (size_t i = 0; i < halves.size(); ++i) rgba[i] = toFloat[halves[i]];
  });
}

Aovs Renderer::readAovs(const View& view) {
  return guarded([&] {
    std::lock_guard lock(impl_->mutex);
    const std::string name = view.method.empty() ? "auto" : view.method;
    if (name != "auto" && name != "trace" && name != "trace-1") {
      throw Error("readAovs: the AOVs come from snell's trace; give the method auto, trace or trace-1, not '" + name + "'");
    }
    View traced = view;
    traced.output = View::Output::Trace;
    traced.method = name == "auto" ? "trace" : name;
    render::FrameRequest frame;
    frame.pose = &impl_->pose;
    frame.views.push_back(impl_->request(traced));
    render::ViewRequest& request = frame.views.back();
    request.aov = true;
    frame.readbacks.push_back({.view = 0});
    const render::FrameResult& result = impl_->renderer->wait(impl_->renderer->submit(frame));
    impl_->note(result);
    const render::ViewPixels& pixels = result.views.at(0);

    const size_t count = size_t(view.width) * view.height;
    Aovs out;
    out.width = view.width;
    out.height = view.height;
    out.rgba.resize(count * 4);
    out.depth.resize(count);
    out.normal.resize(count * 3);
    out.instance.resize(count);
    out.primitive.resize(count);
    out.interfaces.resize(count);
    out.cost.resize(count);
    const scene::Scene& model = impl_->scene.scene;
    auto kept = [&](int shape) -> const float* {
      return impl_->scene.keep ? impl_->renderer->keptVertices(shape).positions : nullptr;
    };
    render::FaceNormals normals(model, impl_->pose, kept);
    const std::vector<render::PixelHit> hits = render::pixelHits(pixels.aov);
    for (size_t p = 0; p < count; ++p) {
      const render::PixelHit& hit = hits[p];
      const bool covered = hit.distance >= 0.0;
      const glm::vec4& c = pixels.trace[p];
      std::copy_n(&c.x, 3, &out.rgba[4 * p]);
      out.rgba[4 * p + 3] = covered ? 1.0f : 0.0f;
      out.depth[p] = covered ? float(render::cameraDepth(request.settings.view, view.width, view.height, p, hit.distance))
                             : INFINITY;
      const glm::vec3 n = covered ? normals.of(hit.instance, hit.primitive) : glm::vec3(0.0f);
      std::copy_n(&n.x, 3, &out.normal[3 * p]);
      out.instance[p] = hit.instance;
      out.primitive[p] = hit.primitive;
      out.interfaces[p] = hit.interfaces;
      out.cost[p] = hit.cost;
    }
    return out;
  });
}

FrameInfo Renderer::lastFrame() const { return impl_->last; }

// ---------------------------------------------------------------- Shots

ShotSummary renderFrames(const std::string& devices, Scene& scene, const View& view,
                         const std::function<std::optional<ShotFrame>()>& next,
                         const std::function<void(ShotPicture&&)>& done, const DeviceOptions& options) {
  return guarded([&] {
    if (!next || !done) throw Error("renderFrames: give both the frames (next) and where they go (done)");
    const scene::Scene& model = scene.impl().scene;
    if (scene.impl().host.positions) {
      throw Error("renderFrames: " + model.source + "'s vertices are in the host's buffers, which only its own device reads");
    }
    const std::string method = view.method.empty() ? "auto" : view.method;
    const std::optional<render::Method> named = render::methodFromName(method);
    if (method != "auto" && !named) {
      throw Error("view: no method '" + method + "' (the methods: auto, " + render::methodNames() + ")");
    }
    render::ShotSettings settings;
    settings.frame = frameSettings(view, model, scene::evaluate(model, 0.0));
    settings.view = [&](const scene::Pose& pose) { return cameraOf(view, model, pose); };
    settings.method = method;
    settings.viewport = view.output == View::Output::Viewport;
    settings.keepVertices = scene.impl().keep;

    // No list: one worker, on the device `options` names (or snell's own choice).
    std::vector<render::ShotDevice> workers = render::shotDevices(devices, io::deviceEnvironment(), options.device);
    DeviceOptions shared = options;
    shared.device.clear();

    render::ShotIo io;
    io.next = [&]() -> std::optional<render::ShotFrame> {
      std::optional<ShotFrame> f = next();
      if (!f) return std::nullopt;
      render::ShotFrame frame{.number = f->number, .seconds = f->seconds};
      if (!std::isfinite(f->seconds)) throw Error("renderFrames: frame " + std::to_string(f->number) + "'s time is not finite");
      if (f->camera) frame.view = viewFromMatrices(*f->camera, view.width, view.height);
      for (const auto& [instance, matrix] : f->transforms) frame.transforms.emplace_back(instance, toMatrix(matrix));
      for (auto& [mesh, vertices] : f->vertices) {
        if (!scene.impl().keep) throw Error("renderFrames: frame " + std::to_string(f->number) + " gives vertices of a scene whose vertices snell does not keep");
        frame.vertices.push_back({mesh, std::move(vertices.positions), std::move(vertices.normals)});
      }
      return frame;
    };
    io.done = [&](render::ShotImage&& image) {
      ShotPicture picture{image.frame.number, image.frame.seconds, view.width, view.height, {}, image.worker,
                          image.device, image.method};
      const std::vector<uint16_t>& halves = image.rgbaHalf();
      const std::array<float, 65536>& toFloat = halfTable();
      picture.rgba.resize(halves.size());
      for (size_t i = 0; i < halves.size(); ++i) picture.rgba[i] = toFloat[halves[i]];
      done(std::move(picture));
    };
    const render::ShotReport report = render::renderShot(model, settings, contextDesc(shared), workers, io);
    ShotSummary summary;
    summary.frames = report.frames;
    summary.seconds = report.seconds;
    for (const render::ShotWorker& w : report.workers) {
      summary.workers.push_back({w.device, w.frames, w.loadSeconds, w.gpuWaitSeconds, w.lost, w.validationMessages});
    }
    return summary;
  });
}

// ---------------------------------------------------------------- SharedImage

struct SharedImage::Impl {
  vk::Image image;
};

SharedImage::SharedImage(Device& device, uint32_t width, uint32_t height, VkFormat format)
    : impl_(guarded([&] {
        vk::Context& context = *device.impl().context;
        if (width == 0 || height == 0) {
          throw Error("shared image: its size is " + std::to_string(width) + "x" + std::to_string(height));
        }
        if (!vkGetDeviceProcAddr(context.device(), "vkGetMemoryFdKHR")) {
          throw Error("shared image: vkGetMemoryFdKHR is missing: make the Device with DeviceOptions::interop");
        }
        vk::ImageDesc desc{width, height, format,
                           VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT,
                           "shared image", true};
        return std::make_unique<Impl>(Impl{vk::Image(context, desc)});
      })) {}
SharedImage::~SharedImage() = default;
SharedImage::SharedImage(SharedImage&&) noexcept = default;
SharedImage& SharedImage::operator=(SharedImage&&) noexcept = default;

Target SharedImage::target(VkImageLayout before, VkImageLayout after) const {
  const vk::Image& i = impl_->image;
  return Target{i.handle(), i.format(), i.width(), i.height(), before, after};
}

int SharedImage::exportMemory() const {
  return guarded([&] { return impl_->image.exportMemory(); });
}

uint64_t SharedImage::memorySize() const { return impl_->image.memorySize(); }
bool SharedImage::dedicated() const { return impl_->image.dedicatedMemory(); }
VkImage SharedImage::image() const { return impl_->image.handle(); }

// ---------------------------------------------------------------- SharedSemaphore

struct SharedSemaphore::Impl {
  vk::ExportableSemaphore semaphore;
};

SharedSemaphore::SharedSemaphore(Device& device)
    : impl_(guarded([&] {
        if (!device.exportsSemaphores()) {
          throw Error("shared semaphore: " + device.name() +
                      " cannot export semaphores as file descriptors (or the Device was made without interop)");
        }
        return std::make_unique<Impl>(Impl{vk::ExportableSemaphore(*device.impl().context, "shared semaphore")});
      })) {}
SharedSemaphore::~SharedSemaphore() = default;
SharedSemaphore::SharedSemaphore(SharedSemaphore&&) noexcept = default;
SharedSemaphore& SharedSemaphore::operator=(SharedSemaphore&&) noexcept = default;

VkSemaphore SharedSemaphore::handle() const { return impl_->semaphore.handle(); }

int SharedSemaphore::exportFd() const {
  return guarded([&] { return impl_->semaphore.exportFd(); });
}

}  // namespace snell
