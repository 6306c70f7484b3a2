// `snell bench scale`: how the work of a frame scales. With triangles, on UV
// spheres of 1e4 to 1e7 triangles: build and refit times (GPU timestamps,
// medians), their rates, tree memory per triangle and the build's SAH cost
// against a CPU binned-SAH tree, next to the driver's own acceleration
// structures built and updated over the same triangles in the same run.
// With characters, on crowds of the procedural eye: the viewport frame's passes.
// With refined vertices, on subdivision cages refined twice: the refine pass
// and the refit after it, per frame the host moves the cage.
#include "cli/commands.h"
#include "io/image_file.h"
#include "io/json.h"

#include "peer/driver_bvh.h"
#include "ref/sah_bvh.h"
#include "render/bvh.h"
#include "render/method.h"
#include "render/pass_names.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/procedural_eye.h"
#include "scene/scene_builder.h"
#include "scene/subdivision.h"
#include "scene/view.h"
#include "vk/commands.h"
#include "vk/upload_arena.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>

namespace snell::cli {

namespace {

struct Options {
  // Lists as given: numbers in any notation (1e6), 0 skipping an entry.
  std::vector<double> triangles = {1e4, 1e5, 1e6, 1e7}, crowds = {1, 2, 10, 100, 1000};
  std::vector<double> refined = {1e4, 1e5, 1e6};  ///< refined vertices of a subdivision cage
  uint32_t runs = 10, restructure = 0, width = 3840, height = 2160, frames = 20;
  uint32_t refinedMaterials = 1;  ///< materials of each subdivision cage, in bands of faces
  uint64_t sahLimit = 1000000;
  bool compactTrees = false;  ///< trees without the exact child boxes (RendererOptions::compactTrees)
  render::BvhTuning tuning;
  std::string json;
};

struct Mesh {
  std::vector<float> positions;
  std::vector<uint32_t> indices;
};

// A UV sphere of about `triangles` triangles: rings x 2 rings quads, two triangles each.
Mesh uvSphere(uint64_t triangles) {
  uint32_t rings = std::max<uint32_t>(2, static_cast<uint32_t>(std::lround(std::sqrt(double(triangles) / 4.0))));
  uint32_t segments = 2 * rings;
  Mesh m;
  m.positions.reserve(size_t(rings + 1) * (segments + 1) * 3);
  for (uint32_t r = 0; r <= rings; ++r) {
    double theta = M_PI * r / rings;
    for (uint32_t s = 0; s <= segments; ++s) {
      double phi = 2.0 * M_PI * s / segments;
      m.positions.insert(m.positions.end(), {float(std::sin(theta) * std::cos(phi)), float(std::cos(theta)),
                                             float(std::sin(theta) * std::sin(phi))});
    }
  }
  for (uint32_t r = 0; r < rings; ++r) {
    for (uint32_t s = 0; s < segments; ++s) {
      uint32_t a = r * (segments + 1) + s, b = a + 1, c = a + segments + 1, d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  }
  return m;
}

struct Row {
  uint64_t triangles = 0;
  double buildMs = 0, refitMs = 0, bytesPerTriangle = 0, scratchPerTriangle = 0, sahRatio = 0;
  /// The build's steps, medians of runs that timed each (BvhBuilder::setStepTiming), in build order.
  std::vector<std::pair<std::string, double>> stepMs;
  // The driver's, where it has them (0 otherwise).
  double driverFastBuildMs = 0, driverFastTraceMs = 0, driverUpdateMs = 0, driverBytesPerTriangle = 0;
};

struct CrowdRow {
  uint32_t characters = 0;
  uint64_t triangles = 0;
  std::map<std::string, double> passMs;  ///< medians
  double frameMs = 0, refractionMs = 0, pixelsTraced = 0, memoryPerTriangle = 0, treeBytesPerTriangle = 0;
};

// Checks an entry of a list option: 0 (skipped) or a whole count from 1 to `most`.
CLI::Validator countOrZero(uint64_t most) {
  return CLI::Validator(
      [most](std::string& item) -> std::string {
        char* end = nullptr;
        double v = std::strtod(item.c_str(), &end);
        if (item.empty() || *end != '\0') return "takes numbers separated by commas, not '" + item + "'";
        if (v == 0 || (v >= 1 && v <= double(most))) return "";
        return "entries must be 0 (skip) or within 1 and " + std::to_string(most) + ", got " + item;
      },
      "");
}

// The counts a list option asks for, its zeros left out.
std::vector<uint64_t> counts(const std::vector<double>& list) {
  std::vector<uint64_t> out;
  for (double v : list) {
    if (v != 0) out.push_back(static_cast<uint64_t>(v));
  }
  return out;
}

// The refraction work these tables quote: the refraction passes, and the
// deform that trees and trace both wait for.
bool refractionPass(const std::string& name) { return name == pass::kDeform || render::isRefractionPass(name); }

CrowdRow measureCrowd(vk::Context& context, uint32_t characters, uint32_t width, uint32_t height, uint32_t frames,
                      bool compactTrees) {
  scene::EyeOptions options;
  options.crowd = characters;
  scene::Scene scene = scene::makeEye(options);
  double duration = std::max(scene::animationDuration(scene), 1e-3);
  scene::Pose firstPose = scene::evaluate(scene, 0.0);
  render::RendererOptions rendererOptions;
  rendererOptions.compactTrees = compactTrees;
  render::Renderer renderer(context, scene, firstPose, rendererOptions);
  CrowdRow row;
  row.characters = characters;
  for (const scene::DrawItem& item : firstPose.items) row.triangles += scene.shapes[size_t(item.shape)].triangleCount();
  std::map<std::string, std::vector<double>> passes;
  std::vector<double> totals, refraction, pixels;
  const uint32_t warmup = 5;
  for (uint32_t f = 0; f < warmup + frames; ++f) {
    scene::Pose pose = scene::evaluate(scene, std::fmod(double(f) / 24.0, duration));
    render::ViewRequest view;
    view.settings = {width, height, scene::resolveView(scene, pose, {}), glm::vec3(scene::kDefaultBackground),
                     gpu::kDefaultMaxInterfaces};
    view.output = render::ViewOutput::Composite;
    render::FrameRequest request;
    request.pose = &pose;
    request.views = {view};
    const render::FrameResult& result = renderer.wait(renderer.submit(request));
    if (f < warmup) continue;
    double total = 0, work = 0;
    for (const vk::PassTime& p : result.passes) {
      passes[p.name].push_back(p.milliseconds);
      total += p.milliseconds;
      if (refractionPass(p.name)) work += p.milliseconds;
    }
    totals.push_back(total);
    refraction.push_back(work);
    pixels.push_back(double(result.stats.pixelsTraced));
  }
  for (auto& [name, v] : passes) row.passMs[name] = io::median(v);
  row.frameMs = io::median(totals);
  row.refractionMs = io::median(refraction);
  row.pixelsTraced = io::median(pixels);
  row.memoryPerTriangle = double(renderer.memoryBytes()) / double(row.triangles);
  row.treeBytesPerTriangle = renderer.treeBytesPerTriangle();
  return row;
}

struct RefineRow {
  uint32_t cageVertices = 0, cageFaces = 0, refinedVertices = 0, materials = 1;
  double refinePasses = 0;  ///< refine passes a frame (median): one whatever the materials
  double refineMs = 0, refitMs = 0;  ///< medians
  double refineMinMs = 0, refineMaxMs = 0, refitMinMs = 0, refitMaxMs = 0;  ///< the spread of the frames timed
  uint64_t triangles = 0;  ///< of the refined surface, which its trees hold
  /// Of the trees' work in the timed frames, how many bottom-level trees were
  /// rebuilt (their SAH grew past the rebuild policy's bound) and refit:
  /// "refit ms" is a refit's time only where none was rebuilt.
  uint32_t treesBuilt = 0, treesRefit = 0;
};

// Frames drawn before a refine row's timed ones: its tables and the trees
// come into the caches, and the clocks up from idle.
constexpr uint32_t kRefineWarmupFrames = 5;  // as the crowds' (--frames says "after 5")

// A wavy open grid of n x n quads as a Catmull-Clark cage refined twice
// ((4n + 1)^2 vertices), moved by the host every frame: the refine pass and
// the refit of its trees, medians over `frames` of each frame's sums. With
// several materials (bands of faces) the cage is one shape split into parts
// that share its refined vertices: refined once, a tree a part.
RefineRow measureRefine(vk::Context& context, uint64_t target, uint32_t frames, bool compactTrees, uint32_t materials) {
  const uint32_t n = std::max<uint32_t>(1, uint32_t(std::lround((std::sqrt(double(target)) - 1.0) / 4.0)));
  scene::SubdivisionCage cage;
  for (uint32_t y = 0; y <= n; ++y) {
    for (uint32_t x = 0; x <= n; ++x) cage.positions.push_back({float(x) / float(n) - 0.5f, float(y) / float(n) - 0.5f, 0.0f});
  }
  for (uint32_t y = 0; y < n; ++y) {
    for (uint32_t x = 0; x < n; ++x) {
      uint32_t a = y * (n + 1) + x;
      cage.faceVertexIndices.insert(cage.faceVertexIndices.end(), {a, a + 1, a + n + 2, a + n + 1});
      cage.faceVertexCounts.push_back(4);
    }
  }
  scene::Scene s;
  s.source = "a refined grid";
  scene::Shape shape;
  std::vector<std::string> warnings;
  std::vector<uint32_t> triangleFaces;
  scene::subdivide(cage, shape, "grid", warnings, scene::kMaxRefinedVertices, &triangleFaces);
  scene::addRootShape(s, std::move(shape));
  if (materials > 1) {
    s.materials.resize(materials);
    std::vector<int> bands(triangleFaces.size());
    for (size_t t = 0; t < bands.size(); ++t) bands[t] = int(uint64_t(triangleFaces[t] / n) * materials / n);
    scene::splitByMaterial(s, 0, bands);
  }
  scene::Pose pose = scene::evaluate(s, 0.0);
  render::RendererOptions options;
  options.keepVertices = true;
  options.compactTrees = compactTrees;
  render::Renderer renderer(context, s, pose, options);
  scene::ViewRequest look;
  look.lookAt = scene::LookAt{{0.0, 0.0, 2.0}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  render::ViewRequest view;
  view.settings = {16, 16, scene::resolveView(s, pose, look), glm::vec3(0.0f), 1};  // the trees, hardly a trace
  render::FrameRequest request;
  request.pose = &pose;
  request.views.push_back(view);
  renderer.wait(renderer.submit(request));  // the first build
  std::vector<double> refine, refit, refinePasses;
  uint32_t built = 0, refitTrees = 0;
  for (uint32_t f = 0; f < frames + kRefineWarmupFrames; ++f) {
    render::KeptVertices kept = renderer.keptVertices(0);
    for (uint32_t v = 0; v < kept.count; ++v) {
      kept.positions[3 * v + 2] = 0.05f * std::sin(3.0f * kept.positions[3 * v] + 0.3f * float(f));
    }
    renderer.markDirty(0);
    const render::FrameResult& result = renderer.wait(renderer.submit(request));
    if (f < kRefineWarmupFrames) continue;
    double refineMs = 0, refitMs = 0, passes = 0;
    for (const vk::PassTime& p : result.passes) {
      if (p.name == pass::kRefine) refineMs += p.milliseconds, ++passes;
      if (p.name == pass::kBlasRefit || p.name == pass::kBlasBuild) refitMs += p.milliseconds;
    }
    built += result.stats.treesBuilt;
    refitTrees += result.stats.treesRefit;
    refine.push_back(refineMs);
    refit.push_back(refitMs);
    refinePasses.push_back(passes);
  }
  RefineRow row;
  row.cageVertices = uint32_t(cage.positions.size());
  row.cageFaces = uint32_t(cage.faceVertexCounts.size());
  row.refinedVertices = uint32_t(s.shapes[0].vertexCount());
  for (const scene::Shape& part : s.shapes) row.triangles += part.triangleCount();
  row.treesBuilt = built;
  row.treesRefit = refitTrees;
  row.materials = materials;
  row.refinePasses = io::median(refinePasses);
  row.refineMs = io::median(refine);
  row.refitMs = io::median(refit);
  if (!refine.empty()) row.refineMinMs = *std::min_element(refine.begin(), refine.end());
  if (!refine.empty()) row.refineMaxMs = *std::max_element(refine.begin(), refine.end());
  if (!refit.empty()) row.refitMinMs = *std::min_element(refit.begin(), refit.end());
  if (!refit.empty()) row.refitMaxMs = *std::max_element(refit.begin(), refit.end());
  return row;
}

int runScale(const Options& o) {
  if (!o.json.empty()) io::checkWritable(o.json);
  const std::vector<uint64_t> sizes = counts(o.triangles), crowds = counts(o.crowds), refineSizes = counts(o.refined);
  const uint32_t runs = o.runs, restructure = o.restructure, width = o.width, height = o.height, frames = o.frames;
  vk::ContextDesc desc = io::contextDescFromEnvironment();
  desc.driverAccelerationStructures = true;
  auto context = vk::Context::create(desc);
  bool driver = context->caps().driverAccelerationStructures;
  std::printf("device: %s; the driver's acceleration structures: %s; trees: %s\n", context->facts().name.c_str(),
              driver ? "measured beside snell's" : "unsupported",
              o.compactTrees ? "compact (no exact child boxes)" : "with exact child boxes");
  render::BvhBuilder builder(*context, o.tuning);
  vk::UploadArena arena(*context, "bench scale uploads");
  std::vector<Row> rows;
  if (!sizes.empty()) {
    std::printf("\nsnell: build and refit of one sphere's tree; driver: fast-build and fast-trace builds, update of the latter\n");
    std::printf("%10s %9s %8s %9s %8s %6s %7s %6s | %9s %9s %9s %6s\n", "triangles", "build ms", "Mtri/s", "refit ms",
                "Mtri/s", "B/tri", "scratch", "SAH", "drv FB ms", "drv FT ms", "drv upd", "B/tri");
  }
  for (uint64_t target : sizes) {
    Mesh mesh = uvSphere(target);
    uint32_t triangles = static_cast<uint32_t>(mesh.indices.size() / 3);
    auto buffer = [&](const void* data, size_t bytes, const char* name) {
      VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT |
                                 (driver ? peer::kDriverInputUsage : 0);
      vk::Buffer b(*context, {bytes, usage, vk::MemoryDomain::Device, name, driver});
      vk::upload(*context, b, data, bytes);
      return b;
    };
    vk::Buffer positions = buffer(mesh.positions.data(), mesh.positions.size() * 4, "sphere positions");
    vk::Buffer indices = buffer(mesh.indices.data(), mesh.indices.size() * 4, "sphere indices");
    render::Bvh bvh = builder.makeBvh({triangles}, render::BvhLeaves::Triangles, "sphere",
                                      o.compactTrees ? render::BvhChildBoxes::Quantised : render::BvhChildBoxes::Exact);
    render::BvhInputs inputs{&positions, &indices, nullptr, nullptr};
    vk::Commands commands(*context, "bench scale");
    std::vector<double> build, refit;
    for (uint32_t run = 0; run <= runs; ++run) {
      commands.begin();
      arena.reset();
      commands.beginPass("build");
      builder.recordBuild(commands, bvh, inputs, {}, arena, restructure);
      commands.endPass();
      commands.beginPass("refit");
      builder.recordRefit(commands, bvh, inputs, {}, arena);
      commands.endPass();
      commands.submitAndWait();
      if (run == 0) continue;  // warm-up
      for (const vk::PassTime& p : commands.passTimes()) (p.name == "build" ? build : refit).push_back(p.milliseconds);
    }
    Row row;
    // The breakdown: separate runs, since a timestamp between steps waits for
    // the step before it and so costs the build some overlap.
    {
      builder.setStepTiming(true);
      std::map<std::string, std::vector<double>> steps;
      std::vector<std::string> order;
      for (uint32_t run = 0; run <= runs; ++run) {
        commands.begin();
        arena.reset();
        builder.recordBuild(commands, bvh, inputs, {}, arena, restructure);
        commands.submitAndWait();
        if (run == 0) continue;
        for (const vk::PassTime& p : commands.passTimes()) {
          if (!steps.count(p.name)) order.push_back(p.name);
          steps[p.name].push_back(p.milliseconds);
        }
      }
      builder.setStepTiming(false);
      for (const std::string& name : order) row.stepMs.emplace_back(name, io::median(steps[name]));
    }
    if (driver) {
      // The driver's structures over the same buffers, timed the same way.
      uint32_t vertices = static_cast<uint32_t>(mesh.positions.size() / 3);
      peer::DriverBlas fastBuild(*context, positions, vertices, indices, triangles, peer::DriverBuild::FastBuild);
      peer::DriverBlas fastTrace(*context, positions, vertices, indices, triangles, peer::DriverBuild::FastTrace);
      std::vector<double> fb, ft, update;
      for (uint32_t run = 0; run <= runs; ++run) {
        commands.begin();
        commands.beginPass("fast build");
        fastBuild.recordBuild(commands);
        commands.beginPass("fast trace");
        fastTrace.recordBuild(commands);
        commands.beginPass("update");
        fastTrace.recordUpdate(commands);
        commands.endPass();
        commands.submitAndWait();
        if (run == 0) continue;
        for (const vk::PassTime& p : commands.passTimes()) {
          (p.name == "fast build" ? fb : p.name == "fast trace" ? ft : update).push_back(p.milliseconds);
        }
      }
      row.driverFastBuildMs = io::median(fb);
      row.driverFastTraceMs = io::median(ft);
      row.driverUpdateMs = io::median(update);
      row.driverBytesPerTriangle = double(fastTrace.structureBytes()) / triangles;
    }
    row.triangles = triangles;
    row.buildMs = io::median(build);
    row.refitMs = io::median(refit);
    row.bytesPerTriangle = double(bvh.treeBytes()) / triangles;
    row.scratchPerTriangle = double(builder.scratchBytes()) / triangles;
    if (triangles <= o.sahLimit) {
      render::BvhSnapshot snapshot = builder.download(bvh);
      std::vector<ref::Aabb> boxes(triangles);
      for (uint32_t t = 0; t < triangles; ++t) {
        for (int k = 0; k < 3; ++k) {
          const float* p = &mesh.positions[3 * size_t(mesh.indices[3 * size_t(t) + size_t(k)])];
          boxes[t].extend(glm::dvec3(p[0], p[1], p[2]));
        }
      }
      render::BvhSnapshot::TreeBoxes tree = snapshot.exactTreeBoxes(0, [&](uint32_t t) {
        const ref::Aabb& b = boxes[t];
        return render::BoxFloats{float(b.lo.x), float(b.lo.y), float(b.lo.z), float(b.hi.x), float(b.hi.y), float(b.hi.z)};
      });
      row.sahRatio = ref::sahCost(tree.internal, tree.leaves) / ref::binnedSahCost(boxes);
    }
    rows.push_back(row);
    auto ms = [&](double v) { return driver ? std::to_string(v).substr(0, 7) : std::string("-"); };
    std::printf("%10llu %9.3f %8.1f %9.4f %8.1f %6.1f %7.1f %6s | %9s %9s %9s %6s\n",
                static_cast<unsigned long long>(triangles), row.buildMs, triangles / row.buildMs / 1e3, row.refitMs,
                triangles / row.refitMs / 1e3, row.bytesPerTriangle, row.scratchPerTriangle,
                row.sahRatio > 0 ? std::to_string(row.sahRatio).substr(0, 5).c_str() : "-",
                ms(row.driverFastBuildMs).c_str(), ms(row.driverFastTraceMs).c_str(), ms(row.driverUpdateMs).c_str(),
                driver ? std::to_string(row.driverBytesPerTriangle).substr(0, 5).c_str() : "-");
    std::printf("%10s build steps, ms:", "");
    double stepSum = 0;
    for (const auto& [name, ms] : row.stepMs) {
      std::printf(" %s %.4f,", name.c_str() + 4, ms);  // less "bvh "
      stepSum += ms;
    }
    std::printf(" sum %.4f\n", stepSum);
    std::fflush(stdout);
    builder.releaseScratch();
  }

  std::vector<CrowdRow> crowdRows;
  if (!crowds.empty()) {
    std::printf("\nviewport frames of eye crowds at %ux%u (median GPU ms per animated frame)\n", width, height);
    std::printf("%6s %10s %7s %7s %7s %7s %7s %7s %8s %8s %10s %7s %6s\n", "chars", "triangles", "deform", "refit",
                "tlas", "r.depth", "trace", "r.shade", "frame", "refract", "pixels", "Grays/s", "B/tri");
  }
  for (uint64_t characters : crowds) {
    CrowdRow r = measureCrowd(*context, static_cast<uint32_t>(characters), width, height, frames, o.compactTrees);
    auto passMs = [&](const char* name) { return r.passMs.count(name) ? r.passMs.at(name) : 0.0; };
    double trace = passMs(pass::kTrace);
    std::printf("%6u %10llu %7.3f %7.3f %7.3f %7.3f %7.3f %7.3f %8.3f %8.3f %10.0f %7.2f %6.1f\n", r.characters,
                static_cast<unsigned long long>(r.triangles), passMs(pass::kDeform), passMs(pass::kBlasRefit), passMs(pass::kTlas),
                passMs(pass::kRasterDepth), trace, passMs(pass::kRasterShading), r.frameMs, r.refractionMs, r.pixelsTraced,
                trace > 0 ? r.pixelsTraced / trace / 1e6 : 0.0, r.treeBytesPerTriangle);
    std::fflush(stdout);
    crowdRows.push_back(std::move(r));
  }
  std::vector<RefineRow> refineRows;
  if (!refineSizes.empty()) {
    std::printf("\nsubdivision cages refined twice, moved every frame (GPU ms: the median of %u frames after %u "
                "warm-up frames, and their spread)%s\n",
                frames, kRefineWarmupFrames,
                o.refinedMaterials > 1 ? (", " + std::to_string(o.refinedMaterials) + " materials a cage").c_str() : "");
    std::printf("%12s %12s %14s %11s %17s %14s %10s %17s %8s %11s %14s\n", "cage verts", "cage faces", "refined verts",
                "refine ms", "refine min-max", "M verts/s", "refit ms", "refit min-max", "refines", "triangles",
                "trees b / r");
  }
  for (uint64_t target : refineSizes) {
    RefineRow r = measureRefine(*context, target, frames, o.compactTrees, o.refinedMaterials);
    std::printf("%12u %12u %14u %11.4f %8.4f-%-8.4f %14.1f %10.4f %8.4f-%-8.4f %8.0f %11llu %6u / %-6u\n", r.cageVertices,
                r.cageFaces, r.refinedVertices, r.refineMs, r.refineMinMs, r.refineMaxMs,
                r.refineMs > 0 ? r.refinedVertices / r.refineMs / 1e3 : 0.0, r.refitMs, r.refitMinMs, r.refitMaxMs,
                r.refinePasses, static_cast<unsigned long long>(r.triangles), r.treesBuilt, r.treesRefit);
    std::fflush(stdout);
    refineRows.push_back(r);
  }
  if (!o.json.empty()) {
    io::Json j = io::reportHead("bench-scale", &context->facts());
    j["driver_acceleration_structures"] = driver;
    j["restructure_rounds"] = restructure;
    j["compact_trees"] = o.compactTrees;
    j["runs"] = runs;
    io::Json spheres = io::Json::array();
    for (const Row& r : rows) {
      spheres.push_back(io::Json{{"triangles", r.triangles},
                                 {"build_ms", r.buildMs},
                                 {"refit_ms", r.refitMs},
                                 {"build_mtris_per_s", double(r.triangles) / r.buildMs / 1e3},
                                 {"refit_mtris_per_s", double(r.triangles) / r.refitMs / 1e3},
                                 {"tree_bytes_per_triangle", r.bytesPerTriangle},
                                 {"scratch_bytes_per_triangle", r.scratchPerTriangle},
                                 {"sah_over_binned", r.sahRatio},
                                 {"driver_fast_build_ms", r.driverFastBuildMs},
                                 {"driver_fast_trace_build_ms", r.driverFastTraceMs},
                                 {"driver_update_ms", r.driverUpdateMs},
                                 {"driver_bytes_per_triangle", r.driverBytesPerTriangle},
                                 {"build_steps_ms", [&] {
                                    io::Json steps = io::Json::object();
                                    for (const auto& [name, ms] : r.stepMs) steps[name] = ms;
                                    return steps;
                                  }()}});
    }
    j["spheres"] = std::move(spheres);
    j["crowd_viewport"] = io::Json{{"width", width}, {"height", height}, {"frames", frames}};
    io::Json crowdsJson = io::Json::array();
    for (const CrowdRow& r : crowdRows) {
      io::Json passes = io::Json::object();
      for (const auto& [name, ms] : r.passMs) passes[name] = ms;
      crowdsJson.push_back(io::Json{{"characters", r.characters},
                                    {"triangles", r.triangles},
                                    {"frame_ms", r.frameMs},
                                    {"refraction_ms", r.refractionMs},
                                    {"pixels_traced", r.pixelsTraced},
                                    {"memory_bytes_per_triangle", r.memoryPerTriangle},
                                    {"tree_bytes_per_triangle", r.treeBytesPerTriangle},
                                    {"passes_ms", std::move(passes)}});
    }
    j["crowds"] = std::move(crowdsJson);
    io::Json refineJson = io::Json::array();
    for (const RefineRow& r : refineRows) {
      refineJson.push_back(io::Json{{"cage_vertices", r.cageVertices},
                                    {"cage_faces", r.cageFaces},
                                    {"refined_vertices", r.refinedVertices},
                                    {"materials", r.materials},
                                    {"refine_passes_per_frame", r.refinePasses},
                                    {"refine_ms", r.refineMs},
                                    {"refine_min_ms", r.refineMinMs},
                                    {"refine_max_ms", r.refineMaxMs},
                                    {"refit_ms", r.refitMs},
                                    {"refit_min_ms", r.refitMinMs},
                                    {"refit_max_ms", r.refitMaxMs},
                                    {"triangles", r.triangles},
                                    {"trees_built", r.treesBuilt},
                                    {"trees_refit", r.treesRefit},
                                    {"warmup_frames", kRefineWarmupFrames}});
    }
    j["subdivision"] = std::move(refineJson);
    io::writeJson(o.json, j);
  }
  return validationExitCode(*context);
}

}  // namespace

void addBenchScale(CLI::App& bench, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* sub =
      bench.add_subcommand("scale", "tree build and refit from 1e4 to 1e7 triangles, and crowds of characters");
  describe(*sub,
      "Triangles: builds and refits the bottom-level tree of UV spheres of\n"
      "increasing size on the GPU and reports, per size, the median GPU time of a\n"
      "build (boxes, Morton codes, sort, H-PLOC) and of a refit, in milliseconds and\n"
      "millions of triangles per second, the tree's memory per triangle (the build's\n"
      "scratch separately) and, up to --sah-limit triangles, its SAH cost against a\n"
      "CPU binned-SAH tree of the same triangles. Where the device has its own\n"
      "acceleration structures (VK_KHR_acceleration_structure), the same triangles\n"
      "are built with them in the same run (fast-build and fast-trace), and the\n"
      "fast-trace one updated in place, as the peer to beat.\n"
      "\n"
      "Characters: animated viewport frames of crowds of the procedural eye (two\n"
      "eyes a character): the median GPU time of each pass, the refraction work\n"
      "(deform, trees, masked trace), pixels traced and the trace's rays per second.\n"
      "\n"
      "Refined vertices: a Catmull-Clark cage of n x n quads refined twice, which\n"
      "the host moves every frame: the refine pass's GPU time, vertices refined per\n"
      "second, and the refit of the refined surface's tree after it, with the\n"
      "triangles it holds and how many trees the timed frames rebuilt and refit\n"
      "(\"trees b / r\": a rebuild, where the surface's SAH grew too far, counts\n"
      "in \"refit ms\"). With --refined-materials the cage's faces carry that\n"
      "many materials in bands: it is still refined once (\"refines\": refine\n"
      "passes a frame), with a tree a material.");
  sub->footer(kHelpFooter);
  // Lists take one word each, so they never swallow the words after them.
  sub->add_option("--triangles", o->triangles, "sphere sizes (default 10000,100000,1000000,10000000; 0 skips)")
      ->type_name("N,N,...")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->check(countOrZero(1000000000));
  sub->add_option("--runs", o->runs, "timed builds and refits per size (default 10, after one warm-up)")
      ->type_name("N")
      ->check(positiveCount());
  sub->add_option("--restructure", o->restructure, "rounds of treelet restructuring after each build (default 0)")
      ->type_name("N");
  sub->add_option("--sah-limit", o->sahLimit, "price the tree against binned SAH up to this size (default 1000000)")
      ->type_name("N");
  sub->add_flag("--compact-trees", o->compactTrees,
                "trees without each node's exact child boxes (40 bytes a triangle): what builds and refits cost without them");
  sub->add_option("--hploc-workgroup", o->tuning.hplocWorkgroup, "H-PLOC's workgroup size (default: the device's choice)")
      ->type_name("N");
  sub->add_option("--refit-workgroup", o->tuning.refitWorkgroup, "the refit's workgroup size (default: the device's choice)")
      ->type_name("N");
  // At most the procedural eye's crowd limit (scene::checkEyeOptions).
  sub->add_option("--crowds", o->crowds, "characters per crowd (default 1,2,10,100,1000; 0 skips; at most 10000)")
      ->type_name("N,N,...")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->check(countOrZero(10000));
  sub->add_option("--refined", o->refined, "refined vertices per subdivision cage (default 10000,100000,1000000; 0 skips)")
      ->type_name("N,N,...")
      ->delimiter(',')
      ->allow_extra_args(false)
      ->check(countOrZero(4194304));
  sub->add_option("--refined-materials", o->refinedMaterials,
                  "materials of each subdivision cage, in bands of its faces (default 1): refined once, a tree each")
      ->type_name("N")
      ->check(CLI::Range(1u, 64u));
  addSize(*sub, "--size", o->width, o->height, "viewport size of the crowd frames (default 3840x2160)");
  sub->add_option("--frames", o->frames, "animated frames measured per crowd and refined cage (default 20, after 5)")
      ->type_name("N")
      ->check(positiveCount());
  sub->add_option("--json", o->json, "write the results as JSON too")->type_name("FILE");
  sub->callback([o, &run] { run = [o] { return runScale(*o); }; });
}

}  // namespace snell::cli
