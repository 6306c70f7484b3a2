// `snell info`: the device table (--devices), or what a scene file holds.
#include "cli/cli.h"

#include "scene/gltf_loader.h"
#include "scene/scene_summary.h"
#include "vk/context.h"

#include <cstdio>

namespace snell::cli {

namespace {

constexpr const char* kHelp = R"(usage: snell info --devices
       snell info SCENE.gltf|SCENE.glb [--scene NAME|INDEX] [--ignore-extension EXT]...

  --devices             list Vulkan devices, the one snell picks, and why
  SCENE                 shapes, triangles, refractive materials with their IOR,
                        lights, cameras, animations, and the GPU memory a frame needs
  --scene S             use this glTF scene instead of the file's default
  --ignore-extension E  load a file that requires extension E anyway, without it
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
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--scene" || a == "--ignore-extension") {
      if (i + 1 >= args.size()) throw UsageError{"info: " + a + " needs a value"};
      if (a == "--scene") options.scene = args[++i];
      else options.ignoredExtensions.push_back(args[++i]);
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
  return 0;
}

}  // namespace snell::cli
