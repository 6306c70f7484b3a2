// `snell bench bvh`: how good the GPU's trees are, as SAH cost against a CPU
// binned-SAH build of the very same triangles (src/ref), per mesh.
#include "cli/commands.h"
#include "io/image_file.h"
#include "io/json.h"

#include "ref/sah_bvh.h"
#include "render/one_view.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "scene/view.h"
#include "vk/commands.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>

namespace snell::cli {

namespace {

struct Options {
  std::vector<std::string> files;
  std::string json;
  uint32_t eyeResolution = 64;
};

struct Row {
  std::string scene, mesh;
  uint32_t triangles = 0;
  double gpuCost = 0, storedCost = 0, restructuredCost = 0, cpuCost = 0;
  double ratio() const { return cpuCost > 0 ? gpuCost / cpuCost : 1.0; }
  double storedRatio() const { return cpuCost > 0 ? storedCost / cpuCost : 1.0; }
  double restructuredRatio() const { return cpuCost > 0 ? restructuredCost / cpuCost : 1.0; }
};

void measure(vk::Context& context, const scene::Scene& scene, const std::string& label, std::vector<Row>& rows) {
  scene::Pose pose = scene::evaluate(scene, 0.0);
  render::Renderer renderer(context, scene, pose);
  // One small frame deforms the shapes into the buffers the trees are built from.
  render::FrameSettings settings{8, 8, scene::resolveView(scene, pose, {}), {}, gpu::kDefaultMaxInterfaces};
  render::renderFrame(renderer, pose, settings);
  const render::SceneGpu& gpuScene = renderer.sceneGpu();
  std::vector<uint32_t> sizes;
  for (const render::GeometryRange& g : gpuScene.geometries) sizes.push_back(g.triangleCount);
  render::BvhBuilder builder(context);
  vk::UploadArena arena(context, "bench bvh uploads");
  auto buildWith = [&](uint32_t rounds) {
    // Compact: its nodes store the quantised boxes "stored" prices (the default trees test exact ones).
    render::Bvh bvh = builder.makeBvh(sizes, render::BvhLeaves::Triangles, label, render::BvhChildBoxes::Quantised);
    vk::Commands commands(context, "bench bvh build");
    commands.begin();
    builder.recordBuild(commands, bvh, {&gpuScene.positions, &gpuScene.indices, nullptr, nullptr}, {}, arena, rounds);
    commands.submitAndWait();
    arena.reset();
    return builder.download(bvh);
  };
  render::BvhSnapshot plain = buildWith(0), restructured = buildWith(3);
  std::vector<float> positions(size_t(gpuScene.vertexCount) * 3);
  std::vector<uint32_t> indices(size_t(gpuScene.triangleCount) * 3);
  vk::download(context, gpuScene.positions, positions.data(), positions.size() * 4);
  vk::download(context, gpuScene.indices, indices.data(), indices.size() * 4);
  auto triangleBox = [&](uint32_t t) {
    ref::Aabb b;
    for (int k = 0; k < 3; ++k) {
      const float* p = &positions[3 * size_t(indices[3 * size_t(t) + size_t(k)])];
      b.extend(glm::dvec3(p[0], p[1], p[2]));
    }
    return b;
  };
  auto boxFloats = [&](uint32_t t) {
    ref::Aabb b = triangleBox(t);
    return render::BoxFloats{float(b.lo.x), float(b.lo.y), float(b.lo.z), float(b.hi.x), float(b.hi.y), float(b.hi.z)};
  };
  // The build's topology priced with exact boxes, and the boxes as stored (quantised) that rays test.
  auto cost = [&](const render::BvhSnapshot& s, uint32_t g) {
    render::BvhSnapshot::TreeBoxes tree = s.exactTreeBoxes(g, boxFloats);
    return ref::sahCost(tree.internal, tree.leaves);
  };
  auto storedCost = [&](const render::BvhSnapshot& s, uint32_t g) {
    render::BvhSnapshot::TreeBoxes tree = s.treeBoxes(g);
    return ref::sahCost(tree.internal, tree.leaves);
  };

  for (size_t g = 0; g < gpuScene.geometries.size(); ++g) {
    const render::GeometryRange& range = gpuScene.geometries[g];
    if (range.triangleCount < 2) continue;
    std::vector<ref::Aabb> triangles;
    for (uint32_t t = range.firstTriangle; t < range.firstTriangle + range.triangleCount; ++t) {
      triangles.push_back(triangleBox(t));
    }
    Row row;
    row.scene = label;
    row.mesh = scene.shapes[size_t(range.shape)].name;
    row.triangles = range.triangleCount;
    row.gpuCost = cost(plain, static_cast<uint32_t>(g));
    row.storedCost = storedCost(plain, static_cast<uint32_t>(g));
    row.restructuredCost = cost(restructured, static_cast<uint32_t>(g));
    row.cpuCost = ref::binnedSahCost(triangles);
    rows.push_back(row);
  }
}

int runBvh(const Options& o) {
  if (!o.json.empty()) io::checkWritable(o.json);
  auto context = vk::Context::create(io::contextDescFromEnvironment());
  std::printf("device: %s\n", context->facts().name.c_str());
  std::vector<Row> rows;
  scene::EyeOptions eye;
  eye.resolution = o.eyeResolution;
  measure(*context, scene::makeEye(eye), "eye (resolution " + std::to_string(o.eyeResolution) + ")", rows);
  for (const std::string& f : o.files) {
    scene::LoadOptions load;
    load.ignoredExtensions = {"KHR_materials_iridescence"};
    measure(*context, scene::loadGltf(f, load), std::filesystem::path(f).stem().string(), rows);
  }

  std::printf("%-28s %-28s %9s %10s %12s %10s %7s %8s %12s\n", "scene", "mesh", "triangles", "GPU SAH", "+restructure",
              "CPU SAH", "ratio", "stored", "restr. ratio");
  double worst = 0;
  for (const Row& r : rows) {
    std::printf("%-28.28s %-28.28s %9u %10.2f %12.2f %10.2f %7.3f %8.3f %12.3f\n", r.scene.c_str(), r.mesh.c_str(),
                r.triangles, r.gpuCost, r.restructuredCost, r.cpuCost, r.ratio(), r.storedRatio(), r.restructuredRatio());
    worst = std::max(worst, r.ratio());
  }
  std::printf("worst ratio %.3f\n", worst);
  if (!o.json.empty()) {
    io::Json j = io::reportHead("bench-bvh", &context->facts());
    io::Json meshes = io::Json::array();
    for (const Row& r : rows) {
      meshes.push_back(io::Json{{"scene", r.scene},
                                {"mesh", r.mesh},
                                {"triangles", r.triangles},
                                {"gpu_sah", r.gpuCost},
                                {"restructured_sah", r.restructuredCost},
                                {"cpu_binned_sah", r.cpuCost},
                                {"ratio", r.ratio()},
                                {"stored_quantised_ratio", r.storedRatio()},
                                {"restructured_ratio", r.restructuredRatio()}});
    }
    j["meshes"] = std::move(meshes);
    j["worst_ratio"] = worst;
    io::writeJson(o.json, j);
  }
  return validationExitCode(*context);
}

}  // namespace

void addBenchBvh(CLI::App& bench, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* sub = bench.add_subcommand("bvh", "SAH cost of the GPU's trees against a CPU binned-SAH tree, per mesh");
  describe(*sub,
      "Builds every bottom-level tree of each scene on the GPU (the procedural eye\n"
      "first, then the files given) and prices it with the surface area heuristic\n"
      "(Ct = 1 per internal node, Ci = 1 per triangle, one triangle per leaf), next\n"
      "to a CPU binned-SAH tree (32 bins) over the same triangles. ratio = GPU / CPU: 1.0 is as good\n"
      "as binned SAH, higher is worse. \"GPU SAH\" prices the tree the renderer builds\n"
      "(H-PLOC) with exact boxes; \"stored\" prices its boxes as compact trees store\n"
      "them, quantised to 8 bits within each node (what their rays test; the default\n"
      "trees keep exact ones); \"+restructure\" is\n"
      "the same build followed by three rounds of treelet restructuring.");
  sub->footer(kHelpFooter);
  sub->add_option("scenes", o->files, "glTF files measured after the procedural eye")->type_name("SCENE.glb");
  sub->add_option("--json", o->json, "write the results as JSON too")->type_name("FILE");
  // The procedural eye's own limits (scene::checkEyeOptions), named after this option.
  sub->add_option("--eye-resolution", o->eyeResolution, "segments of the procedural eye, 8-2048 (default 64)")
      ->type_name("N")
      ->check(CLI::Range(8u, 2048u));
  sub->callback([o, &run] { run = [o] { return runBvh(*o); }; });
}

}  // namespace snell::cli
