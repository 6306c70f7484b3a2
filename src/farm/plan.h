// A shot as a farm runs it: the frames cut into chunks (one array task
// each), the folder beside the images where the job's scripts, logs and
// per-frame records live, and the check that says which frames are missing
// and which tasks failed. The Slurm and Open Job Description jobs
// (slurm.h, openjd.h) are written around it.
#pragma once

#include "farm/frames.h"
#include "io/json.h"

#include <cstdint>
#include <string>
#include <vector>

namespace snell::farm {

struct FarmPlan {
  std::string scene;   ///< absolute
  std::string output;  ///< the images' name pattern, absolute (shot.####.exr)
  FrameList frames;
  uint32_t chunk = 10;  ///< frames per task
  /// What every task adds to `snell render SCENE -o OUTPUT --frames CHUNK`.
  std::vector<std::string> renderOptions;

  /// A plan for `frames` of `scene` into `output` (both made absolute).
  /// Throws std::invalid_argument when several frames have no slot in the name, or `chunk` is 0.
  static FarmPlan make(const std::string& scene, const std::string& output, FrameList frames, uint32_t chunk,
                       std::vector<std::string> renderOptions);

  /// The shot's name: the images' file name without its frame slot and
  /// extension ("shot.####.exr": "shot").
  std::string name() const;
  /// Where the job's files go: .snell-farm/NAME beside the images.
  std::string folder() const;
  std::string planPath() const { return folder() + "/plan.json"; }
  std::string summaryPath() const { return folder() + "/summary.json"; }
  /// The per-frame --stats-json pattern: stats/NAME.####.json in the folder.
  std::string statsPattern() const;
  /// Task `task`'s log and exit-status file, as job.sh writes them.
  std::string logPath(const std::string& job, size_t task) const;
  std::string statusPath(const std::string& job, size_t task) const;

  size_t tasks() const { return (frames.size() + chunk - 1) / chunk; }
  /// The frames task `task` renders: chunk `task` of the list, in order.
  FrameList taskFrames(size_t task) const;
  /// The frames whose image is not a complete file yet.
  std::vector<long> missingFrames() const;
  /// The tasks that have a missing frame: what a (re)submission runs.
  std::vector<size_t> tasksToRun() const;

  io::Json toJson() const;
  /// Reads plan.json back; throws std::runtime_error naming the file.
  static FarmPlan read(const std::string& path);
};

/// How one task of a job ended, from the status file job.sh leaves.
struct TaskOutcome {
  size_t task = 0;
  FrameList frames;
  /// Its exit code; -1 where it left none (killed, out of time, node lost).
  int exitCode = -1;
  std::string log;
};

/// A job's outcome: every frame's image there, and every task it ran exited 0.
struct FarmCheck {
  std::vector<long> missing;
  std::vector<TaskOutcome> failed;
  size_t written = 0;
  bool ok() const { return missing.empty() && failed.empty(); }
  /// One line: "shot: 6 of 6 frames written" or what is missing and why.
  std::string message;
  io::Json summary;  ///< what summary.json holds
};

/// Checks `plan` after job `job` ran `tasks` (either may be empty: frames only).
FarmCheck checkFarm(const FarmPlan& plan, const std::string& job, const std::vector<size_t>& tasks);

/// Indices as Slurm's --array takes them: "0-2,5".
std::string arrayList(const std::vector<size_t>& indices);

}  // namespace snell::farm
