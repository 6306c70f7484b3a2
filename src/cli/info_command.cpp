// `snell info`: the device table (--devices), or what a scene file holds.
#include "cli/cli.h"

#include "render/scene_gpu.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/scene_summary.h"
#include "vk/context.h"

#include <chrono>
#include <cstdio>
#include <memory>

namespace snell::cli {

namespace {

constexpr const char* kHelp = R"(usage: snell info --devices
       snell info SCENE.gltf|SCENE.glb [--scene NAME|INDEX] [--ignore-extension EXT]...
                  [--texture-budget MIB] [--timings]

  --devices             list Vulkan devices, the one snell picks, and why
  SCENE                 shapes, triangles, refractive materials with their IOR,
                        textures and their memory with mips, lights, cameras,
                        animations, and the GPU memory a frame needs
  --scene S             use this glTF scene instead of the file's default
  --ignore-extension E  load a file that requires extension E anyway, without it
  --texture-budget MIB  textures (with mips) beyond MIB MiB load at a lower mip level
  --timings             also upload the scene to the GPU and print where loading
                        spent its time: parse, image decode (all cores), upload
)";

int devices() {
  vk::DeviceReport report = vk::surveyDevices();
  std::printf("Vulkan devices%s:\n%s", report.override.empty() ? "" : (" (SNELL_DEVICE=" + report.override + ")").c_str(),
              report.table().c_str());
  if (!report.choice.chosen) {
    std::fprintf(stderr, "snell: error: no device meets snell's requirements (see the reasons above)\n");
    return 1;
  }
  std::printf("snell uses [%u] %s\n", report.devices[*report.choice.chosen].index,
              report.devices[*report.choice.chosen].name.c_str());
  return 0;
}

}  // namespace

int runInfo(const Args& args) {
  if (args.empty()) throw UsageError{"info needs --devices or a scene file"};
  if (args[0] == "--help" || args[0] == "-h") {
    std::fputs(kHelp, stdout);
    return 0;
  }
  if (args[0] == "--devices") {
    if (args.size() != 1) throw UsageError{"info --devices takes no other arguments"};
    return devices();
  }
  std::string path;
  scene::LoadOptions options;
  bool timings = false;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--scene" || a == "--ignore-extension" || a == "--texture-budget") {
      if (i + 1 >= args.size()) throw UsageError{"info: " + a + " needs a value"};
      if (a == "--scene") options.scene = args[++i];
      else if (a == "--ignore-extension") options.ignoredExtensions.push_back(args[++i]);
      else options.textureBudget = parseTextureBudget(a, args[++i]);
    } else if (a == "--timings") {
      timings = true;
    } else if (!a.empty() && a[0] == '-') {
      throw UsageError{"info: unknown option " + a};
    } else if (path.empty()) {
      path = a;
    } else {
      throw UsageError{"info takes one scene file"};
    }
  }
  if (path.empty()) throw UsageError{"info: no scene file given"};
  scene::Scene scene = scene::loadGltf(path, options);
  std::fputs(scene::describe(scene).c_str(), stdout);
  if (timings) {
    const scene::Scene::LoadTimes& t = scene.loadTimes;
    std::unique_ptr<vk::Context> context = vk::Context::create(contextDescFromEnvironment());
    scene::Pose pose = scene::evaluate(scene, 0.0);
    auto start = std::chrono::steady_clock::now();
    render::SceneGpu gpu = render::uploadScene(*context, scene, pose);
    double upload = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("  load times: parse %.1f ms, image decode %.1f ms (%u threads), upload %.1f ms "
                "(textures %.1f ms: %s with mips through a %llu MiB staging ring) on %s\n",
                t.parseSeconds * 1e3, t.decodeSeconds * 1e3, t.decodeThreads, upload * 1e3,
                gpu.textureUploadSeconds * 1e3, scene::mebibytes(gpu.textureBytes).c_str(),
                static_cast<unsigned long long>(render::kTextureStagingRingBytes >> 20), context->facts().name.c_str());
  }
  return 0;
}

}  // namespace snell::cli
