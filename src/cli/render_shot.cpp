// The frames of `snell render`, on one device or several (see render_shot.h).
#include "cli/render_shot.h"

#include "bake/refraction_bake.h"
#include "cli/exr_layers.h"
#include "io/environment.h"
#include "io/image_file.h"
#include "io/json.h"
#include "io/progress.h"
#include "ref/reference_tracer.h"
#include "render/pass_names.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "vk/context.h"
#include "vk/error.h"

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <deque>
#include <exception>
#include <fstream>
#include <iterator>
#include <memory>
#include <mutex>
#include <thread>

namespace snell::cli {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// SIGTERM (a farm's scheduler ending the job) and SIGINT: the frames under way
// are dropped unwritten, those written stay, and the exit code is 128 + the signal.
volatile std::sig_atomic_t stopSignal = 0;
void onStopSignal(int signal) { stopSignal = signal; }

// 64-bit FNV-1a: a hash for "the same bytes", not for secrecy.
uint64_t fnv1a(const void* data, size_t bytes, uint64_t hash = 0xcbf29ce484222325ull) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < bytes; ++i) hash = (hash ^ p[i]) * 0x100000001b3ull;
  return hash;
}

std::string hex64(uint64_t value) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value));
  return text;
}

// The scene's identity for --stats-json: its file's bytes, or the procedural eye's options.
std::string sceneHash(const RenderOptions& o) {
  if (o.shot.eye) return "fnv1a64:" + hex64(fnv1a("procedural eye", 14));
  std::ifstream in(o.shot.input, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return "fnv1a64:" + hex64(fnv1a(bytes.data(), bytes.size()));
}

// The pixels' identity: the values written, before the file's encoding and metadata.
std::string pixelHash(const io::LinearImage& image) {
  if (!image.rgbaHalf.empty()) return "fnv1a64:" + hex64(fnv1a(image.rgbaHalf.data(), image.rgbaHalf.size() * 2));
  return "fnv1a64:" + hex64(fnv1a(image.rgba.data(), image.rgba.size() * sizeof(glm::vec4)));
}

// One frame's counters and pass times, for --stats: what a pipeline engineer
// reads to see that a still frame skipped its work.
void printStats(long frameNumber, const render::FrameStats& s, const std::vector<vk::PassTime>& passes) {
  std::printf("frame %ld: deformed %u (skipped %u); trees built %u, refit %u, skipped %u; triangles built %llu, "
              "refit %llu; top level built %u, refit %u, skipped %u; trace dispatches %u, pixels traced %llu; "
              "dispatches %u, draws %u",
              frameNumber, s.itemsDeformed, s.itemsDeformSkipped, s.treesBuilt, s.treesRefit, s.treesSkipped,
              static_cast<unsigned long long>(s.trianglesBuilt), static_cast<unsigned long long>(s.trianglesRefit),
              s.topLevelBuilt, s.topLevelRefit, s.topLevelSkipped, s.traceDispatches,
              static_cast<unsigned long long>(s.pixelsTraced), s.dispatches, s.draws);
  if (s.droppedTriangles) std::printf("; non-finite triangles dropped %u", s.droppedTriangles);
  std::printf("\n  GPU ms:");
  double total = 0;
  for (const vk::PassTime& p : passes) {
    std::printf(" %s %.3f,", p.name.c_str(), p.milliseconds);
    total += p.milliseconds;
  }
  std::printf(" total %.3f\n", total);
}

// The GPU passes that build or refit trees (and sort for them), for bench shot.
bool isTreePass(const std::string& name) {
  return name == pass::kBlasBuild || name == pass::kBlasRefit || name == pass::kTlas || name == pass::kSortHistogram || name == pass::kSortScan ||
         name == pass::kSortScatter;
}

// The frames still to render. Workers take the next as they finish one, so a
// slower device takes fewer; a worker whose device is lost gives its frame back.
class FrameQueue {
 public:
  explicit FrameQueue(size_t count) {
    for (size_t i = 0; i < count; ++i) pending_.push_back(i);
  }
  std::optional<size_t> take() {
    std::lock_guard lock(mutex_);
    if (pending_.empty()) return std::nullopt;
    size_t next = pending_.front();
    pending_.pop_front();
    return next;
  }
  void giveBack(size_t frame) {
    std::lock_guard lock(mutex_);
    pending_.push_front(frame);
  }

 private:
  std::mutex mutex_;
  std::deque<size_t> pending_;
};

// What every worker reads, and the little they share.
struct Shot {
  const RenderOptions& o;
  const scene::Scene& scene;
  std::vector<std::pair<long, double>> frames;  // (frame number, time)
  std::string sceneHash;
  size_t workers = 1;
  FrameQueue queue;
  std::mutex output;  // progress and --stats lines, one worker's at a time
  io::Progress progress;
  size_t written = 0;  // under `output`
  std::atomic<bool> failed{false};  // a worker failed for a reason other devices share: all stop

  std::string pathOf(long frame) const { return o.frames ? framePath(o.output, frame) : o.output; }
};

// One device: its context, renderer and trees, drawing frames from the queue.
class Worker {
 public:
  Worker(Shot& shot, size_t id, std::pair<std::string, std::string> device)
      : shot_(shot), o_(shot.o), id_(id), deviceOverride_(std::move(device.first)), why_(std::move(device.second)),
        raster_(shot.o.raster) {}

  // Never throws: what went wrong stays in error() for the caller.
  void run() {
    vk::setFaultWorker(int(id_));
    auto start = Clock::now();
    try {
      open();
      report_.loadSeconds = secondsSince(start);
      while (!stopSignal && !shot_.failed) {
        std::optional<size_t> frame = shot_.queue.take();
        if (!frame) break;
        try {
          draw(*frame);
        } catch (const vk::VulkanError& e) {
          if (e.result() == VK_ERROR_DEVICE_LOST) shot_.queue.giveBack(*frame);
          throw;
        }
      }
    } catch (const vk::VulkanError& e) {
      error_ = std::current_exception();
      lost_ = e.result() == VK_ERROR_DEVICE_LOST;
      report_.lost = e.what();
      if (!lost_) shot_.failed = true;
    } catch (...) {
      error_ = std::current_exception();
      shot_.failed = true;
    }
  }

  const WorkerReport& report() const { return report_; }
  std::exception_ptr error() const { return error_; }
  bool lostDevice() const { return lost_; }
  int validationCode() const { return context_ ? validationExitCode(*context_) : kExitOk; }
  std::string methodLine() const { return chooser_ ? chooser_->describe() : ""; }

 private:
  void open() {
    const scene::Scene& scene = shot_.scene;
    if (o_.reference) {
      report_.device = "CPU reference";
      return;
    }
    vk::ContextDesc desc = io::contextDescFromEnvironment();
    if (!deviceOverride_.empty()) desc.deviceOverride = deviceOverride_;
    desc.driverRayTracing = render::needsDriverRayTracing(*o_.method) || o_.autoMethod;
    context_ = vk::Context::create(desc);
    report_.device = context_->facts().name;
    if (render::needsDriverRayTracing(*o_.method) && !context_->caps().driverRayTracing) {
      throw std::runtime_error("render --method driver-rt: " + report_.device +
                               " offers no ray tracing pipelines (VK_KHR_ray_tracing_pipeline)");
    }
    try {
      render::checkImageSize(*context_, o_.shot.width, o_.shot.height);
    } catch (const std::invalid_argument& e) {
      throw UsageError{std::string("render: ") + e.what()};
    }
    render::RendererOptions options;
    options.passTimes = o_.stats || o_.autoMethod || o_.timePasses;  // timestamps only where someone reads them
    options.independentFrames = true;  // a frame's pixels are the same whichever worker, chunk or retry draws it
    scene::Pose firstPose = scene::evaluate(scene, shot_.frames.front().second);
    renderer_ = std::make_unique<render::Renderer>(*context_, scene, firstPose, options);
    chooser_.emplace(context_->caps().driverRayTracing, false, shot_.frames.size());
    // A farm task's log says which GPU of the node it drew and why.
    if (shot_.frames.size() > 1 && !quiet()) {
      std::lock_guard lock(shot_.output);
      std::printf("%sdevice %s (%s)\n", shot_.workers > 1 ? ("worker " + std::to_string(id_) + ": ").c_str() : "",
                  report_.device.c_str(), (why_.empty() ? context_->deviceWhy() : why_).c_str());
      std::fflush(stdout);  // before the progress lines on stderr, in a farm's log too
    }

    // refraction-map: the trace bakes the map once, at --bake-time (default:
    // the first frame's), and every frame reads it as the scene moves on.
    if (*o_.method == render::Method::RefractionMap) {
      double t = o_.bakeTime.value_or(shot_.frames.front().second);
      scene::Pose bakePose = scene::evaluate(scene, t);
      scene::View bakeView = o_.shot.resolveView("render", scene, bakePose);
      render::FrameSettings settings{o_.shot.width, o_.shot.height, bakeView, o_.shot.background, o_.shot.maxInterfaces};
      settings.optics = o_.optics;
      render::RefractionBake baked = renderer_->bakeRefractionMap(bakePose, settings);
      if (id_ == 0) std::printf("baked the refraction map at %g s: %s\n", t, bake::describe(baked, scene).c_str());
    }
  }

  // Renders and writes frame `index` of the shot, unless a signal came meanwhile.
  void draw(size_t index) {
    const scene::Scene& scene = shot_.scene;
    const auto [number, time] = shot_.frames[index];
    auto frameStart = Clock::now();
    scene::Pose pose = scene::evaluate(scene, time);
    scene::View view = o_.shot.resolveView("render", scene, pose);
    io::LinearImage image{o_.shot.width, o_.shot.height, {}, {}};
    std::string drawnWith = o_.reference ? "reference" : render::methodName(*o_.method);
    std::vector<PixelHit> hits;
    if (o_.reference) {
      ref::ReferenceSettings settings;
      settings.width = o_.shot.width;
      settings.height = o_.shot.height;
      settings.view = view;
      settings.background = glm::dvec3(o_.shot.background);
      settings.maxInterfaces = o_.shot.maxInterfaces;
      settings.optics = o_.optics;
      ref::ReferenceImage r = ref::renderReference(scene, pose, settings);
      image.rgba.reserve(r.color.size());
      for (const glm::dvec3& c : r.color) image.rgba.emplace_back(glm::vec3(c), 1.0f);
      if (o_.exr()) {
        hits.resize(image.pixels());
        for (size_t p = 0; p < hits.size(); ++p) {
          bool hit = r.instance[p] >= 0;
          hits[p] = {hit ? r.distance[p] : -1.0, hit ? uint32_t(r.instance[p]) : gpu::kNoHit,
                     hit ? uint32_t(r.primitive[p]) : gpu::kNoHit, uint32_t(r.interfaces[p]), 0u};
        }
      }
    } else {
      render::FrameSettings settings{o_.shot.width, o_.shot.height, view, o_.shot.background, o_.shot.maxInterfaces};
      settings.optics = o_.optics;
      if (o_.exr()) settings.backgroundAlpha = 0.0f;  // a composite's coverage: the raster clears alpha to 0
      render::RasterOptions raster = raster_;
      render::Method method = o_.autoMethod ? chooser_->next() : *o_.method;
      drawnWith = render::methodName(method);
      // Coverage (EXR alpha) comes from the trace's AOV, so an EXR trace asks for it.
      const bool wantAov = o_.exr() && !render::drawsComposite(*o_.method) && *o_.method != render::Method::DriverRt;
      render::ViewRequest request = render::methodView(method, settings, raster);
      request.aov = request.aov || wantAov;
      render::FrameRequest frame;
      frame.pose = &pose;
      frame.views.push_back(request);
      frame.readbacks.push_back({.view = 0, .half = true});
      auto waitStart = Clock::now();
      const render::FrameResult& result = renderer_->wait(renderer_->submit(frame));
      report_.gpuWaitSeconds += secondsSince(waitStart);
      for (const vk::PassTime& p : result.passes) report_.treeMs += isTreePass(p.name) ? p.milliseconds : 0.0;
      if (o_.autoMethod) chooser_->note(method, result.passes);
      const render::ViewPixels& pixels = result.views.at(0);
      image.rgbaHalf = render::drawsComposite(*o_.method) ? pixels.compositeHalf : pixels.traceHalf;
      if (wantAov) hits = render::pixelHits(pixels.aov);
      if (o_.stats) {
        std::lock_guard lock(shot_.output);
        printStats(number, result.stats, result.passes);
        if (o_.autoMethod) std::printf("  method %s\n", chooser_->describe().c_str());
      }
    }
    if (stopSignal) return;  // the frame under way is dropped: only whole frames are ever written

    auto writeStart = Clock::now();
    io::ImageExtras extras;
    if (o_.exr()) extras = exrExtras(o_, scene, view, time, drawnWith, report_.device);
    if (!hits.empty()) extras.aovs = aovLayers(o_, scene, pose, view, image, hits);
    const std::string path = shot_.pathOf(number);
    io::writeImage(path, image, extras);
    report_.writeSeconds += secondsSince(writeStart);
    ++report_.frames;
    if (!o_.statsJson.empty()) {
      io::Json j = io::reportHead("render-frame", context_ ? &context_->facts() : nullptr);
      j["frame"] = number;
      j["time_seconds"] = time;
      j["frame_ms"] = std::chrono::duration<double, std::milli>(Clock::now() - frameStart).count();
      j["image"] = path;
      j["image_hash"] = pixelHash(image);
      if (context_) j["device_from"] = why_.empty() ? context_->deviceWhy() : why_;
      j["worker"] = id_;
      j["workers"] = shot_.workers;
      j["scene"] = o_.shot.eye ? std::string("procedural eye") : o_.shot.input;
      j["scene_hash"] = shot_.sceneHash;
      j["method"] = drawnWith;
      j["width"] = o_.shot.width;
      j["height"] = o_.shot.height;
      io::writeJson(framePath(o_.statsJson, number), j);
    }

    std::lock_guard lock(shot_.output);
    ++shot_.written;
    if (shot_.frames.size() > 1) {
      std::string detail = "frame " + std::to_string(number) + " -> " + path;
      if (shot_.workers > 1) detail += " (worker " + std::to_string(id_) + ", " + report_.device + ")";
      shot_.progress.update(shot_.written, detail);
      return;
    }
    std::printf("wrote %s: %ux%u, %s, %s, %.2f s\n", path.c_str(), o_.shot.width, o_.shot.height,
                view.description.c_str(), report_.device.c_str(), secondsSince(frameStart));
    if (!o_.aovs.empty()) {
      std::string layers;
      for (const io::AovLayer& l : extras.aovs) layers += (layers.empty() ? "" : ", ") + l.layer;
      std::printf("  AOV layers: %s\n", layers.c_str());
    }
    if (!o_.reference && o_.autoMethod) {
      std::printf("  method %s\n", chooser_->describe().c_str());
    } else if (!o_.reference) {
      for (const render::MethodInfo& m : render::methods()) {
        if (m.method == *o_.method) std::printf("  method %s: %s\n", m.name, m.summary);
      }
    }
  }

  Shot& shot_;
  const RenderOptions& o_;
  size_t id_;
  std::string deviceOverride_;
  std::string why_;  // how --devices named it; empty: as the context found it
  render::RasterOptions raster_;
  std::unique_ptr<vk::Context> context_;
  std::unique_ptr<render::Renderer> renderer_;
  std::optional<render::AutoMethod> chooser_;
  WorkerReport report_;
  std::exception_ptr error_;
  bool lost_ = false;
};

// A device override per worker, and why: one, as --device or SNELL_DEVICE or
// a launcher picks it; or with --devices, one per device it names.
std::vector<std::pair<std::string, std::string>> workerDevices(const RenderOptions& o) {
  if (o.devices.empty() || o.reference) return {{"", ""}};
  std::string why;
  std::vector<std::pair<std::string, std::string>> overrides;
  for (uint32_t index : vk::devicesForList(o.devices, why)) overrides.emplace_back(std::to_string(index), why);
  return overrides;
}

}  // namespace

int renderShot(RenderOptions& o, ShotReport* report) {
  auto start = Clock::now();
  std::vector<std::pair<long, double>> frames;  // (frame number, time)
  if (o.frames) {
    for (long f : o.frames->frames) frames.emplace_back(f, double(f) / o.fps);
  } else {
    frames.emplace_back(0, o.shot.time);
  }
  auto pathOf = [&](long frame) { return o.frames ? framePath(o.output, frame) : o.output; };
  if (o.skipExisting) {
    size_t asked = frames.size();
    std::erase_if(frames, [&](const auto& f) { return std::filesystem::is_regular_file(pathOf(f.first)); });
    if (frames.size() < asked && !quiet()) {
      std::printf("skipping %zu of %zu frames: their files exist\n", asked - frames.size(), asked);
    }
    if (frames.empty()) return kExitOk;
  }
  io::checkWritable(pathOf(frames.front().first));
  if (!o.statsJson.empty()) io::checkWritable(framePath(o.statsJson, frames.front().first));
  if (!o.environment.empty()) o.optics.environment = std::make_shared<scene::Environment>(io::readEnvironment(o.environment));
  std::vector<std::pair<std::string, std::string>> devices = workerDevices(o);
  // auto times trace against driver-rt on each device, so two could choose differently.
  if (devices.size() > 1 && o.autoMethod) o.autoMethod = false;
  scene::Scene scene = o.shot.loadScene();

  Shot shot{o, scene, frames, o.statsJson.empty() ? std::string() : sceneHash(o), devices.size(),
            FrameQueue(frames.size()), {}, io::Progress("frames", frames.size(), quiet())};
  std::vector<std::unique_ptr<Worker>> workers;
  for (size_t k = 0; k < devices.size(); ++k) workers.push_back(std::make_unique<Worker>(shot, k, devices[k]));

  stopSignal = 0;
  std::signal(SIGTERM, onStopSignal);
  std::signal(SIGINT, onStopSignal);
  {
    std::vector<std::jthread> threads;
    for (size_t k = 1; k < workers.size(); ++k) threads.emplace_back([&worker = *workers[k]] { worker.run(); });
    workers[0]->run();
  }
  std::signal(SIGTERM, SIG_DFL);
  std::signal(SIGINT, SIG_DFL);

  if (report) {
    report->workers.clear();
    for (const auto& w : workers) report->workers.push_back(w->report());
    report->seconds = secondsSince(start);
    report->framesWritten = shot.written;
  }
  if (stopSignal) {
    std::fprintf(stderr, "snell: render: stopped by signal %d; the frames written are whole, those under way were dropped\n",
                 int(stopSignal));
    return 128 + int(stopSignal);
  }
  // A failure every device would meet (a file that cannot be written): the first one's error.
  for (const auto& w : workers) {
    if (w->error() && !w->lostDevice()) std::rethrow_exception(w->error());
  }
  // Lost devices: fatal only when their frames found no other device.
  for (size_t k = 0; k < workers.size(); ++k) {
    if (!workers[k]->lostDevice()) continue;
    if (shot.written < frames.size()) std::rethrow_exception(workers[k]->error());
    std::fprintf(stderr, "snell: note: worker %zu lost its device after %zu frame(s); the others rendered the rest: %s\n",
                 k, workers[k]->report().frames, workers[k]->report().lost.c_str());
  }
  if (workers.size() > 1 && !quiet()) {
    std::string split;
    for (const auto& w : workers) {
      split += (split.empty() ? "" : ", ") + std::to_string(w->report().frames) + " on " + w->report().device;
    }
    std::printf("%zu frames on %zu devices in %.1f s: %s\n", shot.written, workers.size(), secondsSince(start),
                split.c_str());
  }
  if (frames.size() > 1 && o.autoMethod && !quiet()) std::printf("method %s\n", workers[0]->methodLine().c_str());
  int code = kExitOk;
  for (const auto& w : workers) code = std::max(code, w->validationCode());
  return code;
}

}  // namespace snell::cli
