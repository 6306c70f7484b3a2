// Command-line conventions shared by `snell` and `snell-view` (CLI11): the
// options whose values snell parses itself (so every error names its option),
// the scene-and-view options of render, bake and export-web, and the one place
// a command line becomes an exit code: 0 ok, 1 failure, 2 bad usage.
#pragma once

#include "scene/gltf_loader.h"
#include "scene/procedural_eye.h"
#include "scene/scene.h"
#include "scene/view.h"
#include "shared/trace.h"
#include "vk/context.h"

#include <CLI/CLI.hpp>
#include <glm/glm.hpp>

#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace snell::cli {

/// The words of a command line after the program's name.
using Args = std::vector<std::string>;

/// A bad command line found after parsing (two options that cannot go
/// together, a camera the scene lacks): exit 2, with the subcommand's help hinted.
struct UsageError {
  std::string message;
};

/// Runs `body`, turning a caller's mistake a lower layer found
/// (std::invalid_argument: a frame list, a file pattern) into a UsageError.
template <typename Body>
auto usageErrors(Body&& body) -> decltype(body()) {
  try {
    return body();
  } catch (const std::invalid_argument& e) {
    throw UsageError{e.what()};
  }
}

/// What runs a subcommand once its whole command line has parsed.
using Runner = std::function<int()>;

/// Exit codes, as the README and every --help list them: done; failed;
/// bad command line; the GPU was lost (VK_ERROR_DEVICE_LOST: a farm can
/// retry the work on another node). A command stopped by SIGTERM or SIGINT
/// exits 128 + the signal.
inline constexpr int kExitOk = 0, kExitFailure = 1, kExitUsage = 2, kExitDeviceLost = 3;

/// The footer every --help ends with: exit codes and environment.
extern const char* const kHelpFooter;

/// A subcommand's long description, printed at the top of its own --help; the
/// short one given to add_subcommand is what its parent's --help lists.
void describe(CLI::App& command, std::string text);
/// The help layout of snell's commands (describe's texts, wider option
/// columns); subcommands made after it is set inherit it.
void useSnellHelpFormat(CLI::App& app);

/// Parses `args` into `app` and runs what it chose; prints the error (naming the
/// option, and pointing to the failing subcommand's --help) and returns the exit
/// code. `run` is what the parse set; UsageError and CLI11's errors exit 2,
/// anything else thrown exits 1 with "PROGRAM: error: ...".
int runCommandLine(CLI::App& app, int argc, char** argv, const Runner& run);
/// Parses `args` without running anything: bad usage throws UsageError (the CLI fuzz target).
void parseOnly(CLI::App& app, const Args& args);

/// The global options of every command: --device INDEX|NAME (sets
/// SNELL_DEVICE for this process) and -q/--quiet (nothing on standard output,
/// no progress and no notes; errors still go to standard error).
void addGlobalOptions(CLI::App& app);
/// Whether --quiet was given.
bool quiet();
/// Standard output as it was before --quiet hid it: for output the command line
/// asked for by name (`--json -`), which --quiet does not silence.
std::FILE* askedOutput();
/// Prints a note to standard error unless --quiet ("PROGRAM: note: TEXT").
void note(const std::string& text);

/// A check for number options: finite (CLI11 would take "nan" and "inf").
const CLI::Validator& finite();
/// A check for counts of frames or runs: 1 or more.
const CLI::Validator& positiveCount();

/// Options whose values are parsed here, with errors naming the option.
CLI::Option* addSize(CLI::App& app, const std::string& name, uint32_t& width, uint32_t& height, const std::string& description);
/// The procedural eye's --eye-resolution and --crowd, in its own limits (scene::checkEyeOptions).
void addEyeOptions(CLI::App& app, scene::EyeOptions& eye);
/// A benchmark's SCENE (a glTF file instead of the procedural eye) and its
/// --size, `defaultSize` ("1920x1080") said in the help.
void addBenchScene(CLI::App& app, std::string& file, uint32_t& width, uint32_t& height, const std::string& defaultSize);
CLI::Option* addTextureBudget(CLI::App& app, uint64_t& bytes);
/// --offset-strength S (-10 to 10): normal-offset's displacement, its default the one `strength` holds.
CLI::Option* addOffsetStrength(CLI::App& app, float& strength);

/// Parses WxH (each 1..65536) or throws UsageError naming the option.
void parseSize(const std::string& option, const std::string& value, uint32_t& width, uint32_t& height);
/// `count` comma-separated finite numbers, or throws UsageError naming the option.
std::vector<double> parseNumbers(const std::string& option, const std::string& value, size_t count);

/// What scene, which view of it, at what size and time: the options that
/// render, bake and export-web share.
struct ShotOptions {
  std::string input;  ///< the glTF file
  bool eye = false;   ///< the procedural eye instead
  uint32_t width = 640, height = 480;
  scene::ViewRequest view;
  double time = 0.0;
  uint32_t maxInterfaces = gpu::kDefaultMaxInterfaces;
  glm::vec3 background{scene::kDefaultBackground};
  scene::LoadOptions load;
  /// A scene with nothing to draw (no triangles) is an error, not a note
  /// with the background drawn.
  bool strict = false;

  /// Adds SCENE, --eye, --size, --camera, --look-at, --fov, --time,
  /// --max-interfaces, --background, --scene, --ignore-extension,
  /// --texture-budget and --strict to `app`, writing into this (which must outlive the parse).
  void addTo(CLI::App& app);
  /// The --time option, for commands where it excludes others.
  CLI::Option* timeOption = nullptr;
  /// Throws UsageError unless exactly one of a file and --eye was given.
  void require(const std::string& command) const;
  /// The scene, its load notes printed to stderr; one with nothing to draw
  /// is a note (the background is drawn), or with --strict a SceneError.
  scene::Scene loadScene() const;
  /// The view asked for at `pose`; a view the scene cannot give is a UsageError.
  scene::View resolveView(const std::string& command, const scene::Scene& scene, const scene::Pose& pose) const;
  /// A context on the device snell picks (io::contextDescFromEnvironment), the
  /// image size checked against it (a UsageError when too large).
  std::unique_ptr<vk::Context> openContext(const std::string& command) const;
};

/// Exit code 1 with a message when the validation layer spoke, else 0.
int validationExitCode(const vk::Context& context);

}  // namespace snell::cli
