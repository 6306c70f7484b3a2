// The frames of `snell render`, on one device or several (see render_shot.h).
#include "cli/render_shot.h"

#include "bake/refraction_bake.h"
#include "cli/exr_layers.h"
#include "io/environment.h"
#include "io/image_file.h"
#include "io/json.h"
#include "io/progress.h"
#include "ref/reference_tracer.h"
#include "render/renderer.h"
#include "render/shot.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "vk/context.h"
#include "vk/error.h"

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iterator>
#include <memory>
#include <mutex>

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
  if (s.traceLanes > 1) std::printf("; lanes a traced pixel %u", s.traceLanes);
  if (s.droppedTriangles) std::printf("; non-finite triangles dropped %u", s.droppedTriangles);
  std::printf("\n  GPU ms:");
  double total = 0;
  for (const vk::PassTime& p : passes) {
    std::printf(" %s %.3f,", p.name.c_str(), p.milliseconds);
    total += p.milliseconds;
  }
  std::printf(" total %.3f\n", total);
}

// One frame drawn, by a worker of the shot or by the reference, on its way to its file.
struct Drawn {
  long number = 0;
  double time = 0.0;
  size_t worker = 0;
  std::string device, why, method, methodLine;
  const scene::Pose* pose = nullptr;
  scene::View view;
  io::LinearImage image;
  std::vector<PixelHit> hits;  ///< the EXR's coverage and AOV layers (empty: none)
  const render::FrameStats* stats = nullptr;  ///< the GPU's counters (none for the reference)
  const std::vector<vk::PassTime>* passes = nullptr;
  const vk::DeviceFacts* facts = nullptr;  ///< the GPU's (none for the reference)
  double drawSeconds = 0.0;
};

// Writes the frames of one `snell render`: the image (and an EXR's header and
// layers), --stats lines, --stats-json and the progress. The shot's workers
// call it from their threads, so frames are encoded side by side.
class FrameWriter {
 public:
  FrameWriter(const RenderOptions& o, const scene::Scene& scene, size_t frames, size_t workers)
      : o_(o), scene_(scene), frames_(frames), workers_(workers),
        sceneHash_(o.statsJson.empty() ? std::string() : sceneHash(o)), progress_("frames", frames, quiet()) {}

  std::string pathOf(long frame) const { return o_.frames ? framePath(o_.output, frame) : o_.output; }
  size_t written() const {
    std::lock_guard lock(output_);
    return written_;
  }
  std::mutex& output() const { return output_; }

  void write(Drawn& d) {
    if (o_.stats && d.stats) {
      std::lock_guard lock(output_);
      printStats(d.number, *d.stats, *d.passes);
      if (o_.autoMethod) std::printf("  method %s\n", d.methodLine.c_str());
    }
    const auto writeStart = Clock::now();
    io::ImageExtras extras;
    if (o_.exr()) extras = exrExtras(o_, scene_, d.view, d.time, d.method, d.device);
    if (!d.hits.empty()) extras.aovs = aovLayers(o_, scene_, *d.pose, d.view, d.image, d.hits);
    const std::string path = pathOf(d.number);
    io::writeImage(path, d.image, extras);
    const double frameSeconds = d.drawSeconds + secondsSince(writeStart);
    if (!o_.statsJson.empty()) {
      io::Json j = io::reportHead("render-frame", d.facts);
      j["frame"] = d.number;
      j["time_seconds"] = d.time;
      j["frame_ms"] = 1000.0 * frameSeconds;
      j["image"] = path;
      j["image_hash"] = pixelHash(d.image);
      if (!d.why.empty()) j["device_from"] = d.why;
      j["worker"] = d.worker;
      j["workers"] = workers_;
      j["scene"] = o_.shot.eye ? std::string("procedural eye") : o_.shot.input;
      j["scene_hash"] = sceneHash_;
      j["method"] = d.method;
      j["width"] = o_.shot.width;
      j["height"] = o_.shot.height;
      io::writeJson(framePath(o_.statsJson, d.number), j);
    }

    std::lock_guard lock(output_);
    ++written_;
    if (frames_ > 1) {
      std::string detail = "frame " + std::to_string(d.number) + " -> " + path;
      if (workers_ > 1) detail += " (worker " + std::to_string(d.worker) + ", " + d.device + ")";
      progress_.update(written_, detail);
      return;
    }
    std::printf("wrote %s: %ux%u, %s, %s, %.2f s\n", path.c_str(), o_.shot.width, o_.shot.height,
                d.view.description.c_str(), d.device.c_str(), frameSeconds);
    if (!o_.aovs.empty()) {
      std::string layers;
      for (const io::AovLayer& l : extras.aovs) layers += (layers.empty() ? "" : ", ") + l.layer;
      std::printf("  AOV layers: %s\n", layers.c_str());
    }
    if (!d.methodLine.empty()) std::printf("  method %s\n", d.methodLine.c_str());
  }

 private:
  const RenderOptions& o_;
  const scene::Scene& scene_;
  size_t frames_, workers_;
  std::string sceneHash_;
  mutable std::mutex output_;  // progress and --stats lines, one frame's at a time
  io::Progress progress_;
  size_t written_ = 0;
};

// --reference: the CPU draws each frame in turn, in double precision.
void drawReference(const RenderOptions& o, const scene::Scene& scene,
                   const std::vector<std::pair<long, double>>& frames, FrameWriter& writer) {
  for (const auto& [number, time] : frames) {
    if (stopSignal) return;
    const auto start = Clock::now();
    const scene::Pose pose = scene::evaluate(scene, time);
    Drawn d{number, time, 0, "CPU reference", "", "reference", "", &pose, o.shot.resolveView("render", scene, pose)};
    ref::ReferenceSettings settings;
    settings.width = o.shot.width;
    settings.height = o.shot.height;
    settings.view = d.view;
    settings.background = glm::dvec3(o.shot.background);
    settings.maxInterfaces = o.shot.maxInterfaces;
    settings.optics = o.optics;
    ref::ReferenceImage r = ref::renderReference(scene, pose, settings);
    d.image = io::LinearImage{o.shot.width, o.shot.height, {}, {}};
    d.image.rgba.reserve(r.color.size());
    for (const glm::dvec3& c : r.color) d.image.rgba.emplace_back(glm::vec3(c), 1.0f);
    if (o.exr()) {
      d.hits.resize(d.image.pixels());
      for (size_t p = 0; p < d.hits.size(); ++p) {
        const bool hit = r.instance[p] >= 0;
        d.hits[p] = {hit ? r.distance[p] : -1.0, hit ? uint32_t(r.instance[p]) : gpu::kNoHit,
                     hit ? uint32_t(r.primitive[p]) : gpu::kNoHit, uint32_t(r.interfaces[p]), 0u};
      }
    }
    d.drawSeconds = secondsSince(start);
    if (stopSignal) return;  // the frame under way is dropped: only whole frames are ever written
    writer.write(d);
  }
}

// The shot's settings from the command line.
render::ShotSettings shotSettings(const RenderOptions& o, const scene::Scene& scene, double firstTime) {
  render::ShotSettings s;
  s.frame.width = o.shot.width;
  s.frame.height = o.shot.height;
  s.view = [&o, &scene](const scene::Pose& pose) { return o.shot.resolveView("render", scene, pose); };
  s.frame.background = o.shot.background;
  s.frame.backgroundAlpha = o.exr() ? 0.0f : 1.0f;  // an EXR's alpha is coverage: the raster clears it to 0
  s.frame.maxInterfaces = o.shot.maxInterfaces;
  s.frame.optics = o.optics;
  s.method = o.autoMethod ? std::string("auto") : std::string(render::methodName(*o.method));
  s.raster = o.raster;
  s.aov = o.exr();  // coverage (EXR alpha) comes from the trace's AOV
  s.bakeTime = o.bakeTime.value_or(firstTime);  // refraction-map's map: at the first frame's pose by default
  s.passTimes = o.stats || o.timePasses;
  return s;
}

}  // namespace

int renderShot(RenderOptions& o, render::ShotReport* report) {
  const auto start = Clock::now();
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
  const std::vector<render::ShotDevice> devices = render::shotDevices(o.devices, io::deviceEnvironment());
  scene::Scene scene = o.shot.loadScene();
  FrameWriter writer(o, scene, frames.size(), o.reference ? 1 : devices.size());

  stopSignal = 0;
  std::signal(SIGTERM, onStopSignal);
  std::signal(SIGINT, onStopSignal);
  render::ShotReport shot;
  std::exception_ptr failure;
  try {
    if (o.reference) {
      drawReference(o, scene, frames, writer);
    } else {
      const render::ShotSettings settings = shotSettings(o, scene, frames.front().second);
      render::ShotIo shotIo;
      size_t next = 0;
      shotIo.next = [&]() -> std::optional<render::ShotFrame> {
        if (next == frames.size()) return std::nullopt;
        const auto [number, time] = frames[next++];
        return render::ShotFrame{.number = number, .seconds = time};
      };
      shotIo.done = [&](render::ShotImage&& image) {
        Drawn d{image.frame.number, image.frame.seconds, image.worker, image.device, image.why, image.method,
                image.methodLine, &image.pose, image.view};
        d.image = io::LinearImage{o.shot.width, o.shot.height, {}, image.rgbaHalf()};
        if (!image.pixels.aov.empty()) d.hits = render::pixelHits(image.pixels.aov);
        d.stats = &image.stats;
        d.passes = &image.passes;
        d.drawSeconds = image.drawSeconds;
        d.facts = image.facts;
        writer.write(d);
      };
      shotIo.sinkOnWorkers = true;
      shotIo.opened = [&](size_t worker, const render::ShotWorker& w) {
        // A farm task's log says which GPU of the node it drew and why.
        if (frames.size() < 2 || quiet()) return;
        std::lock_guard lock(writer.output());
        std::printf("%sdevice %s (%s)\n", devices.size() > 1 ? ("worker " + std::to_string(worker) + ": ").c_str() : "",
                    w.device.c_str(), w.why.c_str());
        std::fflush(stdout);  // before the progress lines on stderr, in a farm's log too
      };
      shotIo.baked = [&](size_t worker, const render::RefractionBake& bake) {
        if (worker != 0) return;
        std::lock_guard lock(writer.output());
        std::printf("baked the refraction map at %g s: %s\n", settings.bakeTime,
                    bake::describe(bake, scene).c_str());
      };
      shotIo.stop = &stopSignal;
      try {
        shot = render::renderShot(scene, settings, io::contextDescFromEnvironment(), devices, shotIo);
      } catch (const std::invalid_argument& e) {
        throw UsageError{std::string("render: ") + e.what()};
      }
    }
  } catch (...) {
    failure = std::current_exception();
  }
  std::signal(SIGTERM, SIG_DFL);
  std::signal(SIGINT, SIG_DFL);
  if (failure) std::rethrow_exception(failure);

  shot.seconds = secondsSince(start);
  shot.frames = writer.written();
  if (report) *report = shot;
  if (stopSignal) {
    std::fprintf(stderr, "snell: render: stopped by signal %d; the frames written are whole, those under way were dropped\n",
                 int(stopSignal));
    return 128 + int(stopSignal);
  }
  for (size_t k = 0; k < shot.workers.size(); ++k) {
    const render::ShotWorker& w = shot.workers[k];
    if (w.lost.empty()) continue;
    std::fprintf(stderr, "snell: note: worker %zu lost its device after %zu frame(s); the others rendered the rest: %s\n",
                 k, w.frames, w.lost.c_str());
  }
  if (shot.workers.size() > 1 && !quiet()) {
    std::string split;
    for (const render::ShotWorker& w : shot.workers) {
      split += (split.empty() ? "" : ", ") + std::to_string(w.frames) + " on " + w.device;
    }
    std::printf("%zu frames on %zu devices in %.1f s: %s\n", shot.frames, shot.workers.size(), shot.seconds,
                split.c_str());
  }
  if (frames.size() > 1 && o.autoMethod && !quiet() && !shot.workers.empty()) {
    std::printf("method %s\n", shot.workers[0].method.c_str());
  }
  int code = kExitOk;
  for (const render::ShotWorker& w : shot.workers) {
    if (w.validationMessages == 0) continue;
    std::fprintf(stderr, "snell: the validation layer reported %llu message(s)\n",
                 static_cast<unsigned long long>(w.validationMessages));
    code = kExitFailure;
  }
  return code;
}

}  // namespace snell::cli
