// `snell info`: the device table (--devices), or what a scene file holds; as
// text, and as JSON with --json.
#include "cli/commands.h"

#include "io/environment.h"
#include "io/image_file.h"
#include "io/json.h"
#include "render/method.h"
#include "render/renderer.h"
#include "render/scene_gpu.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/scene_summary.h"
#include "scene/texture_mips.h"
#include "scene/view.h"
#include "vk/context.h"
#include "vk/error.h"

#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>

namespace snell::cli {

namespace {

struct Options {
  bool devices = false;
  std::string input;
  scene::LoadOptions load;
  bool timings = false;
  std::string json;  ///< empty: none; "-": the JSON on standard output instead of the text
};

// Where --json goes: standard output for "-", else a file written whole.
void writeReport(const std::string& where, const io::Json& json) {
  if (where == "-") {
    std::fputs(io::jsonText(json).c_str(), askedOutput());
    std::fflush(askedOutput());
  } else {
    io::writeJson(where, json);
  }
}

// A float as the shortest decimal that reads back as it: an IOR of 1.376f
// goes in the JSON as 1.376, not as its double 1.3760000467300415.
double decimal(float value) {
  char text[32];
  char* end = std::to_chars(text, text + sizeof text, value).ptr;
  *end = '\0';
  return std::strtod(text, nullptr);
}

io::Json deviceEntry(const vk::DeviceReport& report, size_t i) {
  const vk::DeviceFacts& d = report.devices[i];
  io::Json entry = io::deviceJson(d);
  entry["type"] = vk::deviceTypeName(d.type);
  entry["min_subgroup_size"] = d.minSubgroupSize;
  entry["max_subgroup_size"] = d.maxSubgroupSize;
  entry["unmet"] = vk::unmetFor(d);
  entry["chosen"] = report.choice.chosen == i;
  entry["verdict"] = report.choice.verdicts[i];
  return entry;
}

int listDevices(const Options& o) {
  if (!o.json.empty() && o.json != "-") io::checkWritable(o.json);
  bool text = o.json != "-";
  vk::DeviceReport report = vk::surveyDevices("", io::deviceEnvironment());
  const std::optional<uint32_t>& chosen = report.choice.chosen;
  if (text) {
    std::printf("Vulkan devices (%s):\n%s", report.why.c_str(), report.table().c_str());
  }
  if (!o.json.empty()) {
    io::Json j = io::reportHead("info", chosen ? &report.devices[*chosen] : nullptr);
    j["override"] = report.override.empty() ? io::Json() : io::Json(report.override);
    j["override_from"] = report.why;
    j["devices"] = io::Json::array();
    for (size_t i = 0; i < report.devices.size(); ++i) j["devices"].push_back(deviceEntry(report, i));
    j["chosen"] = chosen ? io::Json(report.devices[*chosen].index) : io::Json();
    writeReport(o.json, j);
  }
  if (!chosen) {
    std::fprintf(stderr, "snell: error: no device meets snell's requirements (see the reasons above)\n");
    return kExitFailure;
  }
  if (text) std::printf("snell uses [%u] %s\n", report.devices[*chosen].index, report.devices[*chosen].name.c_str());
  return kExitOk;
}

// What describe() prints, as numbers and names.
void addScene(io::Json& j, const scene::Scene& scene) {
  scene::SceneSummary s = scene::summarize(scene);
  j["source"] = scene.source;
  j["nodes"] = s.nodes;
  j["nodes_in_file"] = scene.nodes.size();
  j["shapes"] = s.shapes;
  j["instances"] = s.instances;
  j["triangles"] = s.triangles;
  j["vertices"] = s.vertices;
  j["morphed_shapes"] = s.morphedShapes;
  j["skinned_shapes"] = s.skinnedShapes;
  j["skins"] = scene.skins.size();

  std::vector<bool> drawn = scene::drawnTextures(scene);
  io::Json textures = io::Json::array();
  uint64_t decoded = 0;
  for (size_t t = 0; t < scene.textures.size(); ++t) {
    const scene::Texture& texture = scene.textures[t];
    decoded += texture.rgba.size();
    textures.push_back({{"index", t},
                        {"name", texture.name},
                        {"width", texture.width},
                        {"height", texture.height},
                        {"uploaded", bool(drawn[t])}});
  }
  j["textures"] = textures;
  j["texture_decoded_bytes"] = decoded;

  io::Json materials = io::Json::array();
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const scene::Material& material = scene.materials[m];
    auto texture = [](const scene::TextureRef& ref) { return ref.present() ? io::Json(ref.texture) : io::Json(); };
    const glm::vec3& colour = material.attenuationColor;
    // JSON has no infinity: null is "no attenuation", as glTF's default.
    io::Json distance = material.attenuates() ? io::Json(decimal(material.attenuationDistance)) : io::Json();
    materials.push_back({{"index", m},
                         {"name", material.name},
                         {"refractive", material.refractive()},
                         {"transmission", decimal(material.transmission)},
                         {"ior", decimal(material.ior)},
                         {"thickness", decimal(material.thickness)},
                         {"attenuation_color", {decimal(colour.r), decimal(colour.g), decimal(colour.b)}},
                         {"attenuation_distance", distance},
                         {"dispersion", decimal(material.dispersion)},
                         {"roughness", decimal(material.roughness)},
                         {"priority", material.priority},
                         {"base_color_texture", texture(material.baseColorTexture)},
                         {"ior_texture", texture(material.iorTexture)}});
  }
  j["refractive_materials"] = s.refractiveMaterials;
  j["materials"] = materials;

  const char* lightTypes[] = {"directional", "point", "spot"};
  io::Json lights = io::Json::array();
  for (const scene::Light& light : scene.lights) {
    lights.push_back(
        {{"name", light.name}, {"type", lightTypes[int(light.type)]}, {"intensity", decimal(light.intensity)}});
  }
  j["lights"] = lights;

  io::Json cameras = io::Json::array();
  for (const scene::Camera& camera : scene.cameras) {
    io::Json entry{{"name", camera.name}, {"type", camera.orthographic ? "orthographic" : "perspective"}};
    if (!camera.orthographic) entry["yfov"] = decimal(camera.yfov);
    cameras.push_back(entry);
  }
  j["cameras"] = cameras;

  io::Json animations = io::Json::array();
  for (const scene::Animation& a : scene.animations) {
    animations.push_back(
        {{"name", a.name}, {"duration_seconds", decimal(a.duration)}, {"channels", a.channels.size()}});
  }
  j["animations"] = animations;

  // summarize()'s defaults, the size describe() estimates at.
  j["gpu_memory_per_frame"] = {{"width", 1920},
                               {"height", 1080},
                               {"geometry_bytes", s.geometryBytes},
                               {"deformation_bytes", s.deformBytes},
                               {"bvh_bytes", s.bvhBytes},
                               {"texture_bytes", s.textureBytes},
                               {"image_bytes", s.imageBytes},
                               {"total_bytes", s.totalBytes()}};
  j["notes"] = scene.warnings;
}

// The device snell would run on, for the JSON's head; none when none qualifies.
std::optional<vk::DeviceFacts> deviceSnellPicks() {
  try {
    vk::DeviceReport report = vk::surveyDevices("", io::deviceEnvironment());
    if (report.choice.chosen) return report.devices[*report.choice.chosen];
  } catch (const vk::VulkanError&) {
    // No Vulkan here at all: the scene's facts need no GPU, so the head goes without one.
  }
  return std::nullopt;
}

int describeScene(const Options& o) {
  if (!o.json.empty() && o.json != "-") io::checkWritable(o.json);
  bool text = o.json != "-";
  scene::Scene scene = scene::loadGltf(o.input, o.load);
  if (text) std::fputs(scene::describe(scene).c_str(), stdout);
  int exitCode = kExitOk;
  std::optional<vk::DeviceFacts> device;
  io::Json loadTimes;
  if (o.timings) {
    const scene::Scene::LoadTimes& t = scene.loadTimes;
    auto start = std::chrono::steady_clock::now();
    std::unique_ptr<vk::Context> context = vk::Context::create(io::contextDescFromEnvironment());
    double deviceSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    scene::Pose pose = scene::evaluate(scene, 0.0);
    start = std::chrono::steady_clock::now();
    render::SceneGpu gpu = render::uploadScene(*context, scene, pose);
    double upload = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (text) {
      std::printf("  load times: parse %.1f ms, image decode %.1f ms (%u threads), Vulkan instance and device "
                  "%.1f ms, upload %.1f ms (textures %.1f ms: %s with mips through a %llu MiB staging ring) on %s\n",
                  t.parseSeconds * 1e3, t.decodeSeconds * 1e3, t.decodeThreads, deviceSeconds * 1e3, upload * 1e3,
                  gpu.textureUploadSeconds * 1e3, scene::mebibytes(gpu.textureBytes).c_str(),
                  static_cast<unsigned long long>(render::kTextureStagingRingBytes >> 20),
                  context->facts().name.c_str());
    }
    loadTimes = {{"parse_ms", t.parseSeconds * 1e3},
                 {"device_ms", deviceSeconds * 1e3},
                 {"decode_ms", t.decodeSeconds * 1e3},
                 {"decode_threads", t.decodeThreads},
                 {"upload_ms", upload * 1e3},
                 {"texture_upload_ms", gpu.textureUploadSeconds * 1e3},
                 {"texture_bytes", gpu.textureBytes},
                 {"staging_ring_bytes", render::kTextureStagingRingBytes}};
    // The pipelines a first frame of this scene compiles: a trace and a viewport, small.
    start = std::chrono::steady_clock::now();
    double compileBefore = context->compileSeconds();
    uint64_t pipelinesBefore = context->pipelinesCreated();
    {
      render::Renderer renderer(*context, scene, pose);
      render::FrameSettings settings;
      settings.width = settings.height = 64;
      settings.view = scene::resolveView(scene, pose, {});
      render::FrameRequest frame;
      frame.pose = &pose;
      frame.views = {render::methodView(render::Method::Trace, settings, {}),
                     render::methodView(render::Method::Masked, settings, {})};
      renderer.wait(renderer.submit(frame));
    }
    double firstFrame = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    double compile = context->compileSeconds() - compileBefore;
    uint64_t pipelines = context->pipelinesCreated() - pipelinesBefore;
    const vk::PipelineCache* cache = context->diskCache();
    std::string cacheLine = !cache || cache->path().empty() ? std::string("off (SNELL_PIPELINE_CACHE=off)")
                            : cache->loadedBytes() ? cache->path().string() + ", " + std::to_string(cache->loadedBytes() >> 10) + " KiB loaded"
                                                   : cache->path().string() + ", empty";
    if (text) {
      std::printf("  first frame: %.1f ms, of which %.1f ms compiling %llu pipelines (pipeline cache: %s)\n",
                  firstFrame * 1e3, compile * 1e3, static_cast<unsigned long long>(pipelines), cacheLine.c_str());
    }
    loadTimes["first_frame_ms"] = firstFrame * 1e3;
    loadTimes["compile_ms"] = compile * 1e3;
    loadTimes["pipelines_compiled"] = pipelines;
    loadTimes["pipeline_cache"] = cache && !cache->path().empty() ? io::Json(cache->path().string()) : io::Json();
    loadTimes["pipeline_cache_loaded_bytes"] = cache ? cache->loadedBytes() : 0;
    device = context->facts();
    exitCode = validationExitCode(*context);
  } else if (!o.json.empty()) {
    device = deviceSnellPicks();
  }
  if (!o.json.empty()) {
    io::Json j = io::reportHead("info", device ? &*device : nullptr);
    addScene(j, scene);
    if (o.timings) j["load_times"] = loadTimes;
    writeReport(o.json, j);
  }
  return exitCode;
}

}  // namespace

void addInfo(CLI::App& parent, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* sub = parent.add_subcommand("info", "the Vulkan devices (--devices), or what a glTF file holds");
  describe(*sub,
      "snell info --devices lists the Vulkan devices, the one snell picks, and why.\n"
      "snell info SCENE describes a glTF file: shapes, triangles, refractive materials\n"
      "with their IOR, textures and their memory with mips, lights, cameras,\n"
      "animations, and the GPU memory a frame needs.");
  sub->footer(kHelpFooter);
  CLI::Option* devices = sub->add_flag("--devices", o->devices, "list Vulkan devices, the one snell picks, and why");
  CLI::Option* input = sub->add_option("scene", o->input, "the glTF file (.gltf or .glb)")->type_name("SCENE");
  CLI::Option* which = sub->add_option("--scene", o->load.scene, "use this glTF scene instead of the file's default")
                           ->type_name("NAME|INDEX");
  // One value per --ignore-extension, so that a scene file after it stays the scene.
  CLI::Option* ignore = sub->add_option("--ignore-extension", o->load.ignoredExtensions,
                                        "load a file that requires extension E anyway, without it")
                            ->type_name("E")
                            ->allow_extra_args(false);
  CLI::Option* budget = addTextureBudget(*sub, o->load.textureBudget);
  CLI::Option* timings = sub->add_flag("--timings", o->timings,
                                       "also upload the scene to the GPU and print where loading\n"
                                       "spent its time: parse, image decode (all cores), upload,\n"
                                       "and a first frame's pipeline compile (with the pipeline cache)");
  sub->add_option("--json", o->json,
                  "also write the report as JSON; '-': the JSON on standard\noutput instead of the text")
      ->type_name("FILE");
  for (CLI::Option* sceneOnly : {input, which, ignore, budget, timings}) devices->excludes(sceneOnly);
  sub->callback([o, &run] {
    if (!o->devices && o->input.empty()) throw UsageError{"info needs --devices or a scene file"};
    run = [o] { return o->devices ? listDevices(*o) : describeScene(*o); };
  });
}

}  // namespace snell::cli
