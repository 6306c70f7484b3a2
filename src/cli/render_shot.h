// The frames of `snell render` (render_command.cpp parses its options): on
// one device, or with --devices on several, one worker per device, each with
// its own Vulkan device, scene upload and trees, taking frames from one
// queue so a slower device takes fewer. Frames are written whole, skipped
// where they exist, recorded with --stats-json; SIGTERM drops only the frames
// under way, and a lost device hands its frames back to the others.
#pragma once

#include "cli/frames.h"
#include "cli/options.h"
#include "render/method.h"
#include "render/raster_pass.h"

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace snell::cli {

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

/// What one worker did: for progress, --stats-json and `snell bench shot`.
struct WorkerReport {
  std::string device;
  size_t frames = 0;
  double loadSeconds = 0.0;  ///< its device, the scene's upload and pipelines, before its first frame
  double treeMs = 0.0;       ///< GPU time building trees (with timePasses)
  double gpuWaitSeconds = 0.0;  ///< waiting for its frames' GPU work
  double writeSeconds = 0.0;    ///< encoding and writing its images
  std::string lost;             ///< why it stopped early ("" when it ran to the end)
};

struct ShotReport {
  std::vector<WorkerReport> workers;
  double seconds = 0.0;  ///< from the start to the last frame written, loads included
  size_t framesWritten = 0;
};

/// Renders what `o` asks for; returns the exit code (0, 1 from validation,
/// 3 when a lost device left frames unwritten, 128+N after signal N) or
/// throws naming the problem. `report`, when given, receives each worker's figures.
int renderShot(RenderOptions& o, ShotReport* report = nullptr);

}  // namespace snell::cli
