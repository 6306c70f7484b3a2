// `snell render SCENE -o OUT.png|OUT.exr`: headless frames of a glTF scene,
// traced on the GPU (or by the CPU reference with --reference), or with
// --viewport the viewer's composite: rasterized, with the trace on glass.
// EXR files carry alpha = coverage, the camera and time as metadata, and on
// request the trace's per-pixel AOVs as named layers.
#include "cli/commands.h"
#include "cli/frames.h"

#include "bake/refraction_bake.h"
#include "io/image_file.h"
#include "io/json.h"
#include "io/progress.h"
#include "ref/reference_tracer.h"
#include "render/method.h"
#include "render/raster_pass.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "scene/view.h"
#include "vk/context.h"

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>

namespace snell::cli {

namespace {

constexpr const char* kDescription =
    "Ray traces the scene on the GPU: one ray per pixel, refracted through every\n"
    "transmissive face (KHR_materials_transmission, KHR_materials_ior, _volume,\n"
    "_dispersion; overlapping glass by priority), Phong-shaded where it lands. Glass\n"
    "reflects by Fresnel: the lights as highlights (an eye's catch lights) and the\n"
    "environment. PNG is written as 8-bit sRGB; EXR as linear half floats (or\n"
    "--float) with alpha = coverage (1 where the pixel's ray met a surface), the\n"
    "camera, time, method, device and snell version in its header, and with --aov\n"
    "the trace's per-pixel data as layers compositors read. A file appears only\n"
    "once it is complete.\n"
    "\n"
    "Frames a farm can trust: --frames takes the lists farms write, and a frame's\n"
    "pixels depend on nothing but the scene, its number and the options (each is\n"
    "traced from trees built afresh), so any chunk, retry or node with the same\n"
    "GPU and driver writes the same pixels; give --method trace, as auto may pick\n"
    "driver-rt by timing. Off a terminal, progress is one line per frame.\n"
    "SIGTERM or SIGINT drops the frame under way, keeps those written and exits\n"
    "128+N; --skip-existing then picks up where it stopped. 'snell farm' sends\n"
    "a shot to Slurm or writes an Open Job Description template.";

/// The AOV layers --aov may name, in the order they are written.
const std::vector<std::string> kAovNames = {"depth", "normal", "instance", "primitive", "interfaces", "cost"};

struct Options {
  ShotOptions shot;
  std::string output;
  std::optional<FrameList> frames;  ///< --frames; none: one picture at --time
  double fps = 24.0;
  bool skipExisting = false;
  std::string statsJson;  ///< a per-frame JSON's name pattern; empty: none
  std::optional<double> bakeTime;
  bool reference = false;
  bool viewport = false;
  std::optional<render::Method> method;
  bool autoMethod = false;  ///< --method auto (the default for a trace): trace or driver-rt, timed
  bool stats = false;
  render::RasterOptions raster;
  scene::Optics optics;
  std::string environment;
  std::vector<std::string> aovs;
  bool floatPixels = false;

  bool exr() const {
    std::string ext = std::filesystem::path(output).extension().string();
    return ext == ".exr" || ext == ".EXR";
  }
  bool wants(const std::string& aov) const { return std::find(aovs.begin(), aovs.end(), aov) != aovs.end(); }
};

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


// Camera-space depth along the view axis from the trace's distance along
// each pixel's unit ray (the reference tracer's ray, in double).
double depthOf(const scene::View& view, uint32_t width, uint32_t height, size_t pixel, double distance) {
  if (view.orthographic) return distance;
  double w = width, h = height;
  double x = double(pixel % width), y = double(pixel / width);
  double sx = (2.0 * (x + 0.5) / w - 1.0) * view.halfHeight * w / h + view.shift.x;
  double sy = (1.0 - 2.0 * (y + 0.5) / h) * view.halfHeight + view.shift.y;
  return distance / std::sqrt(1.0 + sx * sx + sy * sy);
}

// The world-space face normal of each (item, triangle) the pixels hit, from
// the item's deformed positions at this pose (deformed once per item).
class FaceNormals {
 public:
  FaceNormals(const scene::Scene& scene, const scene::Pose& pose) : scene_(scene), pose_(pose) {}
  glm::vec3 of(uint32_t item, uint32_t triangle) {
    if (item >= pose_.items.size()) return glm::vec3(0.0f);
    const scene::DrawItem& drawn = pose_.items[item];
    auto [at, fresh] = items_.try_emplace(item);
    Deformed& d = at->second;
    if (fresh) {
      std::vector<glm::dvec3> normals;
      scene::deformOnCpu(drawn, d.positions, normals);
      d.normalToWorld = glm::transpose(glm::inverse(glm::dmat3(drawn.world)));
    }
    const std::vector<uint32_t>& indices = scene_.shapes[size_t(drawn.shape)].indices;
    if (3 * size_t(triangle) + 2 >= indices.size()) return glm::vec3(0.0f);
    const std::vector<glm::dvec3>& p = d.positions;
    glm::dvec3 a = p[indices[3 * triangle]], b = p[indices[3 * triangle + 1]], c = p[indices[3 * triangle + 2]];
    glm::dvec3 n = d.normalToWorld * glm::cross(b - a, c - a);
    double length = glm::length(n);
    return length > 0.0 ? glm::vec3(n / length) : glm::vec3(0.0f);
  }

 private:
  struct Deformed {
    std::vector<glm::dvec3> positions;
    glm::dmat3 normalToWorld{1.0};
  };
  const scene::Scene& scene_;
  const scene::Pose& pose_;
  std::map<uint32_t, Deformed> items_;
};

// What one pixel's trace found, from the GPU's AOV or the reference.
struct PixelHit {
  double distance;  // < 0: missed
  uint32_t instance, primitive, interfaces, cost;
};

// Alpha = coverage written into the image, and the layers --aov asked for.
std::vector<io::AovLayer> aovLayers(const Options& o, const scene::Scene& scene, const scene::Pose& pose,
                                    const scene::View& view, io::LinearImage& image, const std::vector<PixelHit>& hits) {
  const size_t pixels = image.pixels();
  const uint16_t one = glm::packHalf1x16(1.0f), zero = glm::packHalf1x16(0.0f);
  for (size_t i = 0; i < pixels; ++i) {
    bool covered = hits[i].distance >= 0.0;
    if (image.rgba.empty()) image.rgbaHalf[4 * i + 3] = covered ? one : zero;
    else image.rgba[i].a = covered ? 1.0f : 0.0f;
  }
  std::vector<io::AovLayer> layers;
  for (const std::string& name : kAovNames) {
    if (!o.wants(name)) continue;
    io::AovLayer& l = layers.emplace_back();
    l.layer = name;
    if (name == "depth") {
      l.channels = {"Z"};
      l.values.resize(pixels);
      for (size_t i = 0; i < pixels; ++i) {
        l.values[i] = hits[i].distance >= 0.0 ? float(depthOf(view, image.width, image.height, i, hits[i].distance))
                                              : std::numeric_limits<float>::infinity();
      }
    } else if (name == "normal") {
      FaceNormals normals(scene, pose);
      l.channels = {"X", "Y", "Z"};
      l.values.resize(3 * pixels);
      for (size_t i = 0; i < pixels; ++i) {
        glm::vec3 n = hits[i].distance >= 0.0 ? normals.of(hits[i].instance, hits[i].primitive) : glm::vec3(0.0f);
        for (int c = 0; c < 3; ++c) l.values[3 * i + size_t(c)] = n[c];
      }
    } else {
      uint32_t PixelHit::*field = name == "instance"   ? &PixelHit::instance
                                  : name == "primitive"  ? &PixelHit::primitive
                                  : name == "interfaces" ? &PixelHit::interfaces
                                                         : &PixelHit::cost;
      l.channels = {name == "interfaces" ? "count" : name == "cost" ? "nodes" : "id"};
      l.integer = true;
      l.ids.resize(pixels);
      for (size_t i = 0; i < pixels; ++i) l.ids[i] = hits[i].*field;
    }
  }
  return layers;
}

// The EXR header: what a compositor or a pipeline wants to know about the frame.
io::ImageExtras exrExtras(const Options& o, const scene::Scene& scene, const scene::View& view, double time,
                          const std::string& device) {
  io::ImageExtras extras;
  extras.floatPixels = o.floatPixels;
  extras.text = {{"snell:scene", scene.source},
                 {"snell:camera", view.description},
                 {"snell:method", o.reference ? "reference" : render::methodName(*o.method)},
                 {"snell:device", device},
                 {"snell:version", io::version()},
                 {"snell:command_line", io::commandLine()}};
  extras.numbers = {{"snell:time", float(time)},
                    {"snell:vertical_fov_degrees",
                     view.orthographic ? 0.0f : float(2.0 * std::atan(view.halfHeight) * 180.0 / 3.14159265358979)}};
  // Camera space as OpenGL has it: x right, y up, looking down -z.
  glm::dmat4 cameraToWorld(glm::dvec4(view.right, 0.0), glm::dvec4(view.up, 0.0), glm::dvec4(-view.forward, 0.0),
                           glm::dvec4(view.eye, 1.0));
  extras.worldToCamera = glm::mat4(glm::inverse(cameraToWorld));
  extras.hasWorldToCamera = true;
  return extras;
}


void addOptions(CLI::App& render, Options& o) {
  render.add_option("-o,--output", o.output,
                    "the image to write: .png or .exr; with --frames, the name\n"
                    "holds the frame number: '#'s (shot.####.exr: shot.0042.exr)\n"
                    "or a printf %04d")
      ->required()
      ->type_name("FILE")
      ->check([](const std::string& path) -> std::string {
        std::string ext = std::filesystem::path(path).extension().string();
        return ext == ".png" || ext == ".exr" || ext == ".PNG" || ext == ".EXR" ? "" : "must end in .png or .exr, got '" + path + "'";
      });
  o.shot.addTo(render);
  CLI::Option* frames = render.add_option_function<std::string>(
      "--frames", [&o](const std::string& v) { o.frames = FrameList::parse("--frames", v); },
      "render these frames at --fps: 1-240, 1-240x4 (every 4th),\n"
      "1:240:4 (the same), 1,5,10-20; in increasing order, each once");
  frames->type_name("LIST")->excludes(o.shot.timeOption);
  render.add_flag("--skip-existing", o.skipExisting,
                  "leave frames whose file exists alone: files appear only\n"
                  "when complete, so an existing one is a finished frame");
  render.add_option("--stats-json", o.statsJson,
                    "beside each frame, a JSON of its own: frame, time, device,\n"
                    "driver, and hashes of the scene file and of the pixels\n"
                    "(the same pixels hash the same on every machine)")
      ->type_name("PATTERN");
  render.add_option("--fps", o.fps, "frames per second for --frames (default 24)")
      ->type_name("N")
      ->check(CLI::PositiveNumber & finite())
      ->needs(frames);
  render.add_option_function<double>("--bake-time", [&o](double t) { o.bakeTime = t; },
                                     "refraction-map's pose: the seconds the map is baked at\n(default: the first frame's time)")
      ->type_name("T")
      ->check(finite());
  render.add_flag("--reference", o.reference,
                  "render with the CPU double-precision reference instead\n"
                  "of the GPU (slow; golden images are made this way)");
  render.add_option_function<std::string>(
         "--method",
         [&o](const std::string& name) {
           o.autoMethod = name == "auto";
           o.method = o.autoMethod ? std::nullopt : render::methodFromName(name);
           if (!o.method && !o.autoMethod) {
             throw UsageError{"--method takes auto or one of " + render::methodNames() + ", got '" + name + "'"};
           }
         },
         "how refraction is drawn (default auto): auto (trace,\n"
         "or driver-rt where the first frames time it faster;\n"
         "EXR and AOV need trace, so there it is trace), trace,\n"
         "trace-1 (bends at the first interface only), masked\n"
         "(the viewport: raster, glass pixels traced),\n"
         "iris-plane and normal-offset (raster, no trace),\n"
         "refraction-map (raster, no trace: the texture\n"
         "behind the glass read where a map baked by the\n"
         "trace at --bake-time says, as the scene moves on),\n"
         "none (glass seen straight through), driver-rt\n"
         "(the trace's rays through the driver's own ray\n"
         "tracing, where the GPU has it)")
      ->type_name("M");
  render.add_option("--offset-strength", o.raster.offsetStrength, "normal-offset's displacement in image heights (0.02)")
      ->type_name("S")
      ->check(CLI::Range(-10.0f, 10.0f));
  render.add_option("--environment", o.environment,
                    "what glass reflects: an equirectangular HDR, EXR or PNG\n(+Y up, -Z in the middle; default: a studio gradient)")
      ->type_name("FILE")
      ->check(CLI::ExistingFile);
  render.add_option("--reflections", o.optics.reflections,
                    "interfaces per ray that send a reflected ray (default 1, at most 1024)")
      ->type_name("N")
      ->check(CLI::Range(0u, 1024u));
  render.add_flag_callback("--no-fresnel", [&o] { o.optics.fresnel = false; }, "glass transmits everything and reflects nothing");
  render.add_flag_callback("--no-dispersion", [&o] { o.optics.dispersion = false; },
                           "dispersive glass (KHR_materials_dispersion) bends every colour alike");
  render.add_flag_callback("--no-volume", [&o] { o.optics.volume = false; },
                           "thick glass (KHR_materials_volume) tints nothing, as if thin-walled");
  render.add_flag("--viewport", o.viewport,
                  "write the viewport's composite instead of the trace\n"
                  "alone: every face rasterized and Phong-shaded, and\n"
                  "transmissive faces showing the traced image (what\n"
                  "snell-view shows); the same as --method masked");
  render.add_flag_callback("--no-refraction", [&o] { o.raster.refraction = false; },
                           "with --viewport: see through glass without bending (--method none)");
  render.add_flag("--wireframe", o.raster.wireframe, "with --viewport: draw triangle edges over the image");
  render.add_flag("--stats", o.stats,
                  "print each frame's work: what was deformed, refit,\n"
                  "rebuilt or skipped, pixels traced, dispatches, and the\n"
                  "GPU time of each pass");
  render.add_option("--aov", o.aovs,
                    "with an .exr: add the trace's per-pixel data as layers,\n"
                    "any of depth (depth.Z, camera-space, +inf on a miss),\n"
                    "normal (normal.XYZ, world-space face normal), instance\n"
                    "(instance.id, the draw item hit), primitive (primitive.id,\n"
                    "its triangle), interfaces (interfaces.count, refractive\n"
                    "faces crossed), cost (cost.nodes, BVH nodes visited);\n"
                    "ids are 32-bit unsigned, 4294967295 on a miss")
      ->type_name("LIST")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->check(CLI::IsMember(kAovNames));
  render.add_flag("--float", o.floatPixels, "with an .exr: 32-bit float channels instead of half");
}

// The checks that need several options at once.
void check(Options& o) {
  o.shot.require("render");
  if (o.stats && o.reference) throw UsageError{"render: --stats counts GPU work; the reference (--reference) has none"};
  if (o.viewport && o.reference) {
    throw UsageError{"render: --viewport is drawn on the GPU; the reference traces (--reference) without it"};
  }
  if ((o.method || o.autoMethod) && o.reference) {
    throw UsageError{"render: --method draws on the GPU; the reference (--reference) is the physics they approximate"};
  }
  if (o.method && o.viewport && !render::drawsComposite(*o.method)) {
    throw UsageError{std::string("render: --method ") + render::methodName(*o.method) +
                     " draws the trace image, not the viewport (--viewport)"};
  }
  if (!o.method) {
    // No method, or auto: a trace (auto picks its hits' source per frame), or the viewport's.
    o.autoMethod = o.autoMethod || (!o.viewport && !o.reference);
    o.method = !o.viewport ? render::Method::Trace : o.raster.refraction ? render::Method::Masked : render::Method::None;
  } else if (!o.raster.refraction) {
    if (*o.method != render::Method::None && render::drawsComposite(*o.method)) {
      throw UsageError{"render: --no-refraction is --method none; it cannot go with --method " +
                       std::string(render::methodName(*o.method))};
    }
    o.method = render::Method::None;
  }
  if (!render::drawsComposite(*o.method) && (!o.raster.refraction || o.raster.wireframe)) {
    throw UsageError{"render: --no-refraction and --wireframe need --viewport (or a viewport --method)"};
  }
  if (o.bakeTime && *o.method != render::Method::RefractionMap) {
    throw UsageError{"render: --bake-time is for --method refraction-map"};
  }
  if ((!o.aovs.empty() || o.floatPixels) && !o.exr()) {
    throw UsageError{std::string("render: ") + (o.floatPixels ? "--float" : "--aov") + " needs an .exr output, got '" +
                     o.output + "'"};
  }
  if (!o.aovs.empty() && !o.reference && *o.method != render::Method::Trace && *o.method != render::Method::TraceOnce) {
    throw UsageError{std::string("render: --aov comes from the trace of every pixel (--method trace or trace-1, or "
                                 "--reference), not --method ") + render::methodName(*o.method)};
  }
  if (o.reference && o.wants("cost")) throw UsageError{"render: --aov cost counts BVH nodes on the GPU; the reference has none"};
  // EXR coverage and AOVs come from the trace's own per-pixel data, which the driver's ray tracing has not.
  if (o.exr() || o.viewport || o.reference) o.autoMethod = false;
  size_t frames = o.frames ? o.frames->size() : 1;
  checkFramePattern("-o", o.output, frames);
  if (!o.statsJson.empty()) checkFramePattern("--stats-json", o.statsJson, frames);
}

// SIGTERM (a farm's scheduler ending the job) and SIGINT: the frame under way
// is dropped unwritten, those written stay, and the exit code is 128 + the signal.
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
std::string sceneHash(const Options& o) {
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


int runRender(Options& o) {
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
  scene::Scene scene = o.shot.loadScene();
  const std::string hashOfScene = o.statsJson.empty() ? std::string() : sceneHash(o);
  stopSignal = 0;
  std::signal(SIGTERM, onStopSignal);
  std::signal(SIGINT, onStopSignal);

  scene::Pose layout = scene::evaluate(scene, frames.front().second);
  std::unique_ptr<vk::Context> context;
  std::unique_ptr<render::Renderer> renderer;
  if (!o.reference) {
    vk::ContextDesc desc = io::contextDescFromEnvironment();
    desc.driverRayTracing = render::needsDriverRayTracing(*o.method) || o.autoMethod;
    context = vk::Context::create(desc);
    if (render::needsDriverRayTracing(*o.method) && !context->caps().driverRayTracing) {
      throw std::runtime_error("render --method driver-rt: " + context->facts().name +
                               " offers no ray tracing pipelines (VK_KHR_ray_tracing_pipeline)");
    }
    try {
      render::checkImageSize(*context, o.shot.width, o.shot.height);
    } catch (const std::invalid_argument& e) {
      throw UsageError{std::string("render: ") + e.what()};
    }
    render::RendererOptions options;
    options.passTimes = o.stats || o.autoMethod;  // timestamps only where someone reads them
    options.independentFrames = true;  // a frame's pixels are the same in whichever chunk a farm renders it
    renderer = std::make_unique<render::Renderer>(*context, scene, layout, options);
  }
  const std::string device = o.reference ? "CPU reference" : context->facts().name;

  // refraction-map: the trace bakes the map once, at --bake-time (default:
  // the first frame's), and every frame reads it as the scene moves on.
  render::RefractionMapBuffer map;
  if (renderer && *o.method == render::Method::RefractionMap) {
    double t = o.bakeTime.value_or(frames.front().second);
    scene::Pose bakePose = scene::evaluate(scene, t);
    scene::View bakeView = o.shot.resolveView("render", scene, bakePose);
    render::FrameSettings settings{o.shot.width, o.shot.height, bakeView, o.shot.background, o.shot.maxInterfaces};
    settings.optics = o.optics;
    bake::RefractionBake baked = bake::bakeRefraction(*context, *renderer, bakePose, settings);
    map = bake::uploadRefractionMap(*context, baked);
    o.raster.refractionMap = &map;
    std::printf("baked the refraction map at %g s: %s\n", t, bake::describe(baked, scene).c_str());
  }

  // Coverage (EXR alpha) comes from the trace's AOV, so an EXR trace asks for it.
  const bool traced = !render::drawsComposite(*o.method) && *o.method != render::Method::DriverRt;
  render::AutoMethod chooser(context && context->caps().driverRayTracing, false, frames.size());
  const bool wantAov = o.exr() && traced;
  io::Progress progress("frames", frames.size(), quiet());
  // A farm task's log says which GPU of the node it drew and why.
  if (context && frames.size() > 1 && !quiet()) {
    std::printf("device %s (%s)\n", device.c_str(), context->deviceWhy().c_str());
    std::fflush(stdout);  // before the progress lines on stderr, in a farm's log too
  }
  auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < frames.size(); ++i) {
    if (stopSignal) break;
    auto frameStart = std::chrono::steady_clock::now();
    scene::Pose pose = i == 0 ? layout : scene::evaluate(scene, frames[i].second);
    scene::View view = o.shot.resolveView("render", scene, pose);
    io::LinearImage image{o.shot.width, o.shot.height, {}, {}};
    std::string drawnWith = o.reference ? "reference" : render::methodName(*o.method);
    io::ImageExtras extras;
    if (o.exr()) extras = exrExtras(o, scene, view, frames[i].second, device);
    if (o.reference) {
      ref::ReferenceSettings settings;
      settings.width = o.shot.width;
      settings.height = o.shot.height;
      settings.view = view;
      settings.background = glm::dvec3(o.shot.background);
      settings.maxInterfaces = o.shot.maxInterfaces;
      settings.optics = o.optics;
      ref::ReferenceImage r = ref::renderReference(scene, pose, settings);
      image.rgba.reserve(r.color.size());
      for (const glm::dvec3& c : r.color) image.rgba.emplace_back(glm::vec3(c), 1.0f);
      if (o.exr()) {
        std::vector<PixelHit> hits(image.pixels());
        for (size_t p = 0; p < hits.size(); ++p) {
          bool hit = r.instance[p] >= 0;
          hits[p] = {hit ? r.distance[p] : -1.0, hit ? uint32_t(r.instance[p]) : gpu::kNoHit,
                     hit ? uint32_t(r.primitive[p]) : gpu::kNoHit, uint32_t(r.interfaces[p]), 0u};
        }
        extras.aovs = aovLayers(o, scene, pose, view, image, hits);
      }
    } else {
      render::FrameSettings settings{o.shot.width, o.shot.height, view, o.shot.background, o.shot.maxInterfaces};
      settings.optics = o.optics;
      if (o.exr()) settings.backgroundAlpha = 0.0f;  // a composite's coverage: the raster clears alpha to 0
      render::RasterOptions raster = o.raster;
      glm::dvec3 lo, hi;
      scene::sceneBounds(scene, pose, lo, hi);
      render::fitDepthRange(view, lo, hi, raster);
      render::Method method = o.autoMethod ? chooser.next() : *o.method;
      drawnWith = render::methodName(method);
      render::ViewRequest request = render::methodView(method, settings, raster);
      request.readback.enabled = true;
      request.readback.half = true;
      request.aov = request.aov || wantAov;
      render::FrameRequest frame;
      frame.pose = &pose;
      frame.views.push_back(request);
      const render::FrameResult& result = renderer->wait(renderer->submit(frame));
      if (o.autoMethod) chooser.note(method, result.passes);
      const render::ViewPixels& pixels = result.views.at(0);
      image.rgbaHalf = render::drawsComposite(*o.method) ? pixels.compositeHalf : pixels.traceHalf;
      if (wantAov) {
        std::vector<PixelHit> hits(image.pixels());
        for (size_t p = 0; p < hits.size(); ++p) {
          const gpu::TraceAov& a = pixels.aov[p];
          hits[p] = {a.instance == gpu::kNoHit ? -1.0 : double(a.distance), a.instance, a.primitive, a.interfaces,
                     a.nodeVisits};
        }
        extras.aovs = aovLayers(o, scene, pose, view, image, hits);
      }
      if (o.stats) printStats(frames[i].first, result.stats, result.passes);
      if (o.stats && o.autoMethod) std::printf("  method %s\n", chooser.describe().c_str());
    }
    if (stopSignal) break;  // the frame under way is dropped: only whole frames are ever written
    std::string path = pathOf(frames[i].first);
    io::writeImage(path, image, extras);
    if (!o.statsJson.empty()) {
      io::Json j = io::reportHead("render-frame", context ? &context->facts() : nullptr);
      j["frame"] = frames[i].first;
      j["time_seconds"] = frames[i].second;
      j["frame_ms"] = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - frameStart).count();
      j["image"] = path;
      j["image_hash"] = pixelHash(image);
      if (context) j["device_from"] = context->deviceWhy();
      j["scene"] = o.shot.eye ? std::string("procedural eye") : o.shot.input;
      j["scene_hash"] = hashOfScene;
      j["method"] = drawnWith;
      j["width"] = o.shot.width;
      j["height"] = o.shot.height;
      io::writeJson(framePath(o.statsJson, frames[i].first), j);
    }
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (frames.size() > 1) {
      progress.update(i + 1, "frame " + std::to_string(frames[i].first) + " -> " + path);
    } else {
      std::printf("wrote %s: %ux%u, %s, %s, %.2f s\n", path.c_str(), o.shot.width, o.shot.height, view.description.c_str(),
                  device.c_str(), seconds);
      if (!o.aovs.empty()) {
        std::string layers;
        for (const io::AovLayer& l : extras.aovs) layers += (layers.empty() ? "" : ", ") + l.layer;
        std::printf("  AOV layers: %s\n", layers.c_str());
      }
      if (!o.reference && o.autoMethod) {
        std::printf("  method %s\n", chooser.describe().c_str());
      } else if (!o.reference) {
        for (const render::MethodInfo& m : render::methods()) {
          if (m.method == *o.method) std::printf("  method %s: %s\n", m.name, m.summary);
        }
      }
    }
  }
  std::signal(SIGTERM, SIG_DFL);
  std::signal(SIGINT, SIG_DFL);
  if (stopSignal) {
    std::fprintf(stderr, "snell: render: stopped by signal %d; the frames written are whole, the one under way was dropped\n",
                 int(stopSignal));
    return 128 + int(stopSignal);
  }
  if (frames.size() > 1 && o.autoMethod && !quiet()) std::printf("method %s\n", chooser.describe().c_str());
  return context ? validationExitCode(*context) : kExitOk;
}

}  // namespace

RenderCheck checkRender(const Args& args) {
  Options o;
  CLI::App render("render", "render");
  render.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);
  addGlobalOptions(render);  // `snell render` takes --device and --quiet after it too
  addOptions(render, o);
  try {
    parseOnly(render, args);
    check(o);
  } catch (const UsageError& e) {
    throw UsageError{"render options: " + e.message};
  }
  if (!o.environment.empty()) io::readEnvironment(o.environment);
  scene::Scene scene = o.shot.loadScene();
  RenderCheck result;
  result.scene = scene.source;
  result.autoMethod = o.autoMethod;
  result.method = o.reference ? "reference" : render::methodName(*o.method);
  result.bakeTimeGiven = o.bakeTime.has_value();
  result.fps = o.fps;
  return result;
}

void addRender(CLI::App& parent, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* render = parent.add_subcommand("render", "ray trace a frame (or frames) to PNG or EXR");
  describe(*render, kDescription);
  render->footer(kHelpFooter);
  addOptions(*render, *o);
  render->callback([o, &run] {
    check(*o);
    run = [o] { return runRender(*o); };
  });
}

}  // namespace snell::cli
