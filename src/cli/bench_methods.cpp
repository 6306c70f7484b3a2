// `snell bench methods`: what each way of drawing refraction costs and how
// wrong it is, on the same animated frames. Errors are against the CPU
// double-precision reference of each frame, never against another GPU image.
#include "cli/commands.h"

#include "bake/refraction_bake.h"
#include "io/image_compare.h"
#include "io/image_file.h"
#include "io/json.h"
#include "io/progress.h"
#include "ref/reference_tracer.h"
#include "render/method.h"
#include "render/pass_names.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "scene/view.h"
#include "stress/stress.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <optional>
#include <map>
#include <memory>
#include <sstream>

namespace snell::cli {

namespace {

struct Options {
  std::string file;  ///< empty: the procedural eye
  uint32_t width = 320, height = 240, frames = 24, maxInterfaces = gpu::kDefaultMaxInterfaces;
  float offsetStrength = render::RasterOptions{}.offsetStrength;
  std::vector<std::string> methods;  ///< empty: every method
  scene::EyeOptions eye;
  bool optics = false, noReference = false, pipelineStats = false, compactTrees = false;
  std::string json, svg, images;
};

// Times of each method come from this many passes over the sequence.
constexpr uint32_t kTimingRounds = 3;

using Error = io::ImageDifference;

struct Frame {
  double time = 0;
  scene::Pose pose;
  scene::View view;
  render::RasterOptions raster;  ///< depth range fitted to the frame, offset strength
  io::Rgb8Image reference;
  std::vector<bool> transmissive;  ///< the reference's first hit is a refractive face
};

// One row of the table: a method, or with --optics one optics feature drawn
// by trace. Rows that share a scene and optics share their frames.
struct MethodResult {
  render::MethodInfo info;
  std::string name, summary;
  const scene::Scene* scene = nullptr;
  scene::Optics optics;
  std::shared_ptr<const std::vector<Frame>> frames;
  std::string unsupported;  ///< why the method did not run here (empty: it ran)
  std::vector<double> refractionMs;
  std::map<std::string, std::vector<double>> passMs;  ///< per pass, measured frames
  std::map<std::string, double> firstFrameMs;         ///< per pass, the warm-up frame (builds)
  uint64_t hitsCompared = 0, hitsAgreeing = 0;        ///< first hits against trace's (driver-rt)
  std::vector<std::string> pipelineStatistics;        ///< --pipeline-stats: the trace pipelines' registers, spills
  Error glass, image;
  std::vector<double> frameGlassRmse;  ///< per frame of the sequence, in order
  double worstFrameWithin1 = 1.0;  ///< the lowest share of pixels within 1/255 of any frame
  /// refraction-map: its map's bake by the trace at the sequence's first frame
  /// (the renderer keeps the map), wall time: trace, read back, upload.
  double bakeMs = 0.0;
  uint64_t memoryBytes = 0;
};

// Adds a frame's differences to the row's errors; returns the frame's own glass error.
Error accumulate(const io::Rgb8Image& got, const Frame& frame, Error& glass, Error& image, double& worstWithin1) {
  Error frameImage = io::compareImages(got, frame.reference);
  Error frameGlass = io::compareImages(got, frame.reference, &frame.transmissive);
  image.add(frameImage);
  glass.add(frameGlass);
  worstWithin1 = std::min(worstWithin1, 1.0 - frameImage.share(frameImage.over1));
  return frameGlass;
}

// The camera swings about the view's up axis around the scene's centre.
scene::View orbitView(const scene::Scene& scene, const scene::Pose& pose, const scene::View& start, double angle) {
  glm::dvec3 lo, hi;
  scene::sceneBounds(scene, pose, lo, hi);
  glm::dvec3 centre = 0.5 * (lo + hi);
  double distance = glm::length(start.eye - centre);
  glm::dvec3 back = -start.forward;
  scene::ViewRequest request;
  request.lookAt = scene::LookAt{centre + distance * (std::cos(angle) * back + std::sin(angle) * start.right), centre,
                                 start.up};
  request.yfov = 2.0 * std::atan(start.halfHeight);
  return scene::resolveView(scene, pose, request);
}

// ------------------------------------------------------------------ chart

double niceFloor(double v) { return std::pow(10.0, std::floor(std::log10(v))); }
double niceCeil(double v) { return std::pow(10.0, std::ceil(std::log10(v))); }

// Time against transmissive-pixel RMSE, log-log. A method with no refraction
// work (or no error) sits on the axis floor, labelled so.
std::string chartSvg(const std::vector<MethodResult>& results, const std::string& title) {
  const double width = 720, height = 480, left = 80, right = 200, top = 50, bottom = 60;
  double minX = std::numeric_limits<double>::infinity(), maxX = 0, minY = minX, maxY = 0;
  for (const MethodResult& r : results) {
    if (!r.unsupported.empty()) continue;
    double x = io::median(r.refractionMs), y = r.glass.rmse();
    if (x > 0) minX = std::min(minX, x), maxX = std::max(maxX, x);
    if (y > 0) minY = std::min(minY, y), maxY = std::max(maxY, y);
  }
  if (!(maxX > 0)) minX = 1e-3, maxX = 1.0;
  if (!(maxY > 0)) minY = 1e-4, maxY = 1e-1;
  double x0 = niceFloor(minX / 2), x1 = niceCeil(maxX * 1.5), y0 = niceFloor(minY / 2), y1 = niceCeil(maxY * 1.5);
  auto px = [&](double x) { return left + (std::log10(std::max(x, x0)) - std::log10(x0)) / (std::log10(x1) - std::log10(x0)) * (width - left - right); };
  auto py = [&](double y) { return height - bottom - (std::log10(std::max(y, y0)) - std::log10(y0)) / (std::log10(y1) - std::log10(y0)) * (height - top - bottom); };
  std::ostringstream svg;
  svg << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\"" << height
      << "\" viewBox=\"0 0 " << width << " " << height << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
      << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      << "<text x=\"" << left << "\" y=\"24\" font-size=\"15\">" << xmlEscape(title) << "</text>\n";
  for (double x = x0; x <= x1 * 1.001; x *= 10) {
    svg << "<line x1=\"" << px(x) << "\" y1=\"" << top << "\" x2=\"" << px(x) << "\" y2=\"" << height - bottom
        << "\" stroke=\"#ddd\"/><text x=\"" << px(x) << "\" y=\"" << height - bottom + 16
        << "\" text-anchor=\"middle\">" << x << "</text>\n";
  }
  for (double y = y0; y <= y1 * 1.001; y *= 10) {
    svg << "<line x1=\"" << left << "\" y1=\"" << py(y) << "\" x2=\"" << width - right << "\" y2=\"" << py(y)
        << "\" stroke=\"#ddd\"/><text x=\"" << left - 6 << "\" y=\"" << py(y) + 4 << "\" text-anchor=\"end\">" << y
        << "</text>\n";
  }
  svg << "<text x=\"" << (left + width - right) / 2 << "\" y=\"" << height - 18
      << "\" text-anchor=\"middle\">refraction work per frame, ms (median, log)</text>\n"
      << "<text transform=\"translate(18," << (top + height - bottom) / 2
      << ") rotate(-90)\" text-anchor=\"middle\">RMSE on glass pixels against the CPU reference (log)</text>\n";
  // The Pareto front: no other method is both faster and more accurate.
  std::vector<const MethodResult*> sorted;
  for (const MethodResult& r : results) {
    if (r.unsupported.empty()) sorted.push_back(&r);
  }
  std::sort(sorted.begin(), sorted.end(), [](const MethodResult* a, const MethodResult* b) {
    double ta = io::median(a->refractionMs), tb = io::median(b->refractionMs);
    return ta != tb ? ta < tb : a->glass.rmse() < b->glass.rmse();
  });
  std::string front;
  double best = std::numeric_limits<double>::infinity();
  for (const MethodResult* r : sorted) {
    if (r->glass.rmse() >= best) continue;
    best = r->glass.rmse();
    front += (front.empty() ? "" : " ") + std::to_string(px(io::median(r->refractionMs))) + "," +
             std::to_string(py(r->glass.rmse()));
  }
  svg << "<polyline points=\"" << front << "\" fill=\"none\" stroke=\"#c33\" stroke-width=\"1.5\" stroke-dasharray=\"5,3\"/>\n";
  std::vector<std::pair<double, double>> placed;  // labels already drawn, so close points' labels stack
  for (const MethodResult& r : results) {
    if (!r.unsupported.empty()) continue;
    double t = io::median(r.refractionMs), e = r.glass.rmse();
    std::string label = r.name;
    if (t <= 0) label += " (no work)";
    if (e <= 0) label += " (exact)";
    double lx = px(t) + 8, ly = py(e) - 6;
    for (bool moved = true; moved;) {
      moved = false;
      for (const auto& [x, y] : placed) {
        if (std::abs(x - lx) < 90 && std::abs(y - ly) < 14) ly = y + 14, moved = true;
      }
    }
    placed.emplace_back(lx, ly);
    svg << "<circle cx=\"" << px(t) << "\" cy=\"" << py(e) << "\" r=\"5\" fill=\"#2468a8\"><title>"
        << xmlEscape(r.summary) << "</title></circle><text x=\"" << lx << "\" y=\"" << ly << "\">"
        << xmlEscape(label) << "</text>\n";
  }
  svg << "<text x=\"" << width - right + 10 << "\" y=\"" << top + 10
      << "\" fill=\"#c33\">- - Pareto front</text>\n</svg>\n";
  return svg.str();
}

// ------------------------------------------------------------------ sequence

struct SequenceSettings {
  uint32_t width, height, frames, maxInterfaces;
  float offsetStrength;
  bool reference;
  std::string images;  ///< where the last frame's reference goes as PNG (empty: nowhere)
};

// The animated sequence of one scene, with the reference image of each frame
// under `optics` (unless the run has no reference). `progress` counts the
// reference frames of every sequence of the run, `done` of them made so far.
std::shared_ptr<const std::vector<Frame>> makeFrames(const scene::Scene& scene, const scene::Optics& optics,
                                                     const SequenceSettings& s, const std::string& imageName,
                                                     io::Progress& progress, uint64_t& done) {
  double duration = scene::animationDuration(scene);
  scene::Pose first = scene::evaluate(scene, 0.0);
  scene::View start = scene::resolveView(scene, first, scene::ViewRequest{});
  auto frames = std::make_shared<std::vector<Frame>>(s.frames);
  for (uint32_t f = 0; f < s.frames; ++f) {
    Frame& frame = (*frames)[f];
    double along = s.frames > 1 ? double(f) / double(s.frames - 1) : 0.0;
    frame.time = duration * along;
    frame.pose = scene::evaluate(scene, frame.time);
    frame.view = orbitView(scene, frame.pose, start, glm::radians(80.0) * along);
    frame.raster.offsetStrength = s.offsetStrength;
    if (!s.reference) continue;
    ref::ReferenceSettings settings;
    settings.width = s.width;
    settings.height = s.height;
    settings.view = frame.view;
    settings.maxInterfaces = s.maxInterfaces;
    settings.optics = optics;
    ref::ReferenceImage reference = ref::renderReference(scene, frame.pose, settings);
    io::LinearImage linear{s.width, s.height, {}};
    frame.transmissive.resize(reference.color.size());
    for (size_t i = 0; i < reference.color.size(); ++i) {
      linear.rgba.emplace_back(glm::vec3(reference.color[i]), 1.0f);
      int item = reference.instance[i];
      if (item < 0) continue;
      int shape = frame.pose.items[size_t(item)].shape;
      int material = scene.shapes[size_t(shape)].material;
      frame.transmissive[i] = material >= 0 && scene.materials[size_t(material)].refractive();
    }
    frame.reference = io::toSrgb8(linear);
    if (!s.images.empty() && f + 1 == s.frames) io::writeImage(s.images + "/" + imageName + ".png", linear);
    progress.update(++done, imageName);
  }
  return frames;
}

// ------------------------------------------------------------------ optics rows

struct OpticsVariant {
  std::string name, summary;
  scene::Scene scene;
  scene::Optics optics;
};

std::vector<OpticsVariant> opticsVariants(const scene::Scene& scene, const std::optional<scene::EyeOptions>& eye) {
  scene::Optics plain, fresnel, environment, reflections, levelZero;
  plain.fresnel = false;
  levelZero.textureLod = false;
  environment.environment = std::make_shared<scene::Environment>(scene::proceduralSky());
  reflections.reflections = 4;
  using stress::withGlass;
  auto volume = [](scene::Material& m) { stress::addVolume(m, 0.004f); };  // 4 mm: the eye's scale
  auto iorTexture = [&](scene::Material& m) {
    if (!scene.textures.empty()) stress::addIorTexture(m, 0);
  };
  std::vector<OpticsVariant> rows = {
      {"plain", "no Fresnel: the bend only", scene, plain},
      {"fresnel", "Fresnel, one reflected ray, highlights, studio gradient (the default)", scene, fresnel},
      {"texture-level-0", "the default without ray cones: every texture read at level 0", scene, levelZero},
      {"environment", "the reflected ray sees a 1024x512 HDR sky with a sun", scene, environment},
      {"reflections-4", "four boundaries per path send a reflected ray", scene, reflections},
      {"volume", "Beer-Lambert inside every transmissive material", withGlass(scene, volume), fresnel},
      {"dispersion", "Abbe number 20 on every transmissive material: three rays there", withGlass(scene, stress::addDispersion),
       fresnel},
  };
  if (!scene.textures.empty()) {
    rows.push_back({"ior-texture", "IOR + 0.05 x the scene's first texture", withGlass(scene, iorTexture), fresnel});
  }
  auto everything = [&](scene::Material& m) { volume(m), stress::addDispersion(m), iorTexture(m); };
  scene::Scene all = scene;
  if (eye) {
    scene::EyeOptions nested = *eye;
    nested.aqueous = true;
    rows.push_back({"aqueous", "the aqueous humour nested in the cornea (priorities)", scene::makeEye(nested), fresnel});
    all = rows.back().scene;
  }
  rows.push_back({"all", "every feature above at once", withGlass(std::move(all), everything), environment});
  rows.back().optics.reflections = 4;
  return rows;
}

int runMethods(const Options& o) {
  if (!o.json.empty()) io::checkWritable(o.json);
  if (!o.svg.empty()) io::checkWritable(o.svg);
  if (!o.images.empty()) io::checkWritable(o.images + "/trace.png");  // the folder exists and takes files
  const uint32_t width = o.width, height = o.height, frameCount = o.frames, maxInterfaces = o.maxInterfaces;
  const bool reference = !o.noReference, optics = o.optics;
  std::vector<render::MethodInfo> chosen = render::methods();
  if (!o.methods.empty()) {
    chosen.clear();
    for (const std::string& name : o.methods) {
      for (const render::MethodInfo& info : render::methods()) {
        if (info.name == name) chosen.push_back(info);
      }
    }
  }
  scene::Scene scene = o.file.empty() ? scene::makeEye(o.eye) : scene::loadGltf(o.file);
  std::string label = o.file;
  if (o.file.empty()) {
    label = o.eye.crowd ? "eye crowd of " + std::to_string(o.eye.crowd) : std::string("procedural eye");
    label += " (resolution " + std::to_string(o.eye.resolution) + ")";
  }
  vk::ContextDesc desc = io::contextDescFromEnvironment();
  desc.driverRayTracing = true;  // for driver-rt, where the device has it
  desc.pipelineStatistics = o.pipelineStats;
  auto context = vk::Context::create(desc);
  render::checkImageSize(*context, width, height);
  std::printf("device: %s\nscene: %s, %ux%u, %u frames\n", context->facts().name.c_str(), label.c_str(), width, height,
              frameCount);

  // The rows: every chosen method on the scene as it is, or (--optics) trace
  // on each optics variant. Frames and references are made once per variant.
  std::vector<OpticsVariant> variants;
  if (optics) {
    variants = opticsVariants(scene, o.file.empty() ? std::optional<scene::EyeOptions>(o.eye) : std::nullopt);
    auto trace = std::find_if(render::methods().begin(), render::methods().end(),
                              [](const render::MethodInfo& m) { return m.method == render::Method::Trace; });
    chosen.assign(variants.size(), *trace);
  }
  std::vector<MethodResult> results(chosen.size());
  SequenceSettings sequence{width, height, frameCount, maxInterfaces, o.offsetStrength, reference, o.images};
  // One sequence per optics row, or one that every method shares.
  size_t sequences = optics ? chosen.size() : std::min<size_t>(chosen.size(), 1);
  io::Progress progress("CPU reference frames", reference ? frameCount * sequences : 0, quiet());
  uint64_t referenceFrames = 0;
  for (size_t m = 0; m < chosen.size(); ++m) {
    MethodResult& r = results[m];
    r.info = chosen[m];
    r.name = optics ? variants[m].name : chosen[m].name;
    r.summary = optics ? variants[m].summary : chosen[m].summary;
    r.scene = optics ? &variants[m].scene : &scene;
    r.optics = optics ? variants[m].optics : scene::Optics{};
    if (m == 0 || optics) {
      r.frames = makeFrames(*r.scene, r.optics, sequence, optics ? "reference-" + r.name : "reference", progress,
                            referenceFrames);
    } else {
      r.frames = results[0].frames;
    }
  }

  // One renderer per row, all alive at once, so the timing can take the rows
  // in turn on every frame: whatever the GPU's clocks do, they do it to every
  // row alike, and the ratios stand.
  std::vector<std::unique_ptr<render::Renderer>> renderers(results.size());
  for (size_t m = 0; m < results.size(); ++m) {
    if (render::needsDriverRayTracing(results[m].info.method) && !context->caps().driverRayTracing) {
      results[m].unsupported = "this device offers no ray tracing pipelines (VK_KHR_ray_tracing_pipeline)";
      std::printf("%s: unsupported: %s\n", results[m].name.c_str(), results[m].unsupported.c_str());
      continue;
    }
    render::RendererOptions rendererOptions;
    rendererOptions.compactTrees = o.compactTrees;
    renderers[m] = std::make_unique<render::Renderer>(*context, *results[m].scene, results[m].frames->at(0).pose,
                                                      rendererOptions);
    if (results[m].info.method == render::Method::RefractionMap) {
      // Baked once, by the trace, at the first frame's pose and view; every frame after drifts from it.
      const Frame& first = results[m].frames->at(0);
      render::FrameSettings settings{width, height, first.view, glm::vec3(scene::kDefaultBackground), maxInterfaces};
      settings.optics = results[m].optics;
      auto bakeStart = std::chrono::steady_clock::now();
      renderers[m]->bakeRefractionMap(first.pose, settings);
      results[m].bakeMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - bakeStart).count();
    }
  }
  auto hitsOf = [](render::Method method) {
    return method == render::Method::Trace || method == render::Method::DriverRt;
  };
  auto request = [&](const MethodResult& row, uint32_t f, bool readback) {
    const Frame& frame = row.frames->at(f);
    render::FrameSettings settings{width, height, frame.view, glm::vec3(scene::kDefaultBackground), maxInterfaces};
    settings.optics = row.optics;
    render::RasterOptions raster = frame.raster;
    render::ViewRequest view = render::methodView(row.info.method, settings, raster);
    view.aov = readback && hitsOf(row.info.method);
    render::FrameRequest r;
    r.pose = &frame.pose;
    r.views.push_back(view);
    if (readback) r.readbacks.push_back({.view = 0});
    return r;
  };
  auto timed = [](MethodResult& result, const render::FrameResult& out) {
    double ms = 0;
    std::map<std::string, double> frameMs;
    for (const vk::PassTime& p : out.passes) {
      ms += render::isRefractionPass(p.name) ? p.milliseconds : 0.0;
      frameMs[p.name] += p.milliseconds;
    }
    for (const auto& [name, t] : frameMs) result.passMs[name].push_back(t);
    result.refractionMs.push_back(ms);
  };
  // The first frame builds the trees and the pipelines: reported, not timed.
  for (size_t m = 0; m < results.size(); ++m) {
    if (!renderers[m]) continue;
    for (const vk::PassTime& p : renderers[m]->wait(renderers[m]->submit(request(results[m], 0, false))).passes) {
      results[m].firstFrameMs[p.name] += p.milliseconds;
    }
  }
  // Timing: one round to warm up, then kTimingRounds measured, each frame
  // drawn by every row in turn, two frames in flight per renderer and
  // nothing read back, as a viewer runs.
  std::vector<uint64_t> previous(results.size(), 0);
  for (uint32_t round = 0; round <= kTimingRounds; ++round) {
    for (uint32_t f = 0; f < frameCount; ++f) {
      for (size_t m = 0; m < results.size(); ++m) {
        if (!renderers[m]) continue;
        uint64_t id = renderers[m]->submit(request(results[m], f, false));
        if (previous[m]) {
          const render::FrameResult& out = renderers[m]->wait(previous[m]);
          if (round > 0) timed(results[m], out);
        }
        previous[m] = id;
      }
    }
  }
  for (size_t m = 0; m < results.size(); ++m) {
    if (renderers[m]) timed(results[m], renderers[m]->wait(previous[m]));
  }
  // Errors: every frame once more, read back, all rows on one frame before
  // the next, so only that frame's first hits are kept for the comparison.
  for (uint32_t f = 0; f < frameCount; ++f) {
    std::vector<std::pair<uint32_t, uint32_t>> traceHits, driverHits;
    MethodResult* driver = nullptr;
    for (size_t m = 0; m < results.size(); ++m) {
      if (!renderers[m]) continue;
      MethodResult& result = results[m];
      const Frame& frame = result.frames->at(f);
      render::Method method = result.info.method;
      const render::FrameResult& out = renderers[m]->wait(renderers[m]->submit(request(result, f, true)));
      const render::ViewPixels& pixels = out.views.at(0);
      if (hitsOf(method) && !optics) {
        std::vector<std::pair<uint32_t, uint32_t>>& hits = method == render::Method::Trace ? traceHits : driverHits;
        for (const gpu::TraceAov& a : pixels.aov) hits.emplace_back(a.instance, a.primitive);
        if (method == render::Method::DriverRt) driver = &result;
      }
      io::LinearImage image{width, height, render::drawsComposite(method) ? pixels.composite : pixels.trace};
      if (reference) {
        Error glass = accumulate(io::toSrgb8(image), frame, result.glass, result.image, result.worstFrameWithin1);
        result.frameGlassRmse.push_back(glass.rmse());
      }
      if (!o.images.empty() && f + 1 == frameCount) io::writeImage(o.images + "/" + result.name + ".png", image);
      if (f + 1 == frameCount) {
        result.memoryBytes = renderers[m]->memoryBytes();
        result.pipelineStatistics = renderers[m]->pipelineStatistics();
      }
    }
    if (driver && traceHits.size() == driverHits.size()) {
      for (size_t i = 0; i < traceHits.size(); ++i) driver->hitsAgreeing += traceHits[i] == driverHits[i];
      driver->hitsCompared += traceHits.size();
    }
  }

  std::printf("\n%-14s %10s %10s %9s %9s %5s %10s %9s %9s %12s %10s\n", "method", "refract ms", "glass RMSE",
              ">1/255", ">8/255", "max", "image RMSE", ">1/255", ">8/255", "worst frame", "GPU MiB");
  for (const MethodResult& r : results) {
    if (!r.unsupported.empty()) {
      std::printf("%-14s unsupported here\n", r.name.c_str());
      continue;
    }
    std::printf("%-14s %10.4f %10.5f %8.3f%% %8.3f%% %5d %10.5f %8.3f%% %8.3f%% %11.3f%% %10.2f\n", r.name.c_str(),
                io::median(r.refractionMs), r.glass.rmse(), 100 * r.glass.share(r.glass.over1),
                100 * r.glass.share(r.glass.over8), r.glass.maximum, r.image.rmse(), 100 * r.image.share(r.image.over1),
                100 * r.image.share(r.image.over8), 100 * r.worstFrameWithin1, double(r.memoryBytes) / 1048576.0);
  }
  std::printf("(glass: pixels whose first hit in the reference is transmissive; worst frame: the lowest share of a\n"
              " frame's pixels within 1/255; GPU MiB: geometry, trees and per-frame tables, not the images)\n");
  if (!reference) std::printf("(--no-reference: errors not measured)\n");
  if (o.pipelineStats) {
    for (const MethodResult& r : results) {
      if (r.pipelineStatistics.empty()) continue;
      std::printf("%s pipelines, as the driver compiled them:\n", r.name.c_str());
      for (const std::string& line : r.pipelineStatistics) std::printf("  %s\n", line.c_str());
    }
  }
  // The peer side by side: per pass, the build on the first frame, medians after.
  for (const MethodResult& r : results) {
    bool peer = r.info.method == render::Method::Trace || r.info.method == render::Method::DriverRt;
    if (!peer || !r.unsupported.empty()) continue;
    std::printf("\n%s passes, ms (first frame / median of the others):", r.name.c_str());
    std::map<std::string, int> names;  // every pass of any frame
    for (const auto& entry : r.firstFrameMs) names[entry.first] = 1;
    for (const auto& entry : r.passMs) names[entry.first] = 1;
    for (const auto& entry : names) {
      auto first = r.firstFrameMs.find(entry.first);
      auto later = r.passMs.find(entry.first);
      std::printf(" %s %.4f / %.4f,", entry.first.c_str(), first == r.firstFrameMs.end() ? 0.0 : first->second,
                  later == r.passMs.end() ? 0.0 : io::median(later->second));
    }
    if (r.hitsCompared) {
      std::printf("\n  first hits agreeing with trace's: %.4f%% of %llu pixels",
                  100.0 * double(r.hitsAgreeing) / double(r.hitsCompared), static_cast<unsigned long long>(r.hitsCompared));
    }
  }
  std::printf("\n");
  if (optics) {
    // Each feature's price: the trace pass against the plain bend's, same frames, same run.
    auto traceMs = [](const MethodResult& r) {
      auto it = r.passMs.find(pass::kTrace);
      return it == r.passMs.end() ? 0.0 : io::median(it->second);
    };
    double plain = traceMs(results.at(0));
    std::printf("\n%-14s %10s %10s   %s\n", "optics", "trace ms", "x plain", "what the row adds");
    for (const MethodResult& r : results) {
      std::printf("%-14s %10.4f %10.2f   %s\n", r.name.c_str(), traceMs(r), plain > 0 ? traceMs(r) / plain : 0.0,
                  r.summary.c_str());
    }
  }
  // Error against animation time: what a baked map loses as the pose and the
  // view drift from the ones it was baked at, beside methods that follow them.
  const MethodResult* baked = nullptr;
  for (const MethodResult& r : results) {
    if (r.info.method == render::Method::RefractionMap && r.unsupported.empty() && !r.frameGlassRmse.empty()) baked = &r;
  }
  if (baked && !optics) {
    std::printf("\nglass RMSE against animation time (refraction-map baked at frame 0 in %.1f ms, wall):\n%5s %8s %7s",
                baked->bakeMs, "frame", "time s", "orbit");
    for (const MethodResult& r : results) {
      if (r.unsupported.empty()) std::printf(" %14s", r.name.c_str());
    }
    std::printf("\n");
    for (uint32_t f = 0; f < frameCount; ++f) {
      double along = frameCount > 1 ? double(f) / double(frameCount - 1) : 0.0;
      std::printf("%5u %8.3f %6.1f%s", f, baked->frames->at(f).time, 80.0 * along, "\u00b0");
      for (const MethodResult& r : results) {
        if (r.unsupported.empty()) std::printf(" %14.5f", r.frameGlassRmse.at(f));
      }
      std::printf("\n");
    }
  }
  const MethodResult *traced = nullptr, *driver = nullptr;
  for (const MethodResult& r : results) {
    if (r.info.method == render::Method::Trace) traced = &r;
    if (r.info.method == render::Method::DriverRt && r.unsupported.empty()) driver = &r;
  }
  if (traced && driver) {
    auto traceMs = [](const MethodResult& r, const char* pass) {
      auto it = r.passMs.find(pass);
      return it == r.passMs.end() ? 0.0 : io::median(it->second);
    };
    double ours = traceMs(*traced, pass::kTrace), theirs = traceMs(*driver, pass::kDriverTrace);
    std::printf("rays per second, trace against driver-rt on the same frames: %.3fx (trace %.4f ms, driver %.4f ms)\n",
                ours > 0 ? theirs / ours : 0.0, ours, theirs);
  }

  std::string title = "snell bench methods: " + label + ", " + std::to_string(width) + "x" + std::to_string(height) +
                      ", " + std::to_string(frameCount) + " frames, " + context->facts().name;
  if (!o.json.empty()) {
    auto errorJson = [](const Error& e) {
      return io::Json{{"pixels", e.pixels},
                      {"rmse", e.rmse()},
                      {"share_over_1", e.share(e.over1)},
                      {"share_over_8", e.share(e.over8)},
                      {"max", e.maximum}};
    };
    io::Json j = io::reportHead("bench-methods", &context->facts());
    j["scene"] = label;
    j["width"] = width;
    j["height"] = height;
    j["frames"] = frameCount;
    j["rows"] = optics ? "optics features, drawn by trace" : "methods";
    io::Json rows = io::Json::array();
    for (const MethodResult& r : results) {
      if (!r.unsupported.empty()) {
        rows.push_back(io::Json{{"method", r.name}, {"unsupported", r.unsupported}});
        continue;
      }
      io::Json passes = io::Json::object(), firstFrame = io::Json::object();
      for (const auto& [name, v] : r.passMs) passes[name] = io::median(v);
      for (const auto& [name, v] : r.firstFrameMs) firstFrame[name] = v;
      io::Json row{{"method", r.name},
                   {"passes_median_ms", std::move(passes)},
                   {"first_frame_ms", std::move(firstFrame)},
                   {"first_hits_agreeing_with_trace",
                    r.hitsCompared ? double(r.hitsAgreeing) / double(r.hitsCompared) : -1.0},
                   {"summary", r.summary},
                   {"refraction_median_ms", io::median(r.refractionMs)},
                   {"glass", errorJson(r.glass)},
                   {"image", errorJson(r.image)},
                   {"worst_frame_within_1", r.worstFrameWithin1},
                   {"memory_bytes", r.memoryBytes},
                   {"glass_rmse_per_frame", r.frameGlassRmse}};
      if (r.info.method == render::Method::RefractionMap && r.unsupported.empty()) row["bake_ms"] = r.bakeMs;
      rows.push_back(std::move(row));
    }
    j["methods"] = std::move(rows);
    io::writeJson(o.json, j);
  }
  if (!o.svg.empty()) io::writeTextFile(o.svg, chartSvg(results, title));
  return validationExitCode(*context);
}

}  // namespace

void addBenchMethods(CLI::App& bench, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* sub =
      bench.add_subcommand("methods", "each way of drawing refraction: its GPU time against its error");
  describe(*sub,
      "Renders an animated sequence of the procedural eye (or SCENE) with every way\n"
      "snell can draw refraction and reports, per method, the median GPU time of its\n"
      "refraction work per frame and its error against the CPU double-precision\n"
      "reference of the same frames. The sequence plays the scene's animation (the\n"
      "eye looks around, squashes and dilates) while the camera orbits from the\n"
      "scene's own view to 80 degrees aside, a grazing view of the cornea.\n"
      "\n"
      "Refraction work is every pass but deform and the viewport's own raster depth\n"
      "and shading, which a viewport pays with or without glass; the first frame's\n"
      "tree build is a warm-up and not counted. Times are medians over three passes\n"
      "through the sequence after one to warm up, every method drawing each frame in\n"
      "turn (so the GPU's clock changes fall on all alike), two frames in flight and\n"
      "nothing read back; the errors come from one more pass that reads every frame\n"
      "back. Errors compare 8-bit sRGB pixels as\n"
      "a PNG would hold them: RMSE, the share of pixels over 1/255 and over 8/255,\n"
      "the largest difference, over the pixels whose first hit in the reference is\n"
      "transmissive, and over the whole image.\n"
      "\n"
      "methods:\n" +
      render::methodHelp() +
      "refraction-map's map is baked by the trace at the first frame and read by every\n"
      "frame after: a table shows its glass error against animation time beside the\n"
      "others'. driver-rt, the peer, runs the same rays and shading code with the hits found by\n"
      "the driver's own ray tracing (VK_KHR_ray_tracing_pipeline), where the device\n"
      "has it (not lavapipe: reported unsupported). For it the table adds the share\n"
      "of pixels whose first hit (instance, triangle) agrees with trace's, and its\n"
      "build (first frame), update and trace times.\n"
      "\n"
      "With --optics the rows are not methods but the optics features, each drawn\n"
      "by trace on its own copy of the scene against its own reference: \"plain\"\n"
      "(no Fresnel: the bend only), \"fresnel\" (the default: Fresnel, one reflected\n"
      "ray, the lights' highlights, the studio gradient), \"environment\" (an HDR sky\n"
      "instead of the gradient), \"reflections-4\", and on every transmissive\n"
      "material \"volume\" (Beer-Lambert), \"dispersion\" (Abbe number 20: three rays\n"
      "where it applies), \"ior-texture\" (the scene's first texture as IOR, scale\n"
      "0.05); for the procedural eye \"aqueous\" (nested media), and \"all\" of them.");
  sub->footer(kHelpFooter);
  addBenchScene(*sub, o->file, o->width, o->height, "320x240");
  sub->add_option("--frames", o->frames, "frames of the sequence (default 24)")
      ->type_name("N")
      ->check(positiveCount());
  std::vector<std::string> names;
  for (const render::MethodInfo& m : render::methods()) names.push_back(m.name);
  // A list takes one word, so it never swallows the scene file after it.
  CLI::Option* methods = sub->add_option("--methods", o->methods, "only these methods")
                             ->type_name("A,B,...")
                             ->delimiter(',')
                             ->allow_extra_args(false)
                             ->check(CLI::IsMember(names));
  sub->add_option("--max-interfaces", o->maxInterfaces,
                  "refractive faces a traced ray may cross (default 8, at most 1024)")
      ->type_name("N")
      ->check(CLI::Range(0u, 1024u));
  addOffsetStrength(*sub, o->offsetStrength);
  addEyeOptions(*sub, o->eye);
  sub->add_flag("--optics", o->optics, "rows per optics feature (trace) instead of per method")->excludes(methods);
  sub->add_flag("--no-reference", o->noReference, "time only: no CPU reference, no errors (for scaling runs)");
  sub->add_flag("--compact-trees", o->compactTrees,
                "trees of 40 bytes a triangle, whose walk decodes quantised child boxes (default: 88, exact boxes)");
  sub->add_flag("--pipeline-stats", o->pipelineStats,
                "print the driver's statistics of each trace pipeline (registers, spills), where it offers them");
  sub->add_option("--json", o->json, "write the results as JSON")->type_name("FILE");
  sub->add_option("--svg", o->svg,
                  "write a chart of time against error (log-log, the\nPareto front drawn) that a browser opens")
      ->type_name("FILE");
  sub->add_option("--images", o->images,
                  "write the last (grazing) frame of each method and of the\n"
                  "reference there as PNG (DIR/METHOD.png, DIR/reference.png)")
      ->type_name("DIR");
  sub->callback([o, &run] { run = [o] { return runMethods(*o); }; });
}

}  // namespace snell::cli
