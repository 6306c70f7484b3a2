// `snell render SCENE -o OUT.png|OUT.exr`: its options and their checks.
// What it draws and writes, on one device or several, is render_shot.cpp's:
// headless frames of a glTF scene, traced on the GPU (or by the CPU reference
// with --reference), or with --viewport the viewer's composite.
#include "cli/commands.h"
#include "cli/exr_layers.h"
#include "cli/render_shot.h"
#include "farm/frames.h"

#include "io/environment.h"
#include "render/method.h"
#include "scene/gltf_loader.h"

#include <filesystem>
#include <memory>
#include <optional>
#include <string>

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
    "a shot to Slurm or writes an Open Job Description template.\n"
    "\n"
    "Every GPU of the machine: --devices all renders the frames with one worker\n"
    "per device, each taking the next frame as it finishes one; the pixels are\n"
    "those one device writes. A device lost mid-shot hands its frames to the\n"
    "others (exit 0 if every frame was written, 3 if not).";

void addOptions(CLI::App& render, RenderOptions& o) {
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
      "--frames", [&o](const std::string& v) { o.frames = usageErrors([&] { return FrameList::parse("--frames", v); }); },
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
  render.add_option_function<std::string>(
         "--devices",
         [&o](const std::string& list) {
           if (list.empty() || list.front() == ',' || list.back() == ',' || list.find(",,") != std::string::npos) {
             throw UsageError{"--devices " + list + ": give all, or device indices and UUIDs separated by commas (0,1)"};
           }
           o.devices = list;
         },
         "render on several devices, a worker each: all (every GPU, or\n"
         "every GPU a launcher's CUDA_VISIBLE_DEVICES gives), or indices\n"
         "and UUIDs from 'snell info --devices' (0,1; 0,0 runs two\n"
         "workers on one device); the default is the one device --device picks")
      ->type_name("LIST");
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
         "how refraction is drawn (default auto):\n" +
             render::methodHelp({{"auto", "trace, or driver-rt where the first frames time it faster (for EXR and AOVs: trace)"}}) +
             "refraction-map's map is baked by the trace at --bake-time")
      ->type_name("M");
  addOffsetStrength(render, o.raster.offsetStrength);
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
void check(RenderOptions& o) {
  o.shot.require("render");
  if (o.stats && o.reference) throw UsageError{"render: --stats counts GPU work; the reference (--reference) has none"};
  if (o.viewport && o.reference) {
    throw UsageError{"render: --viewport is drawn on the GPU; the reference traces (--reference) without it"};
  }
  if (!o.devices.empty() && o.reference) {
    throw UsageError{"render: --devices splits frames over GPUs; the reference (--reference) runs on the CPU"};
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
  usageErrors([&] { checkFramePattern("-o", o.output, frames); });
  if (!o.statsJson.empty()) usageErrors([&] { checkFramePattern("--stats-json", o.statsJson, frames); });
}


}  // namespace

RenderCheck checkRender(const Args& args) {
  RenderOptions o;
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
  auto o = std::make_shared<RenderOptions>();
  CLI::App* render = parent.add_subcommand("render", "ray trace a frame (or frames) to PNG or EXR");
  describe(*render, kDescription);
  render->footer(kHelpFooter);
  addOptions(*render, *o);
  render->callback([o, &run] {
    check(*o);
    run = [o] { return renderShot(*o); };
  });
}

}  // namespace snell::cli
