// `snell bench cost`: what one traced frame costs and where its time goes.
// Per pixel: closest-hit queries (segments), node visits, child boxes and
// triangles tested (the trace's AOV counters), and how many of a subgroup's
// lanes its traversal loops kept at work; and the hit-replay ablation:
// the same view traced again reading each segment's recorded hit instead of
// traversing, so the trace's time splits into traversal and the rest
// (shading, refraction, textures). The driver's ray tracing is timed beside
// it on the same view where the device has it.
#include "cli/commands.h"
#include "io/environment.h"
#include "io/image_file.h"
#include "io/json.h"

#include "render/pass_names.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "scene/scene_summary.h"
#include "scene/view.h"

#include <algorithm>
#include <cstdio>
#include <map>

namespace snell::cli {

namespace {

struct Options {
  std::string file;  ///< empty: the procedural eye
  uint32_t width = 1920, height = 1080, frames = 20;
  scene::EyeOptions eye;
  std::string json;
};

struct CostCounters {
  double segments = 0, visits = 0, boxTests = 0, triangleTests = 0;
  /// Visits that entered no child; of those, the ones whose children the ray
  /// meets beyond the nearest hit (which a hit found sooner would have culled).
  double deadVisits = 0, culledVisits = 0;
  double leafVisits = 0;  ///< leaves reached, whose triangles make triangleTests
  uint32_t visitsP50 = 0, visitsP99 = 0, visitsMax = 0, segmentsMax = 0;
  /// The traversal loops' lanes at work: the share of a subgroup's lanes still
  /// walking, over the passes it made (0: not counted, as by the driver's pipeline).
  double laneUtilisation = 0;
  /// The leaf loops' lanes at work: the share of a subgroup's lanes testing a
  /// triangle in each pass of a leaf loop (the others wait for them).
  double leafLaneUtilisation = 0;
  /// How much longer a subgroup's longest walk is than its pixels' mean walk:
  /// the sum over pixels of their subgroup's most node visits over the sum of their own.
  double longestOverMean = 0;
};

CostCounters countersOf(const std::vector<gpu::TraceAov>& aov) {
  CostCounters c;
  std::vector<uint32_t> visits;
  visits.reserve(aov.size());
  double laneSteps = 0, subgroupLanes = 0, longest = 0, leafLanes = 0;
  for (const gpu::TraceAov& a : aov) {
    laneSteps += a.walkSteps;
    subgroupLanes += double(a.subgroupSteps) * a.subgroupSize;
    longest += a.subgroupVisits;
    leafLanes += double(a.leafSteps) * a.subgroupSize;
    c.segments += a.segments;
    c.visits += a.nodeVisits;
    c.boxTests += a.boxTests;
    c.triangleTests += a.triangleTests;
    c.deadVisits += a.deadVisits;
    c.culledVisits += a.culledVisits;
    c.leafVisits += a.leafVisits;
    c.segmentsMax = std::max(c.segmentsMax, a.segments);
    visits.push_back(a.nodeVisits);
  }
  if (subgroupLanes > 0) c.laneUtilisation = laneSteps / subgroupLanes;
  if (c.visits > 0) c.longestOverMean = longest / c.visits;
  if (leafLanes > 0) c.leafLaneUtilisation = c.leafVisits / leafLanes;  // before the sums become means
  double n = std::max<double>(double(aov.size()), 1.0);
  for (double* v : {&c.segments, &c.visits, &c.boxTests, &c.triangleTests, &c.deadVisits, &c.culledVisits, &c.leafVisits}) {
    *v /= n;
  }
  if (!visits.empty()) {
    std::sort(visits.begin(), visits.end());
    c.visitsP50 = visits[visits.size() / 2];
    c.visitsP99 = visits[std::min(visits.size() - 1, visits.size() * 99 / 100)];
    c.visitsMax = visits.back();
  }
  return c;
}

int runCost(const Options& o) {
  if (!o.json.empty()) io::checkWritable(o.json);
  scene::Scene scene = o.file.empty() ? scene::makeEye(o.eye) : scene::loadGltf(o.file);
  std::string label = !o.file.empty() ? o.file
                      : o.eye.crowd  ? "eye crowd of " + std::to_string(o.eye.crowd)
                                     : "eye (resolution " + std::to_string(o.eye.resolution) + ")";
  vk::ContextDesc desc = io::contextDescFromEnvironment();
  desc.driverRayTracing = true;  // for the peer, where the device has it
  auto context = vk::Context::create(desc);
  render::checkImageSize(*context, o.width, o.height);
  bool driver = context->caps().driverRayTracing;
  scene::SceneSummary summary = scene::summarize(scene);
  std::printf("device: %s\nscene: %s, %llu triangles, %ux%u, Fresnel on, one still frame\n",
              context->facts().name.c_str(), label.c_str(), static_cast<unsigned long long>(summary.triangles),
              o.width, o.height);

  scene::Pose pose = scene::evaluate(scene, 0.0);
  render::Renderer renderer(*context, scene, pose);
  auto view = [&](render::HitReplay replay, bool driverTrace, bool aov) {
    render::ViewRequest v;
    v.settings = {o.width, o.height, scene::resolveView(scene, pose, {}), glm::vec3(scene::kDefaultBackground),
                  gpu::kDefaultMaxInterfaces};
    v.settings.hitReplay = replay;
    v.driverTrace = driverTrace;
    v.aov = aov;
    return v;
  };
  auto draw = [&](const render::ViewRequest& v, bool readback) -> const render::FrameResult& {
    render::FrameRequest request;
    request.pose = &pose;
    request.views.push_back(v);
    if (readback) request.readbacks.push_back({.view = 0});
    return renderer.wait(renderer.submit(request));
  };
  auto traceMs = [](const render::FrameResult& r) {
    double ms = 0;
    for (const vk::PassTime& p : r.passes) ms += p.name == pass::kTrace || p.name == pass::kDriverTrace ? p.milliseconds : 0.0;
    return ms;
  };

  // The counters, from one frame's AOVs; then the record the replays read.
  render::ViewPixels pixels = draw(view(render::HitReplay::Off, false, true), true).views.at(0);
  CostCounters cost = countersOf(pixels.aov);
  CostCounters driverCost;
  if (driver) driverCost = countersOf(draw(view(render::HitReplay::Off, true, true), true).views.at(0).aov);
  draw(view(render::HitReplay::Record, false, false), false);
  // The ablation is only fair if the replay does the path's whole work: it must draw the same picture.
  std::vector<glm::vec4> replayed = draw(view(render::HitReplay::Replay, false, false), true).views.at(0).trace;
  size_t differing = 0;
  for (size_t i = 0; i < replayed.size() && i < pixels.trace.size(); ++i) differing += replayed[i] != pixels.trace[i];

  // Each round draws every row once, in turn, so clock changes fall on all alike.
  std::vector<std::string> rows = {"trace", "trace, hits replayed"};
  if (driver) rows.push_back("driver-rt");
  std::map<std::string, std::vector<double>> times;
  for (uint32_t round = 0; round <= o.frames; ++round) {
    for (const std::string& row : rows) {
      render::HitReplay replay = row == "trace, hits replayed" ? render::HitReplay::Replay : render::HitReplay::Off;
      double ms = traceMs(draw(view(replay, row == "driver-rt", false), false));
      if (round > 0) times[row].push_back(ms);  // the first round warms up
    }
  }
  double full = io::median(times["trace"]), replayMs = io::median(times["trace, hits replayed"]);
  double pixelCount = double(o.width) * o.height;

  std::printf("\nper pixel: %.3f segments (most %u), %.2f node visits (median %u, 99th %u, most %u), %.2f child boxes "
              "and %.2f triangles tested\n",
              cost.segments, cost.segmentsMax, cost.visits, cost.visitsP50, cost.visitsP99, cost.visitsMax,
              cost.boxTests, cost.triangleTests);
  std::printf("per segment: %.2f node visits, %.2f child boxes, %.2f triangles\n", cost.visits / cost.segments,
              cost.boxTests / cost.segments, cost.triangleTests / cost.segments);
  auto share = [](double part, double whole) { return whole > 0 ? 100.0 * part / whole : 0.0; };
  std::printf("visits: %.2f child boxes tested a visit; %.1f%% dead (no child entered), %.1f%% dead only for the "
              "nearest hit (children beyond it); %.2f triangles tested a leaf reached\n",
              cost.visits > 0 ? cost.boxTests / cost.visits : 0.0, share(cost.deadVisits, cost.visits),
              share(cost.culledVisits, cost.visits), cost.leafVisits > 0 ? cost.triangleTests / cost.leafVisits : 0.0);
  std::printf("lanes: %.1f%% of a subgroup's lanes walk in each pass of the traversal loops (subgroups of %u); "
              "a subgroup's longest walk is %.2fx its pixels' mean\n",
              100.0 * cost.laneUtilisation, pixels.aov.empty() ? 0u : pixels.aov.front().subgroupSize,
              cost.longestOverMean);
  std::printf("leaves: %.1f%% of a subgroup's lanes test a triangle in each pass of the leaf loops\n",
              100.0 * cost.leafLaneUtilisation);
  if (driver) std::printf("driver-rt: %.3f segments per pixel\n", driverCost.segments);
  std::printf("\n%-22s %10s %12s\n", "trace", "median ms", "G segments/s");
  for (const std::string& row : rows) {
    double ms = io::median(times[row]);
    double segs = (row == "driver-rt" ? driverCost.segments : cost.segments) * pixelCount;
    std::printf("%-22s %10.4f %12.3f\n", row.c_str(), ms, segs / ms / 1e6);
  }
  std::printf("traversal: %.4f ms of %.4f (%.1f%%); the rest (shading, refraction, textures, writes): %.4f ms\n",
              full - replayMs, full, 100.0 * (full - replayMs) / full, replayMs);
  std::printf("the replay draws the traced picture: %s (%zu pixels differ)\n", differing == 0 ? "yes" : "NO", differing);
  if (driver) std::printf("trace against driver-rt: %.3fx\n", io::median(times["driver-rt"]) / full);

  if (!o.json.empty()) {
    io::Json j = io::reportHead("bench-cost", &context->facts());
    j["scene"] = label;
    j["triangles"] = summary.triangles;
    j["width"] = o.width;
    j["height"] = o.height;
    j["frames"] = o.frames;
    j["per_pixel"] = io::Json{{"segments", cost.segments},
                              {"node_visits", cost.visits},
                              {"node_visits_median", cost.visitsP50},
                              {"node_visits_p99", cost.visitsP99},
                              {"node_visits_max", cost.visitsMax},
                              {"child_box_tests", cost.boxTests},
                              {"triangle_tests", cost.triangleTests},
                              {"dead_visits", cost.deadVisits},
                              {"late_pops", cost.culledVisits},
                              {"leaf_visits", cost.leafVisits}};
    j["child_tests_per_visit"] = cost.visits > 0 ? cost.boxTests / cost.visits : 0.0;
    j["triangle_tests_per_leaf"] = cost.leafVisits > 0 ? cost.triangleTests / cost.leafVisits : 0.0;
    j["lane_utilisation"] = cost.laneUtilisation;
    j["leaf_lane_utilisation"] = cost.leafLaneUtilisation;
    j["subgroup_longest_over_mean_visits"] = cost.longestOverMean;
    j["subgroup_size"] = pixels.aov.empty() ? 0u : pixels.aov.front().subgroupSize;
    if (driver) j["driver_segments_per_pixel"] = driverCost.segments;
    io::Json medians = io::Json::object();
    for (const std::string& row : rows) medians[row] = io::median(times[row]);
    j["trace_median_ms"] = std::move(medians);
    j["traversal_share"] = (full - replayMs) / full;
    j["replay_pixels_differing"] = differing;
    io::writeJson(o.json, j);
  }
  return validationExitCode(*context);
}

}  // namespace

void addBenchCost(CLI::App& bench, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* sub = bench.add_subcommand("cost", "per-pixel work of the trace, and its traversal's share of the time");
  describe(*sub,
      "Traces one still frame of the procedural eye (or SCENE), Fresnel on, and\n"
      "reports per pixel the closest-hit queries (segments), BVH node visits and\n"
      "the child boxes and triangles tested, the visits that entered no child (of\n"
      "those, the ones whose children lie beyond the nearest hit) and the\n"
      "triangles tested a leaf reached, and the share of a subgroup's lanes at\n"
      "work in the traversal loops' passes and in the leaf loops' (a pass in\n"
      "which some lanes test a triangle holds up the others). Then the\n"
      "hit-replay ablation: each segment's closest hit is recorded and the\n"
      "frame traced again reading them instead of traversing (the first 8\n"
      "segments of a pixel; later ones are traced in both), which leaves the\n"
      "path's work without the traversal.\n"
      "Medians over --frames rounds, each drawing the trace, the replay and the\n"
      "driver's ray tracing (where the device has it) in turn.");
  sub->footer(kHelpFooter);
  addBenchScene(*sub, o->file, o->width, o->height, "1920x1080");
  sub->add_option("--frames", o->frames, "rounds measured (default 20)")->type_name("N")->check(positiveCount());
  addEyeOptions(*sub, o->eye);
  sub->add_option("--json", o->json, "write the results as JSON too")->type_name("FILE");
  sub->callback([o, &run] { run = [o] { return runCost(*o); }; });
}

}  // namespace snell::cli
