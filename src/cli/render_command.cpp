// `snell render SCENE -o OUT.png|OUT.exr`: headless frames of a glTF scene,
// traced on the GPU (or by the CPU reference with --reference), or with
// --viewport the viewer's composite: rasterized, with the trace on glass.
#include "cli/cli.h"

#include "bake/refraction_bake.h"
#include "cli/image_file.h"
#include "ref/reference_tracer.h"
#include "render/method.h"
#include "render/raster_pass.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "scene/view.h"
#include "vk/context.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace snell::cli {

namespace {

constexpr const char* kHelp = R"(usage: snell render SCENE.glb|SCENE.gltf|--eye -o OUT.png|OUT.exr [options]

Ray traces the scene on the GPU: one ray per pixel, refracted through every
transmissive face (KHR_materials_transmission, KHR_materials_ior, _volume,
_dispersion; overlapping glass by priority), Phong-shaded where it lands. Glass
reflects by Fresnel: the lights as highlights (an eye's catch lights) and the
environment. PNG is written as 8-bit sRGB, EXR as linear half floats. The
file appears only once it is complete.

options:
  -o, --output FILE      the image to write (required); with --frames, '#'s in
                         the name become the frame number, else it is added
                         before the extension (out.0012.png)
  --eye                  render the procedural eye instead of a file
  --size WxH             image size in pixels (default 640x480)
  --camera N             the scene's glTF camera N (default: camera 0, or a view
                         framing the whole scene when it has none)
  --look-at EX,EY,EZ,TX,TY,TZ   camera at E looking at T, +Y up (overrides --camera)
  --fov DEGREES          vertical field of view for --look-at and framed views (40)
  --time T               seconds into the animation (default 0)
  --frames A:B           frames A to B inclusive at --fps (default 24), with progress
  --fps N                frames per second for --frames
  --max-interfaces N     refractive faces a ray may cross (default 8)
  --background R,G,B     linear colour of misses (default 0.02,0.02,0.025)
  --environment FILE     what glass reflects: an equirectangular HDR, EXR or PNG
                         (+Y up, -Z in the middle; default: a studio gradient)
  --reflections N        interfaces per ray that send a reflected ray (default 1)
  --no-fresnel           glass transmits everything and reflects nothing
  --scene NAME|INDEX     which glTF scene of the file
  --ignore-extension E   load a file that requires extension E anyway
  --texture-budget MIB   textures (with mips) beyond MIB MiB load at a lower mip level
  --reference            render with the CPU double-precision reference instead
                         of the GPU (slow; golden images are made this way)
  --method M             how refraction is drawn (default trace): trace,
                         trace-1 (bends at the first interface only), masked
                         (the viewport: raster, glass pixels traced),
                         iris-plane and normal-offset (raster, no trace),
                         refraction-map (raster, no trace: the texture
                         behind the glass read where a map baked by the
                         trace at --bake-time says, as the scene moves on),
                         none (glass seen straight through), driver-rt
                         (the trace's rays through the driver's own ray
                         tracing, where the GPU has it)
  --offset-strength S    normal-offset's displacement in image heights (0.02)
  --bake-time T          refraction-map's pose: the seconds the map is baked at
                         (default: the first frame's time)
  --viewport             write the viewport's composite instead of the trace
                         alone: every face rasterized and Phong-shaded, and
                         transmissive faces showing the traced image (what
                         snell-view shows); the same as --method masked
  --no-refraction        with --viewport: see through glass without bending
                         (--method none)
  --wireframe            with --viewport: draw triangle edges over the image
  --stats                print each frame's work: what was deformed, refit,
                         rebuilt or skipped, pixels traced, dispatches, and the
                         GPU time of each pass
)";

struct Options {
  ShotOptions shot;
  std::string output;
  bool frames = false;
  long firstFrame = 0, lastFrame = 0;
  double fps = 24.0;
  std::optional<double> bakeTime;
  bool reference = false;
  bool viewport = false;
  std::optional<render::Method> method;
  bool stats = false;
  render::RasterOptions raster;
  scene::Optics optics;
  std::string environment;
};

Options parse(const Args& args) {
  Options o;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--reference") { o.reference = true; continue; }
    if (a == "--viewport") { o.viewport = true; continue; }
    if (a == "--no-refraction") { o.raster.refraction = false; continue; }
    if (a == "--wireframe") { o.raster.wireframe = true; continue; }
    if (a == "--stats") { o.stats = true; continue; }
    if (a == "--no-fresnel") { o.optics.fresnel = false; continue; }
    if (o.shot.take("render", args, i)) continue;
    if (i + 1 >= args.size()) throw UsageError{"render: " + a + " needs a value (or is unknown)"};
    const std::string& v = args[++i];
    if (a == "-o" || a == "--output") {
      o.output = v;
    } else if (a == "--bake-time") {
      o.bakeTime = parseNumbers(a, v, 1)[0];
    } else if (a == "--frames") {
      size_t colon = v.find(':');
      if (colon == std::string::npos) throw UsageError{"--frames expects A:B, e.g. 1:48, got '" + v + "'"};
      o.firstFrame = long(parseCount("--frames", v.substr(0, colon)));
      o.lastFrame = long(parseCount("--frames", v.substr(colon + 1)));
      if (o.lastFrame < o.firstFrame) throw UsageError{"--frames " + v + ": the last frame comes before the first"};
      o.frames = true;
    } else if (a == "--fps") {
      o.fps = parseNumbers(a, v, 1)[0];
      if (!(o.fps > 0.0)) throw UsageError{"--fps must be positive, got " + v};
    } else if (a == "--method") {
      o.method = render::methodFromName(v);
      if (!o.method) throw UsageError{"render: --method takes one of " + render::methodNames() + ", got '" + v + "'"};
    } else if (a == "--offset-strength") {
      char* end = nullptr;
      double strength = std::strtod(v.c_str(), &end);
      if (v.empty() || *end != '\0' || !std::isfinite(strength)) {
        throw UsageError{"render: --offset-strength expects a number, got '" + v + "'"};
      }
      o.raster.offsetStrength = float(strength);
    } else if (a == "--environment") {
      o.environment = v;
    } else if (a == "--reflections") {
      o.optics.reflections = uint32_t(std::min<unsigned long long>(parseCount(a, v), 1024));
    } else {
      throw UsageError{"render: unknown option " + a};
    }
  }
  o.shot.require("render");
  if (o.stats && o.reference) throw UsageError{"render: --stats counts GPU work; the reference (--reference) has none"};
  if (o.output.empty()) throw UsageError{"render: give the output image with -o FILE.png or FILE.exr"};
  if (o.viewport && o.reference) {
    throw UsageError{"render: --viewport is drawn on the GPU; the reference traces (--reference) without it"};
  }
  if (o.method && o.reference) {
    throw UsageError{"render: --method draws on the GPU; the reference (--reference) is the physics they approximate"};
  }
  if (o.method && o.viewport && !render::drawsComposite(*o.method)) {
    throw UsageError{std::string("render: --method ") + render::methodName(*o.method) +
                     " draws the trace image, not the viewport (--viewport)"};
  }
  if (!o.method) {
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
  std::string ext = std::filesystem::path(o.output).extension().string();
  if (ext != ".png" && ext != ".exr" && ext != ".PNG" && ext != ".EXR") {
    throw UsageError{"render: the output must end in .png or .exr, got '" + o.output + "'"};
  }
  return o;
}

std::string framePath(const std::string& pattern, long frame) {
  size_t first = pattern.find('#');
  if (first != std::string::npos) {
    size_t last = pattern.find_first_not_of('#', first);
    size_t width = (last == std::string::npos ? pattern.size() : last) - first;
    std::string number = std::to_string(frame);
    if (number.size() < width) number.insert(0, width - number.size(), '0');
    return pattern.substr(0, first) + number + pattern.substr(first + width);
  }
  std::filesystem::path p(pattern);
  char number[32];
  std::snprintf(number, sizeof number, ".%04ld", frame);
  return (p.parent_path() / (p.stem().string() + number + p.extension().string())).string();
}

void progress(long done, long total, double seconds) {
  const int width = 30;
  int filled = int(width * done / std::max(total, 1L));
  std::fprintf(stderr, "\r[%.*s%.*s] %ld/%ld frames, %.1f s", filled, "##############################", width - filled,
               "..............................", done, total, seconds);
  if (done == total) std::fputc('\n', stderr);
  std::fflush(stderr);
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

}  // namespace

void parseRenderOptions(const Args& args) { (void)parse(args); }

int runRender(const Args& args) {
  for (const std::string& a : args) {
    if (a == "--help" || a == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
  }
  Options o = parse(args);
  checkWritable(o.frames ? framePath(o.output, o.firstFrame) : o.output);
  if (!o.environment.empty()) o.optics.environment = std::make_shared<scene::Environment>(readEnvironment(o.environment));
  scene::Scene scene = o.shot.loadScene();

  if (o.bakeTime && *o.method != render::Method::RefractionMap) {
    throw UsageError{"render: --bake-time is for --method refraction-map"};
  }
  std::vector<std::pair<long, double>> frames;  // (frame number, time)
  if (o.frames) {
    for (long f = o.firstFrame; f <= o.lastFrame; ++f) frames.emplace_back(f, double(f) / o.fps);
  } else {
    frames.emplace_back(0, o.shot.time);
  }

  scene::Pose layout = scene::evaluate(scene, frames.front().second);
  std::unique_ptr<vk::Context> context;
  std::unique_ptr<render::Renderer> renderer;
  if (!o.reference) {
    vk::ContextDesc desc = contextDescFromEnvironment();
    desc.driverRayTracing = render::needsDriverRayTracing(*o.method);
    context = vk::Context::create(desc);
    if (desc.driverRayTracing && !context->caps().driverRayTracing) {
      throw std::runtime_error("render --method driver-rt: " + context->facts().name +
                               " offers no ray tracing pipelines (VK_KHR_ray_tracing_pipeline)");
    }
    try {
      render::checkImageSize(*context, o.shot.width, o.shot.height);
    } catch (const std::invalid_argument& e) {
      throw UsageError{std::string("render: ") + e.what()};
    }
    renderer = std::make_unique<render::Renderer>(*context, scene, layout);
  }

  // refraction-map: the trace bakes the map once, at --bake-time (default:
  // the first frame's), and every frame reads it as the scene moves on.
  render::RefractionMapBuffer map;
  if (renderer && *o.method == render::Method::RefractionMap) {
    double t = o.bakeTime.value_or(frames.front().second);
    scene::Pose bakePose = scene::evaluate(scene, t);
    scene::View bakeView;
    try {
      bakeView = scene::resolveView(scene, bakePose, o.shot.view);
    } catch (const std::invalid_argument& e) {
      throw UsageError{std::string("render: ") + e.what()};
    }
    render::FrameSettings settings{o.shot.width, o.shot.height, bakeView, o.shot.background, o.shot.maxInterfaces};
    settings.optics = o.optics;
    bake::RefractionBake baked = bake::bakeRefraction(*context, *renderer, bakePose, settings);
    map = bake::uploadRefractionMap(*context, baked);
    o.raster.refractionMap = &map;
    std::printf("baked the refraction map at %g s: %s\n", t, bake::describe(baked, scene).c_str());
  }

  auto start = std::chrono::steady_clock::now();
  for (size_t i = 0; i < frames.size(); ++i) {
    scene::Pose pose = i == 0 ? layout : scene::evaluate(scene, frames[i].second);
    scene::View view;
    try {
      view = scene::resolveView(scene, pose, o.shot.view);
    } catch (const std::invalid_argument& e) {
      throw UsageError{std::string("render: ") + e.what()};
    }
    LinearImage image{o.shot.width, o.shot.height, {}};
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
    } else {
      render::FrameSettings settings{o.shot.width, o.shot.height, view, o.shot.background, o.shot.maxInterfaces};
      settings.optics = o.optics;
      render::RasterOptions raster = o.raster;
      glm::dvec3 lo, hi;
      scene::sceneBounds(scene, pose, lo, hi);
      render::fitDepthRange(view, lo, hi, raster);
      render::ViewRequest request = render::methodView(*o.method, settings, raster);
      request.readback = true;
      render::FrameRequest frame;
      frame.pose = &pose;
      frame.views.push_back(request);
      const render::FrameResult& result = renderer->wait(renderer->submit(frame));
      const render::ViewPixels& pixels = result.views.at(0);
      image.rgba = render::drawsComposite(*o.method) ? pixels.composite : pixels.trace;
      if (o.stats) printStats(frames[i].first, result.stats, result.passes);
    }
    std::string path = o.frames ? framePath(o.output, frames[i].first) : o.output;
    writeImage(path, image);
    double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (frames.size() > 1) {
      progress(long(i + 1), long(frames.size()), seconds);
    } else {
      std::printf("wrote %s: %ux%u, %s, %s, %.2f s\n", path.c_str(), o.shot.width, o.shot.height, view.description.c_str(),
                  o.reference ? "CPU reference" : context->facts().name.c_str(), seconds);
      if (!o.reference) {
        for (const render::MethodInfo& m : render::methods()) {
          if (m.method == *o.method) std::printf("  method %s: %s\n", m.name, m.summary);
        }
      }
    }
  }
  if (context && context->validationMessageCount() > 0) {
    std::fprintf(stderr, "snell: the validation layer reported %llu message(s)\n",
                 static_cast<unsigned long long>(context->validationMessageCount()));
    return 1;
  }
  return 0;
}

}  // namespace snell::cli
