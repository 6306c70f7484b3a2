// The `snell` command's subcommands; main.cpp routes to them.
#pragma once

#include "scene/gltf_loader.h"
#include "scene/scene.h"
#include "scene/view.h"
#include "shared/trace.h"
#include "vk/context.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace snell::cli {

/// The words after the subcommand's name.
using Args = std::vector<std::string>;

/// This process's resident host memory in bytes (/proc/self/statm), for the
/// long runs' reports.
uint64_t hostResidentBytes();

/// Thrown for a bad command line; main prints it with the usage hint, exit 2.
struct UsageError {
  std::string message;
};

int runInfo(const Args& args);
int runBenchSort(const Args& args);
int runEye(const Args& args);
int runRender(const Args& args);
int runBenchBvh(const Args& args);
int runBenchFrame(const Args& args);
int runBenchStress(const Args& args);
int runBenchScale(const Args& args);
int runBenchMethods(const Args& args);
int runBake(const Args& args);
int runExportWeb(const Args& args);
/// Parse a subcommand's options as its run does, without running it: a bad
/// command line throws UsageError (the CLI fuzz target, tests/fuzz).
void parseRenderOptions(const Args& args);
void parseBakeOptions(const Args& args);
void parseExportWebOptions(const Args& args);

/// A context on the device snell picks; SNELL_VALIDATION=1 turns on the
/// validation layer, synchronization checks included.
vk::ContextDesc contextDescFromEnvironment();

/// Parses WxH (each 1..65536) or throws UsageError naming the option.
void parseSize(const std::string& option, const std::string& value, uint32_t& width, uint32_t& height);

/// Parses an unsigned integer option value or throws UsageError naming the option.
unsigned long long parseCount(const std::string& option, const std::string& value);

/// Parses a texture budget in MiB (1..2^20) into bytes, or throws UsageError naming the option.
uint64_t parseTextureBudget(const std::string& option, const std::string& value);

/// `count` comma-separated finite numbers, or throws UsageError naming the option.
std::vector<double> parseNumbers(const std::string& option, const std::string& value, size_t count);

/// What scene, which view of it, at what size and time: the options that
/// render, bake and export-web share (their --help texts list them).
struct ShotOptions {
  std::string input;  ///< the glTF file
  bool eye = false;   ///< the procedural eye instead
  uint32_t width = 640, height = 480;
  scene::ViewRequest view;
  double time = 0.0;
  uint32_t maxInterfaces = gpu::kDefaultMaxInterfaces;
  glm::vec3 background{0.02f, 0.02f, 0.025f};
  scene::LoadOptions load;

  /// Takes args[i] (a scene file, or an option and its value, advancing i)
  /// when it is one of these; false when it is not.
  bool take(const std::string& command, const Args& args, size_t& i);
  /// Throws UsageError unless exactly one of a file and --eye was given.
  void require(const std::string& command) const;
  /// The scene, its load notes printed to stderr.
  scene::Scene loadScene() const;
  /// The view asked for at `pose`; a view the scene cannot give is a UsageError.
  scene::View resolveView(const std::string& command, const scene::Scene& scene, const scene::Pose& pose) const;
  /// A context on the device snell picks (contextDescFromEnvironment), the
  /// image size checked against it (a UsageError when too large).
  std::unique_ptr<vk::Context> openContext(const std::string& command) const;
};

/// The material `wanted` names (its name or index) that has a base colour
/// texture, or a UsageError saying why there is none.
uint32_t findTexturedMaterial(const std::string& command, const scene::Scene& scene, const std::string& wanted);

/// Exit code 1 with a message when the validation layer spoke, else 0.
int validationExitCode(const vk::Context& context);

/// `text` with &, <, > and " escaped for XML, SVG and HTML.
std::string xmlEscape(const std::string& text);

/// The median of `values` (0 when empty), for benchmark tables.
double median(std::vector<double> values);

/// `text` as the inside of a JSON string.
std::string jsonEscape(const std::string& text);

}  // namespace snell::cli
