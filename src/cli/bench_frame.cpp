// `snell bench frame`: GPU time of each pass of a frame (deform, bottom-level
// build or refit, top level, raster, trace) while the scene animates, medians
// over many frames, and what each frame did and skipped.
#include "cli/commands.h"
#include "io/image_file.h"
#include "io/json.h"

#include "render/method.h"
#include "render/pass_names.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "scene/scene_summary.h"
#include "scene/subdivision.h"
#include "scene/view.h"
#include "stress/stress.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>

namespace snell::cli {

namespace {

struct Options {
  std::string file;  ///< empty: the procedural eye
  uint32_t width = 1920, height = 1080, frames = 30, warmup = 5;
  scene::EyeOptions eye;
  bool viewport = false, noMask = false, noRefraction = false;
  bool orbit = false;  ///< the camera swings about the scene, 30 degrees either way over 240 frames
  uint32_t traceLanes = 0;  ///< RendererOptions::traceLanes (0: chosen per frame)
  uint32_t subdivision = 0;  ///< > 0: a subdivided cornea refined this many levels, its cage moved each frame
  std::string json;
  double soak = 0;  ///< seconds; 0: measure --frames instead
};

// The refraction work these tables quote: the refraction passes, and the
// deform that trees and trace both wait for.
bool refractionPass(const std::string& name) {
  return name == pass::kDeform || name == pass::kRefine || render::isRefractionPass(name);
}

// The view turned `degrees` about the vertical axis through `centre`: an orbit.
scene::View orbited(scene::View v, const glm::dvec3& centre, double degrees) {
  double a = degrees * 3.14159265358979 / 180.0, c = std::cos(a), s = std::sin(a);
  auto turn = [&](const glm::dvec3& d) { return glm::dvec3(c * d.x + s * d.z, d.y, -s * d.x + c * d.z); };
  v.eye = centre + turn(v.eye - centre);
  v.right = turn(v.right), v.up = turn(v.up), v.forward = turn(v.forward);
  return v;
}

// A long run: is anything growing? Each sample covers a twentieth of the run;
// only the samples are kept, so the benchmark's own memory stays flat.
template <typename RenderFrame>
int soakFrames(const vk::Context& context, const render::Renderer& renderer, RenderFrame&& renderFrame,
               uint32_t warmup, double seconds, const std::string& json, const std::string& label,
               const std::string& mode) {
  struct Sample {
    double atSeconds = 0;
    uint64_t frames = 0;
    double frameMs = 0, wallMs = 0;
    uint64_t hostBytes = 0, deviceBytes = 0, validation = 0;
  };
  std::vector<Sample> samples;
  double wall = 0;
  uint64_t f = 0;
  for (; f < warmup; ++f) renderFrame(f, wall);
  renderer.finishCompiles();
  using Clock = std::chrono::steady_clock;
  auto start = Clock::now();
  double interval = seconds / 20.0;
  std::vector<double> frameMs, wallMs;
  std::printf("%9s %10s %12s %12s %14s %14s %11s\n", "seconds", "frames", "frame ms", "wall ms", "host MiB",
              "GPU MiB", "validation");
  for (;;) {
    const render::FrameResult& result = renderFrame(f++, wall);
    double total = 0;
    for (const vk::PassTime& p : result.passes) total += p.milliseconds;
    frameMs.push_back(total);
    wallMs.push_back(wall);
    double now = std::chrono::duration<double>(Clock::now() - start).count();
    if (now < interval * double(samples.size() + 1)) continue;
    Sample s{now, f - warmup, io::median(frameMs), io::median(wallMs), io::hostResidentBytes(), context.memoryInUse(),
             context.validationMessageCount()};
    samples.push_back(s);
    frameMs.clear();
    wallMs.clear();
    std::printf("%9.1f %10llu %12.4f %12.4f %14.2f %14.2f %11llu\n", s.atSeconds, (unsigned long long)s.frames, s.frameMs,
                s.wallMs, double(s.hostBytes) / 1048576.0, double(s.deviceBytes) / 1048576.0,
                (unsigned long long)s.validation);
    std::fflush(stdout);
    if (samples.size() == 20) break;
  }
  const Sample &first = samples.front(), &last = samples.back();
  bool deviceFlat = last.deviceBytes == first.deviceBytes;
  double hostGrowth = double(last.hostBytes) - double(first.hostBytes);
  std::printf("%llu frames in %.0f s: GPU memory %s (%.2f MiB to %.2f MiB), host memory %+.2f MiB from the first "
              "sample, %llu validation message(s); GPU memory by the renderer's own count: %.2f MiB\n",
              (unsigned long long)last.frames, last.atSeconds, deviceFlat ? "flat" : "GREW",
              double(first.deviceBytes) / 1048576.0, double(last.deviceBytes) / 1048576.0, hostGrowth / 1048576.0,
              (unsigned long long)last.validation, double(renderer.memoryBytes()) / 1048576.0);
  if (!json.empty()) {
    io::Json j = io::reportHead("bench-frame", &context.facts());
    j["scene"] = label;
    j["mode"] = mode;
    j["soak_seconds"] = seconds;
    j["frames"] = last.frames;
    j["device_memory_flat"] = deviceFlat;
    j["host_growth_bytes"] = int64_t(hostGrowth);
    io::Json rows = io::Json::array();
    for (const Sample& s : samples) {
      rows.push_back(io::Json{{"seconds", s.atSeconds},
                              {"frames", s.frames},
                              {"frame_median_ms", s.frameMs},
                              {"wall_median_ms", s.wallMs},
                              {"host_resident_bytes", s.hostBytes},
                              {"device_bytes", s.deviceBytes},
                              {"validation_messages", s.validation}});
    }
    j["samples"] = std::move(rows);
    io::writeJson(json, j);
  }
  return deviceFlat && last.validation == 0 ? kExitOk : kExitFailure;
}

int runFrame(const Options& o) {
  if (!o.json.empty()) io::checkWritable(o.json);
  const uint32_t width = o.width, height = o.height, frames = o.frames, warmup = o.warmup;
  const bool viewport = o.viewport, masked = !o.noMask, refraction = !o.noRefraction;
  scene::Scene scene = o.subdivision ? stress::subdividedCorneaScene(o.subdivision, true, 6, 24)
                      : o.file.empty() ? scene::makeEye(o.eye)
                                       : scene::loadGltf(o.file);
  std::string label = o.file;
  if (o.subdivision) {
    const scene::Refinement& r = *scene.shapes[0].refinement;
    label = "a cornea of " + std::to_string(r.cageFaces) + " cage faces refined " + std::to_string(r.level) +
            " levels to " + std::to_string(scene.shapes[0].vertexCount()) + " vertices, its cage moved every frame";
  } else if (o.file.empty()) {
    label = o.eye.crowd ? "eye crowd of " + std::to_string(o.eye.crowd) : std::string("eye");
    label += " (resolution " + std::to_string(o.eye.resolution) + ")";
  }
  auto context = vk::Context::create(io::contextDescFromEnvironment());
  render::checkImageSize(*context, width, height);
  scene::SceneSummary summary = scene::summarize(scene);
  std::string mode = !viewport ? "trace" : !refraction ? "viewport, no refraction" : masked ? "viewport, masked trace"
                                                                                            : "viewport, full trace";
  if (o.orbit) mode += ", orbiting";
  std::printf("device: %s\nscene: %s, %llu triangles, %ux%u, %s\n", context->facts().name.c_str(), label.c_str(),
              static_cast<unsigned long long>(summary.triangles), width, height, mode.c_str());

  double duration = std::max(scene::animationDuration(scene), 1e-3);
  scene::Pose firstPose = scene::evaluate(scene, 0.0);
  glm::dvec3 lo, hi;
  scene::approximateBounds(scene, firstPose, lo, hi);
  const glm::dvec3 centre = lo.x <= hi.x ? 0.5 * (lo + hi) : glm::dvec3(0.0);
  render::RendererOptions rendererOptions;
  rendererOptions.traceLanes = o.traceLanes;
  rendererOptions.keepVertices = o.subdivision > 0;  // the host moves the cage
  render::Renderer renderer(*context, scene, firstPose, rendererOptions);
  std::map<std::string, std::vector<double>> times;
  std::vector<std::string> order;
  std::vector<double> totals, refractionTotals, walls;
  std::map<std::string, std::vector<double>> counters;
  std::vector<std::string> counterOrder = {"items deformed", "vertices refined", "trees refit", "trees rebuilt",
                                           "triangles refit", "pixels traced", "trace lanes", "dispatches", "draws"};
  // One animated frame, rendered and waited for; its wall time in `wall`.
  auto renderFrame = [&](uint64_t f, double& wall) -> const render::FrameResult& {
    double t = std::fmod(double(f) / 24.0, duration);
    scene::Pose pose = scene::evaluate(scene, t);
    if (o.subdivision) {  // the cornea breathes: its cage stretched along its axis, as a host's rig would move it
      const std::vector<glm::vec3>& rest = scene.shapes[0].refinement->cageRest;
      render::KeptVertices kept = renderer.keptVertices(0);
      const float stretch = 1.0f + 0.1f * std::sin(float(f) * 0.25f);
      for (size_t v = 0; v < rest.size(); ++v) {
        kept.positions[3 * v] = rest[v].x, kept.positions[3 * v + 1] = rest[v].y;
        kept.positions[3 * v + 2] = rest[v].z * stretch;
      }
      renderer.markDirty(0);
    }
    render::ViewRequest view;
    scene::View camera = scene::resolveView(scene, pose, {});
    // A swing of 30 degrees either way, not a full circle: the side that faces the camera stays in view.
    if (o.orbit) camera = orbited(camera, centre, 30.0 * std::sin(double(f) * 2.0 * 3.14159265358979 / 240.0));
    view.settings = {width, height, camera, glm::vec3(scene::kDefaultBackground), gpu::kDefaultMaxInterfaces};
    if (viewport) {
      view.output = render::ViewOutput::Composite;
      view.masked = masked;
      view.raster.refraction = refraction;
    }
    render::FrameRequest request;
    request.pose = &pose;
    request.views.push_back(view);
    auto start = std::chrono::steady_clock::now();
    const render::FrameResult& result = renderer.wait(renderer.submit(request));
    wall = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return result;
  };
  if (o.soak > 0) {
    int soaked = soakFrames(*context, renderer, renderFrame, warmup, o.soak, o.json, label, mode);
    int validation = validationExitCode(*context);
    return soaked == kExitOk ? validation : soaked;
  }
  for (uint32_t f = 0; f < warmup + frames; ++f) {
    // Measured frames draw as a long session's: the pipelines a warm-up
    // frame chose (the masked trace's lanes among them) have compiled.
    if (f == warmup) renderer.finishCompiles();
    double wall = 0;
    const render::FrameResult& result = renderFrame(f, wall);
    // The first build happens once, on the first frame: report it even though it is warm-up.
    bool measured = f >= warmup;
    double total = 0, refractionTotal = 0;
    for (const vk::PassTime& p : result.passes) {
      if (!measured && !(f == 0 && p.name == pass::kBlasBuild)) continue;
      if (!times.count(p.name)) order.push_back(p.name);
      times[p.name].push_back(p.milliseconds);
      if (p.name == pass::kBlasBuild && f == 0) continue;
      total += p.milliseconds;
      if (refractionPass(p.name)) refractionTotal += p.milliseconds;
    }
    if (!measured) continue;
    totals.push_back(total);
    refractionTotals.push_back(refractionTotal);
    walls.push_back(wall);
    const render::FrameStats& s = result.stats;
    counters["items deformed"].push_back(s.itemsDeformed);
    counters["vertices refined"].push_back(s.verticesRefined);
    counters["trees refit"].push_back(s.treesRefit);
    counters["trees rebuilt"].push_back(s.treesBuilt);
    counters["triangles refit"].push_back(double(s.trianglesRefit));
    counters["pixels traced"].push_back(double(s.pixelsTraced));
    counters["trace lanes"].push_back(s.traceLanes);
    counters["dispatches"].push_back(s.dispatches);
    counters["draws"].push_back(s.draws);
  }

  std::printf("%-16s %10s %10s %10s %7s\n", "pass", "median ms", "min ms", "max ms", "frames");
  for (const std::string& name : order) {
    const std::vector<double>& v = times[name];
    std::printf("%-16s %10.4f %10.4f %10.4f %7zu\n", name.c_str(), io::median(v), *std::min_element(v.begin(), v.end()),
                *std::max_element(v.begin(), v.end()), v.size());
  }
  std::printf("%-16s %10.4f   (median of each animated frame's passes)\n", "frame", io::median(totals));
  std::printf("%-16s %10.4f   (deform + trees + trace), %.2f%% of a 60 Hz frame\n", "refraction",
              io::median(refractionTotals), 100.0 * io::median(refractionTotals) / (1000.0 / 60.0));
  std::printf("%-16s %10.4f   (host: recording, submit and wait for the frame; where passes overlap\n"
              "%-16s              or a CPU device defers work, the timestamps split it less surely)\n",
              "wall", io::median(walls), "");
  std::printf("per frame (medians):");
  for (const std::string& c : counterOrder) std::printf(" %s %.0f,", c.c_str(), io::median(counters[c]));
  std::printf("\nGPU memory (geometry, deformation, trees, per-frame tables): %.2f MiB, trees %.1f bytes per triangle\n",
              double(renderer.memoryBytes()) / 1048576.0, renderer.treeBytesPerTriangle());
  if (!o.json.empty()) {
    io::Json j = io::reportHead("bench-frame", &context->facts());
    j["scene"] = label;
    j["mode"] = mode;
    j["triangles"] = summary.triangles;
    j["width"] = width;
    j["height"] = height;
    j["memory_bytes"] = renderer.memoryBytes();
    j["tree_bytes_per_triangle"] = renderer.treeBytesPerTriangle();
    io::Json passes = io::Json::array();
    for (const std::string& name : order) {
      const std::vector<double>& v = times[name];
      passes.push_back(io::Json{{"pass", name},
                                {"median_ms", io::median(v)},
                                {"min_ms", *std::min_element(v.begin(), v.end())},
                                {"max_ms", *std::max_element(v.begin(), v.end())},
                                {"frames", v.size()}});
    }
    j["passes"] = std::move(passes);
    j["frame_median_ms"] = io::median(totals);
    j["refraction_median_ms"] = io::median(refractionTotals);
    j["wall_median_ms"] = io::median(walls);
    io::Json countersMedian = io::Json::object();
    for (const std::string& c : counterOrder) countersMedian[c] = io::median(counters[c]);
    j["counters_median"] = std::move(countersMedian);
    io::writeJson(o.json, j);
  }
  return validationExitCode(*context);
}

}  // namespace

void addBenchFrame(CLI::App& bench, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* sub = bench.add_subcommand("frame", "GPU time of each pass of an animated frame, with counters");
  describe(*sub,
      "Renders animated frames of the procedural eye (or SCENE) and reports each\n"
      "pass's GPU time: the median, min and max over the measured frames. The first\n"
      "frame builds the trees (\"blas build\"); later frames refit what deformed and\n"
      "rebuild trees the surface area heuristic finds spoiled.\n"
      "\n"
      "\"refraction\" sums the passes refraction costs: deform, the trees and the\n"
      "trace (with --viewport the trace covers only the pixels whose visible face is\n"
      "transmissive); the raster passes draw the viewport with or without it.");
  sub->footer(kHelpFooter);
  addBenchScene(*sub, o->file, o->width, o->height, "1920x1080");
  CLI::Option* frames = sub->add_option("--frames", o->frames, "frames measured (default 30)")
                            ->type_name("N")
                            ->check(positiveCount());
  sub->add_option("--warmup", o->warmup,
                  "frames rendered first and not measured (default 5); the pipelines\nthey chose then finish compiling")
      ->type_name("N");
  addEyeOptions(*sub, o->eye);
  CLI::Option* viewport =
      sub->add_flag("--viewport", o->viewport, "the viewport composite: raster pass, transmissive pixels traced");
  sub->add_flag("--orbit", o->orbit,
                "the camera swings about the scene (30 degrees either way over\n240 frames): a still scene is measured too (its trees stay;\nthe trace and raster run)");
  CLI::Option* noMask = sub->add_flag("--no-mask", o->noMask, "with --viewport: trace every pixel")->needs(viewport);
  sub->add_flag("--no-refraction", o->noRefraction, "with --viewport: glass left out, nothing traced")
      ->needs(viewport)
      ->excludes(noMask);
  sub->add_option("--subdiv", o->subdivision,
                  "a cornea made as a Catmull-Clark cage of 216 faces (stress::corneaCage), refined LEVEL times on "
                  "the GPU every frame its host moves the cage, instead of the eye")
      ->type_name("LEVEL")
      ->check(CLI::Range(1, 8));
  sub->add_option("--trace-lanes", o->traceLanes,
                  "with --viewport: lanes that trace each glass pixel, 1, 2, 4 or 8 (default: chosen each frame "
                  "from the last frame's count)")
      ->check(CLI::IsMember({1, 2, 4, 8}))
      ->needs(viewport)
      ->type_name("N");
  sub->add_option("--json", o->json, "write the results as JSON too")->type_name("FILE");
  sub->add_option("--soak", o->soak,
                  "render for SECONDS instead, and every twentieth of it\n"
                  "report the frame time, host memory (resident), GPU memory\n"
                  "and validation messages; fails if GPU memory grows")
      ->type_name("SECONDS")
      ->check([](const std::string& value) -> std::string {
        double seconds = std::strtod(value.c_str(), nullptr);
        return seconds > 0 && std::isfinite(seconds) ? "" : "takes seconds above 0, got " + value;
      })
      ->excludes(frames);
  sub->callback([o, &run] { run = [o] { return runFrame(*o); }; });
}

}  // namespace snell::cli
