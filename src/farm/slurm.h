// A shot as a Slurm job: an array job whose task i renders chunk i of the
// plan's frames with `snell render --skip-existing`, and a check job after
// every task (afterany) that writes the summary. The scripts, logs and
// status files live in the plan's folder; submitting again submits only
// the tasks with a frame missing.
#pragma once

#include "farm/plan.h"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace snell::farm {

struct SlurmSettings {
  uint32_t gpusPerTask = 0, cpusPerTask = 0;  ///< what each task asks for (0: nothing)
  std::string partition, timeLimit;
  std::string jobName;  ///< empty: snell-NAME
  std::vector<std::string> sbatchLines;  ///< further #SBATCH lines for the tasks
  std::string executable;  ///< the snell every task runs (the submitting one's path)
  std::string workingDirectory;  ///< where the tasks start (#SBATCH --chdir)
};

/// The array job's batch script.
std::string slurmJobScript(const FarmPlan& plan, const SlurmSettings& settings);

/// Whether the plan fits a Slurm job (array size, names Slurm's log
/// patterns can hold); throws std::invalid_argument saying what to change.
void checkSlurmPlan(const FarmPlan& plan);

/// Writes the plan and the job's script into the plan's folder and submits
/// tasks `tasks` of it; returns the job's id.
std::string submitSlurmTasks(const FarmPlan& plan, const SlurmSettings& settings, const std::vector<size_t>& tasks);

struct SlurmCheck {
  std::string job;   ///< the check job's id
  int exitCode = 0;  ///< with wait: how the check job (and so the shot) ended
};
/// Submits the check job to run after job `job`'s `tasks`, however they end.
/// With `wait`, returns once it has run, calling `tick` about once a second meanwhile.
SlurmCheck submitSlurmCheck(const FarmPlan& plan, const SlurmSettings& settings, const std::string& job,
                            const std::vector<size_t>& tasks, bool wait, const std::function<void()>& tick);

}  // namespace snell::farm
