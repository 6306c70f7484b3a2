// Command-line conventions shared by `snell` and `snell-view` (options.h).
#include "cli/options.h"

#include "io/environment.h"
#include "render/renderer.h"
#include "scene/procedural_eye.h"
#include "scene/scene_summary.h"
#include "vk/error.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <map>
#include <sstream>

#include <fcntl.h>
#include <unistd.h>

namespace snell::cli {

const char* const kHelpFooter = R"(exit codes: 0 done, 1 failed (the message says what), 2 bad command line,
  3 the GPU was lost (retry on another machine), 128+N stopped by signal N
  (SIGTERM: 143; the frames written are whole, the one under way is dropped)

environment:
  SNELL_DEVICE=INDEX|UUID|NAME  the device to use (as --device; 'snell info
                           --devices' lists them)
  CUDA_VISIBLE_DEVICES, GPU_DEVICE_ORDINAL, SLURM_STEP_GPUS, SLURM_JOB_GPUS
                           without SNELL_DEVICE: the GPU a launcher (Slurm, a
                           CUDA job) gave this task, by index in PCI bus order
                           (nvidia-smi's) or GPU-UUID, the first one set
  SLURM_CPUS_PER_TASK=N    lavapipe renders on N threads (unless LP_NUM_THREADS)
  SNELL_VALIDATION=1       turn on the Khronos validation layer; any message it
                           reports makes the exit code 1
  SNELL_PIPELINE_CACHE=DIR where compiled pipelines are kept for the next run
                           (default $XDG_CACHE_HOME/snell, else ~/.cache/snell; off: none)
  SNELL_GPU_TIMEOUT=SECONDS how long a submission may run before the device is
                           reported as hung (default 60 on a GPU, 600 on a CPU
                           device such as lavapipe))";

namespace {

bool quietFlag = false;
std::FILE* askedForOutput = nullptr;  // the real standard output, kept when --quiet hides it

std::string programName(const CLI::App& app) {
  const CLI::App* root = &app;
  while (root->get_parent()) root = root->get_parent();
  return root->get_name();
}

// The deepest subcommand the parse reached ("snell bench frame"), for the hint.
std::string reachedCommand(CLI::App& app) {
  std::string path = app.get_name();
  CLI::App* at = &app;
  while (!at->get_subcommands().empty()) {
    at = at->get_subcommands().front();
    path += " " + at->get_name();
  }
  return path;
}

// The long descriptions, by command: CLI11 keeps one description, which its
// parent's list prints whole.
std::map<const CLI::App*, std::string>& longDescriptions() {
  static std::map<const CLI::App*, std::string> texts;
  return texts;
}

class SnellHelpFormat : public CLI::Formatter {
 public:
  std::string make_description(const CLI::App* app) const override {
    auto text = longDescriptions().find(app);
    if (text == longDescriptions().end()) return CLI::Formatter::make_description(app);
    return app->get_description() + "\n\n" + text->second + "\n\n";
  }
};

}  // namespace

void describe(CLI::App& command, std::string text) { longDescriptions()[&command] = std::move(text); }

void useSnellHelpFormat(CLI::App& app) {
  auto format = std::make_shared<SnellHelpFormat>();
  format->column_width(34);
  app.formatter(format);
}

bool quiet() { return quietFlag; }

std::FILE* askedOutput() { return askedForOutput ? askedForOutput : stdout; }

void note(const std::string& text) {
  if (!quietFlag) std::fprintf(stderr, "snell: note: %s\n", text.c_str());
}

void addGlobalOptions(CLI::App& app) {
  app.add_option_function<std::string>(
         "--device",
         [](const std::string& device) {
           if (device.empty()) throw UsageError{"--device needs an index, a UUID or part of a name"};
           ::setenv("SNELL_DEVICE", device.c_str(), 1);
         },
         "the device to use: an index or UUID from 'snell info --devices', or\npart of its name (the same as SNELL_DEVICE)")
      ->type_name("INDEX|UUID|NAME");
  app.add_flag_callback(
      "-q,--quiet",
      [] {
        quietFlag = true;
        // Nothing on standard output: every "wrote ..." line and table goes;
        // errors, on standard error, stay.
        std::fflush(stdout);
        if (!askedForOutput) askedForOutput = ::fdopen(::dup(STDOUT_FILENO), "w");
        int null = ::open("/dev/null", O_WRONLY);
        if (null >= 0) {
          ::dup2(null, STDOUT_FILENO);
          ::close(null);
        }
      },
      "print nothing but errors: no results on standard output, no progress, no notes");
}

void parseOnly(CLI::App& app, const Args& args) {
  try {
    app.parse(Args(args.rbegin(), args.rend()));  // CLI11 takes the words last first
  } catch (const CLI::Success&) {
  } catch (const CLI::ParseError& e) {
    throw UsageError{e.what()};
  }
}

int runCommandLine(CLI::App& app, int argc, char** argv, const Runner& run) {
  const std::string program = programName(app);
  auto usage = [&](const std::string& message) {
    std::string command = reachedCommand(app);
    std::fprintf(stderr, "%s: %s\nRun '%s --help' for usage.\n", program.c_str(), message.c_str(), command.c_str());
    return kExitUsage;
  };
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help or --version: printed, exit 0
  } catch (const CLI::ParseError& e) {
    return usage(e.what());
  } catch (const UsageError& e) {
    return usage(e.message);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", program.c_str(), e.what());
    return kExitFailure;
  }
  if (!run) return usage("give a command");
  io::keepToTheTasksCpus();
  try {
    return run();
  } catch (const UsageError& e) {
    return usage(e.message);
  } catch (const vk::VulkanError& e) {
    std::fprintf(stderr, "%s: error: %s\n", program.c_str(), e.what());
    return e.result() == VK_ERROR_DEVICE_LOST ? kExitDeviceLost : kExitFailure;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", program.c_str(), e.what());
    return kExitFailure;
  }
}

namespace {

unsigned long long parseCount(const std::string& option, const std::string& value) {
  unsigned long long result = 0;
  auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), result);
  if (value.empty() || error != std::errc() || end != value.data() + value.size()) {
    throw UsageError{option + " expects a whole number, got '" + value + "'"};
  }
  return result;
}

}  // namespace

void parseSize(const std::string& option, const std::string& value, uint32_t& width, uint32_t& height) {
  size_t x = value.find('x');
  if (x == std::string::npos) throw UsageError{option + " expects WxH, e.g. 640x480, got '" + value + "'"};
  unsigned long long w = parseCount(option, value.substr(0, x)), h = parseCount(option, value.substr(x + 1));
  if (w == 0 || h == 0 || w > 65536 || h > 65536) {
    throw UsageError{option + " " + value + " is out of range (1x1 to 65536x65536)"};
  }
  width = uint32_t(w);
  height = uint32_t(h);
}

std::vector<double> parseNumbers(const std::string& option, const std::string& value, size_t count) {
  std::vector<double> numbers;
  std::stringstream in(value);
  std::string part;
  while (std::getline(in, part, ',')) {
    char* end = nullptr;
    double v = std::strtod(part.c_str(), &end);
    if (part.empty() || *end != '\0' || !std::isfinite(v)) break;
    numbers.push_back(v);
  }
  if (numbers.size() != count || std::count(value.begin(), value.end(), ',') != long(count - 1)) {
    throw UsageError{option + " expects " + std::to_string(count) + " comma-separated numbers, got '" + value + "'"};
  }
  return numbers;
}

const CLI::Validator& finite() {
  static const CLI::Validator validator(
      [](std::string& value) -> std::string {
        char* end = nullptr;
        double v = std::strtod(value.c_str(), &end);
        return value.empty() || *end != '\0' || !std::isfinite(v) ? "expects a finite number, got '" + value + "'" : "";
      },
      "NUMBER");
  return validator;
}

const CLI::Validator& positiveCount() {
  static const CLI::Validator validator = CLI::Range(1u, std::numeric_limits<uint32_t>::max(), "POSITIVE");
  return validator;
}

void addEyeOptions(CLI::App& app, scene::EyeOptions& eye) {
  app.add_option("--eye-resolution", eye.resolution, "segments of the procedural eye, 8-2048 (default 64)")
      ->type_name("N")
      ->check(CLI::Range(8u, 2048u));
  app.add_option("--crowd", eye.crowd, "N characters' eye pairs instead of one eye (at most 10000)")
      ->type_name("N")
      ->check(CLI::Range(0u, 10000u));
}

void addBenchScene(CLI::App& app, std::string& file, uint32_t& width, uint32_t& height, const std::string& defaultSize) {
  app.add_option("scene", file, "the glTF file instead of the procedural eye")->type_name("SCENE.glb");
  addSize(app, "--size", width, height, "image size (default " + defaultSize + ")");
}

CLI::Option* addSize(CLI::App& app, const std::string& name, uint32_t& width, uint32_t& height,
                     const std::string& description) {
  std::string option = name.substr(name.rfind(',') == std::string::npos ? 0 : name.rfind(',') + 1);
  return app
      .add_option_function<std::string>(
          name, [&width, &height, option](const std::string& v) { parseSize(option, v, width, height); }, description)
      ->type_name("WxH");
}

CLI::Option* addTextureBudget(CLI::App& app, uint64_t& bytes) {
  return app
      .add_option_function<uint64_t>(
          "--texture-budget", [&bytes](uint64_t mib) { bytes = mib << 20; },
          "textures (with their mips) beyond MIB MiB load at a lower mip level")
      ->type_name("MIB")
      ->check(CLI::Range(uint64_t(1), uint64_t(1) << 20));
}

CLI::Option* addOffsetStrength(CLI::App& app, float& strength) {
  char text[96];
  std::snprintf(text, sizeof text, "normal-offset's displacement in image heights (%g)", double(strength));
  return app.add_option("--offset-strength", strength, text)->type_name("S")->check(CLI::Range(-10.0f, 10.0f));
}

void ShotOptions::addTo(CLI::App& app) {
  app.add_option("scene", input, "the glTF file (.gltf or .glb)")->type_name("SCENE");
  app.add_flag("--eye", eye, "the procedural eye instead of a file");
  addSize(app, "--size", width, height, "image size in pixels (default " + std::to_string(width) + "x" +
                                            std::to_string(height) + ")");
  app.add_option("--camera", view.camera,
                 "the scene's glTF camera N (default: camera 0, or a view\nframing the whole scene when it has none)")
      ->type_name("N")
      ->check(CLI::Range(0, 1 << 20));
  app.add_option_function<std::string>(
         "--look-at",
         [this](const std::string& v) {
           std::vector<double> n = parseNumbers("--look-at", v, 6);
           view.lookAt = scene::LookAt{{n[0], n[1], n[2]}, {n[3], n[4], n[5]}, {0.0, 1.0, 0.0}};
         },
         "camera at E looking at T, +Y up (overrides --camera)")
      ->type_name("EX,EY,EZ,TX,TY,TZ");
  app.add_option_function<double>(
         "--fov", [this](double degrees) { view.yfov = degrees * 3.14159265358979 / 180.0; },
         "vertical field of view in degrees for --look-at and framed views (40)")
      ->type_name("DEGREES")
      ->check(CLI::Range(0.001, 179.999));
  timeOption = app.add_option("--time", time, "seconds into the animation (default 0)")->type_name("T")->check(finite());
  app.add_option("--max-interfaces", maxInterfaces, "refractive faces a ray may cross (default 8, at most 1024)")
      ->type_name("N")
      ->check(CLI::Range(0u, 1024u));
  app.add_option_function<std::string>(
         "--background",
         [this](const std::string& v) {
           std::vector<double> n = parseNumbers("--background", v, 3);
           background = glm::vec3(glm::dvec3(n[0], n[1], n[2]));
         },
         "linear colour of misses (default 0.02,0.02,0.025)")
      ->type_name("R,G,B");
  app.add_option("--scene", load.scene, "which glTF scene of the file")->type_name("NAME|INDEX");
  app.add_option("--ignore-extension", load.ignoredExtensions, "load a file that requires extension E anyway")
      ->type_name("E")
      ->allow_extra_args(false)  // one extension per --ignore-extension: the scene file after it stays the scene
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  addTextureBudget(app, load.textureBudget);
  app.add_flag("--strict", strict,
               "a scene with nothing to draw is an error (default: a note, and the background is drawn)");
}

void ShotOptions::require(const std::string& command) const {
  if (input.empty() && !eye) throw UsageError{command + ": give a scene file (or --eye)"};
  if (!input.empty() && eye) throw UsageError{command + ": give a scene file or --eye, not both"};
}

scene::Scene ShotOptions::loadScene() const {
  scene::Scene scene = eye ? scene::makeEye() : scene::loadGltf(input, load);
  if (eye) scene.source = "procedural eye";
  for (const std::string& w : scene.warnings) note(w);
  if (scene::summarize(scene).triangles == 0) {
    // As snell-usd: an empty scene (a layout file, a glTF of cameras) draws its background.
    std::string what = scene.source + ": nothing to draw: no mesh with triangles";
    if (strict) throw scene::SceneError(what + " (--strict)");
    note(what + "; the background is drawn");
  }
  return scene;
}

scene::View ShotOptions::resolveView(const std::string& command, const scene::Scene& scene,
                                     const scene::Pose& pose) const {
  try {
    return scene::resolveView(scene, pose, view);
  } catch (const std::invalid_argument& e) {
    throw UsageError{command + ": " + e.what()};
  }
}

std::unique_ptr<vk::Context> ShotOptions::openContext(const std::string& command) const {
  std::unique_ptr<vk::Context> context = vk::Context::create(io::contextDescFromEnvironment());
  try {
    render::checkImageSize(*context, width, height);
  } catch (const std::invalid_argument& e) {
    throw UsageError{command + ": " + e.what()};
  }
  return context;
}

int validationExitCode(const vk::Context& context) {
  if (context.validationMessageCount() == 0) return kExitOk;
  std::fprintf(stderr, "snell: the validation layer reported %llu message(s)\n",
               static_cast<unsigned long long>(context.validationMessageCount()));
  return kExitFailure;
}

}  // namespace snell::cli
