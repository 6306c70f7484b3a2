// The frames of `snell render` (render_command.cpp parses its options), drawn
// as a shot (render/shot.h: one worker per --devices entry) or by the CPU
// reference, and written here: whole, skipped where they exist, recorded
// with --stats-json, with the EXR's layers; SIGTERM drops only the frames
// under way.
#pragma once

#include "cli/options.h"
#include "farm/frames.h"
#include "render/method.h"
#include "render/raster_pass.h"
#include "render/shot.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace snell::cli {

using farm::FrameList;
using farm::checkFramePattern;
using farm::framePath;

/// The AOV layers --aov may name, in the order they are written.
extern const std::vector<std::string> kAovNames;

struct RenderOptions {
  ShotOptions shot;
  std::string output;
  std::optional<FrameList> frames;  ///< --frames; none: one picture at --time
  double fps = 24.0;
  bool skipExisting = false;
  std::string statsJson;  ///< a per-frame JSON's name pattern; empty: none
  /// --devices: "all", or indices and UUIDs ("0,1"; one may repeat); empty:
  /// the one device --device, SNELL_DEVICE or a launcher names.
  std::string devices;
  std::optional<double> bakeTime;
  bool reference = false;
  bool viewport = false;
  std::optional<render::Method> method;
  bool autoMethod = false;  ///< --method auto (the default for a trace): trace or driver-rt, timed
  bool stats = false;
  /// GPU timestamps around every pass though no --stats asks (bench shot's tree times).
  bool timePasses = false;
  render::RasterOptions raster;
  scene::Optics optics;
  std::string environment;
  std::vector<std::string> aovs;
  bool floatPixels = false;

  bool exr() const {
    std::string ext = std::filesystem::path(output).extension().string();
    return ext == ".exr" || ext == ".EXR";
  }
  bool wants(const std::string& aov) const { return std::find(aovs.begin(), aovs.end(), aov) != aovs.end(); }
};

/// Renders what `o` asks for; returns the exit code (0, 1 from validation,
/// 3 when a lost device left frames unwritten, 128+N after signal N) or
/// throws naming the problem. `report`, when given, receives each worker's figures.
int renderShot(RenderOptions& o, render::ShotReport* report = nullptr);

}  // namespace snell::cli
