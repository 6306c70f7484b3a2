// `snell bench frame`: GPU time of each pass of a frame (deform, bottom-level
// build or refit, top level, trace) while the eye animates, medians over many frames.
#include "cli/cli.h"

#include "render/renderer.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "scene/scene_summary.h"
#include "scene/view.h"
#include "vk/commands.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>

namespace snell::cli {

namespace {

constexpr const char* kHelp = R"(usage: snell bench frame [SCENE.glb] [options]

Renders animated frames of the procedural eye (or SCENE) and reports each
pass's GPU time: the median, min and max over the measured frames. The first
frame builds the bottom level ("blas build"); later frames refit what deformed.

options:
  --size WxH        image size (default 1920x1080)
  --frames N        frames measured (default 30)
  --warmup N        frames rendered first and not measured (default 5)
  --eye-resolution N  segments of the procedural eye (default 64)
  --json FILE       write the results as JSON too
)";

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

}  // namespace

int runBenchFrame(const Args& args) {
  uint32_t width = 1920, height = 1080, frames = 30, warmup = 5, eyeResolution = 64;
  std::string json, file;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
    if (!a.empty() && a[0] != '-') {
      file = a;
      continue;
    }
    if (i + 1 >= args.size()) throw UsageError{"bench frame: " + a + " needs a value (or is unknown)"};
    const std::string& v = args[++i];
    if (a == "--size") {
      parseSize(a, v, width, height);
    } else if (a == "--frames") {
      frames = std::max<uint32_t>(1, uint32_t(parseCount(a, v)));
    } else if (a == "--warmup") {
      warmup = uint32_t(parseCount(a, v));
    } else if (a == "--eye-resolution") {
      eyeResolution = uint32_t(parseCount(a, v));
    } else if (a == "--json") {
      json = v;
    } else {
      throw UsageError{"bench frame: unknown option " + a};
    }
  }
  scene::EyeOptions eye;
  eye.resolution = eyeResolution;
  scene::Scene scene = file.empty() ? scene::makeEye(eye) : scene::loadGltf(file);
  std::string label = file.empty() ? "eye (resolution " + std::to_string(eyeResolution) + ")" : file;
  auto context = vk::Context::create(contextDescFromEnvironment());
  render::checkImageSize(*context, width, height);
  scene::SceneSummary summary = scene::summarize(scene);
  std::printf("device: %s\nscene: %s, %llu triangles, %ux%u\n", context->facts().name.c_str(), label.c_str(),
              static_cast<unsigned long long>(summary.triangles), width, height);

  double duration = std::max(scene::animationDuration(scene), 1e-3);
  scene::Pose layout = scene::evaluate(scene, 0.0);
  render::Renderer renderer(*context, scene, layout);
  vk::Image image(*context, {width, height, VK_FORMAT_R16G16B16A16_SFLOAT, VK_IMAGE_USAGE_STORAGE_BIT, "bench image"});
  vk::Commands commands(*context, "bench frame");
  std::map<std::string, std::vector<double>> times;
  std::vector<std::string> order;
  for (uint32_t f = 0; f < warmup + frames; ++f) {
    double t = std::fmod(double(f) / 24.0, duration);
    scene::Pose pose = scene::evaluate(scene, t);
    scene::View view = scene::resolveView(scene, pose, {});
    commands.begin();
    if (f == 0) commands.imageLayout(image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    renderer.record(commands, pose, {width, height, view, {0.02f, 0.02f, 0.025f}, gpu::kDefaultMaxInterfaces}, image);
    commands.submitAndWait();
    // The build happens once, on the first frame: report it even though it is warm-up.
    for (const vk::PassTime& p : commands.passTimes()) {
      if (f < warmup && p.name != "blas build") continue;
      if (!times.count(p.name)) order.push_back(p.name);
      times[p.name].push_back(p.milliseconds);
    }
  }

  std::printf("%-12s %10s %10s %10s %7s\n", "pass", "median ms", "min ms", "max ms", "frames");
  double total = 0;
  for (const std::string& name : order) {
    const std::vector<double>& v = times[name];
    double m = median(v);
    if (name != "blas build") total += m;
    std::printf("%-12s %10.4f %10.4f %10.4f %7zu\n", name.c_str(), m, *std::min_element(v.begin(), v.end()),
                *std::max_element(v.begin(), v.end()), v.size());
  }
  std::printf("%-12s %10.4f   (per animated frame: deform + refit + tlas + trace)\n", "frame", total);
  std::printf("GPU memory (geometry, BVHs, per-frame buffers): %.2f MiB; image %.2f MiB\n",
              double(renderer.memoryBytes()) / 1048576.0, double(width) * height * 8 / 1048576.0);
  if (!json.empty()) {
    std::ofstream out(json);
    out << "{\n  \"device\": \"" << context->facts().name << "\",\n  \"scene\": \"" << label << "\",\n  \"triangles\": "
        << summary.triangles << ",\n  \"width\": " << width << ",\n  \"height\": " << height
        << ",\n  \"memory_bytes\": " << renderer.memoryBytes() << ",\n  \"passes\": [\n";
    for (size_t i = 0; i < order.size(); ++i) {
      const std::vector<double>& v = times[order[i]];
      out << "    {\"pass\": \"" << order[i] << "\", \"median_ms\": " << median(v)
          << ", \"min_ms\": " << *std::min_element(v.begin(), v.end())
          << ", \"max_ms\": " << *std::max_element(v.begin(), v.end()) << ", \"frames\": " << v.size() << "}"
          << (i + 1 < order.size() ? "," : "") << "\n";
    }
    out << "  ],\n  \"frame_median_ms\": " << total << "\n}\n";
    if (!out) throw std::runtime_error(json + ": could not write");
  }
  return 0;
}

}  // namespace snell::cli
