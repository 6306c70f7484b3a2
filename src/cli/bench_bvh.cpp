// `snell bench bvh`: how good the GPU's trees are, as SAH cost against a CPU
// binned-SAH build of the very same triangles (src/ref), per mesh.
#include "cli/cli.h"
#include "cli/image_file.h"

#include "ref/sah_bvh.h"
#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "scene/view.h"
#include "vk/commands.h"

#include <sstream>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace snell::cli {

namespace {

constexpr const char* kHelp = R"(usage: snell bench bvh [SCENE.glb ...] [--json FILE] [--eye-resolution N]

Builds every bottom-level tree of each scene on the GPU (the procedural eye
first, then the files given) and prices it with the surface area heuristic
(Ct = 1 per internal node, Ci = 1 per triangle, one triangle per leaf), next
to a CPU binned-SAH tree (32 bins) over the same triangles. ratio = GPU / CPU: 1.0 is as good
as binned SAH, higher is worse. "GPU SAH" prices the tree the renderer builds
(H-PLOC) with exact boxes; "stored" prices its boxes as the nodes store them,
quantised to 8 bits within each node (what a ray tests); "+restructure" is
the same build followed by three rounds of treelet restructuring.
)";

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
  render::renderFrame(context, renderer, pose, settings);
  const render::SceneGpu& gpuScene = renderer.sceneGpu();
  std::vector<uint32_t> sizes;
  for (const render::GeometryRange& g : gpuScene.geometries) sizes.push_back(g.triangleCount);
  render::BvhBuilder builder(context);
  vk::UploadArena arena(context, "bench bvh uploads");
  auto buildWith = [&](uint32_t rounds) {
    render::Bvh bvh = builder.makeBvh(sizes, render::BvhLeaves::Triangles, label);
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

}  // namespace

int runBenchBvh(const Args& args) {
  std::vector<std::string> files;
  std::string json;
  uint32_t eyeResolution = 64;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
    if (a == "--json" || a == "--eye-resolution") {
      if (i + 1 >= args.size()) throw UsageError{"bench bvh: " + a + " needs a value"};
      if (a == "--json") checkWritable(json = args[++i]);
      else eyeResolution = uint32_t(parseCount(a, args[++i]));
    } else if (!a.empty() && a[0] == '-') {
      throw UsageError{"bench bvh: unknown option " + a};
    } else {
      files.push_back(a);
    }
  }
  auto context = vk::Context::create(contextDescFromEnvironment());
  std::printf("device: %s\n", context->facts().name.c_str());
  std::vector<Row> rows;
  scene::EyeOptions eye;
  eye.resolution = eyeResolution;
  measure(*context, scene::makeEye(eye), "eye (resolution " + std::to_string(eyeResolution) + ")", rows);
  for (const std::string& f : files) {
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
  if (!json.empty()) {
    std::ostringstream out;  // written whole or not at all
    out << "{\n  \"device\": \"" << context->facts().name << "\",\n  \"meshes\": [\n";
    for (size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      out << "    {\"scene\": \"" << r.scene << "\", \"mesh\": \"" << r.mesh << "\", \"triangles\": " << r.triangles
          << ", \"gpu_sah\": " << r.gpuCost << ", \"restructured_sah\": " << r.restructuredCost
          << ", \"cpu_binned_sah\": " << r.cpuCost << ", \"ratio\": " << r.ratio()
          << ", \"stored_quantised_ratio\": " << r.storedRatio()
          << ", \"restructured_ratio\": " << r.restructuredRatio()
          << "}" << (i + 1 < rows.size() ? "," : "") << "\n";
    }
    out << "  ],\n  \"worst_ratio\": " << worst << "\n}\n";
    writeTextFile(json, out.str());
  }
  return 0;
}

}  // namespace snell::cli
