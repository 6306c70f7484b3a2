// The `snell` command's subcommands, one file each; main.cpp puts them
// together. Each add function adds its subcommand's options to `parent` and,
// once the command line has parsed, sets `run` to what runs it.
#pragma once

#include "cli/options.h"
#include "io/environment.h"
#include "render/frame_settings.h"
#include "scene/evaluate.h"
#include "scene/view.h"

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace snell::cli {

void addInfo(CLI::App& parent, Runner& run);
void addEye(CLI::App& parent, Runner& run);
void addRender(CLI::App& parent, Runner& run);
void addBake(CLI::App& parent, Runner& run);
void addExportWeb(CLI::App& parent, Runner& run);
void addBenchSort(CLI::App& bench, Runner& run);
void addBenchBvh(CLI::App& bench, Runner& run);
void addBenchFrame(CLI::App& bench, Runner& run);
void addBenchCost(CLI::App& bench, Runner& run);
void addBenchStress(CLI::App& bench, Runner& run);
void addBenchScale(CLI::App& bench, Runner& run);
void addBenchMethods(CLI::App& bench, Runner& run);
void addBenchShot(CLI::App& bench, Runner& run);
void addBenchPipelines(CLI::App& bench, Runner& run);

/// What `snell render ARGS` would draw, found as it would find it: the
/// options parse and agree, the scene and environment load. Throws
/// UsageError (a bad command line) or an error naming the file otherwise.
struct RenderCheck {
  std::string scene;       ///< the loaded scene's source
  bool autoMethod = false; ///< --method auto, which chooses per run by timing
  std::string method;      ///< what it draws without auto ("trace", "masked", "reference", ...)
  bool bakeTimeGiven = false;
  double fps = 24.0;
};
RenderCheck checkRender(const Args& args);
void addFarm(CLI::App& parent, Runner& run);

/// The whole `snell` command line: every subcommand and the global options.
/// `run` is set by whichever subcommand the parse picks.
std::unique_ptr<CLI::App> makeSnellApp(Runner& run);

/// The material `wanted` names (its name or index) that has a base colour
/// texture, or a UsageError saying why there is none.
uint32_t findTexturedMaterial(const std::string& command, const scene::Scene& scene, const std::string& wanted);

/// What bake and export-web start from: the scene, the textured material
/// behind the glass (--material, when given), the pose and view at
/// --time, a device and the frame settings; `start` is taken once the scene
/// is loaded, so the time they report is the bake's, not the load's.
struct BakeSetup {
  scene::Scene scene;
  std::optional<uint32_t> material;
  std::chrono::steady_clock::time_point start;
  scene::Pose pose;
  scene::View view;
  std::unique_ptr<vk::Context> context;
  render::FrameSettings settings;
};
BakeSetup prepareBake(const std::string& command, const ShotOptions& shot, const std::string& material);

/// `text` with &, <, > and " escaped for XML, SVG and HTML.
std::string xmlEscape(const std::string& text);

}  // namespace snell::cli
