// A shot as a Slurm job (see slurm.h).
#include "farm/slurm.h"

#include "io/image_file.h"
#include "io/json.h"
#include "io/process.h"
#include "io/version.h"

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>

namespace snell::farm {

namespace {

namespace fs = std::filesystem;

std::string sbatchHeader(const SlurmSettings& s, const std::string& jobName, const std::string& log) {
  std::string h = "#SBATCH --job-name=" + jobName + "\n";
  h += "#SBATCH --output=" + log + "\n";
  h += "#SBATCH --chdir=" + s.workingDirectory + "\n";
  if (!s.partition.empty()) h += "#SBATCH --partition=" + s.partition + "\n";
  if (!s.timeLimit.empty()) h += "#SBATCH --time=" + s.timeLimit + "\n";
  return h;
}

// sbatch's job id: "123" or "123;cluster" with --parsable.
std::string submit(const std::vector<std::string>& argv, const std::function<void()>& tick, int& exitCode) {
  io::ProcessResult r = io::runProcess(argv, tick);
  exitCode = r.exitCode;
  std::string id = io::trimmed(r.out.substr(0, r.out.find(';')));
  if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos) {
    throw std::runtime_error("farm slurm: sbatch refused the job: " + io::trimmed(r.err.empty() ? r.out : r.err));
  }
  return id;
}

std::string slurmJobName(const FarmPlan& plan, const SlurmSettings& settings) {
  return settings.jobName.empty() ? "snell-" + plan.name() : settings.jobName;
}

// The check job's script: `snell farm check` of job `job`'s `tasks`.
std::string slurmCheckScript(const FarmPlan& plan, const SlurmSettings& s, const std::string& job,
                             const std::vector<size_t>& tasks) {
  std::string script = "#!/bin/bash\n";
  script += "# Runs after every task of job " + job + " however it ended (afterany), so that the\n";
  script += "# summary names the frames missing and the tasks that failed; exits 1 if any did.\n";
  script += sbatchHeader(s, slurmJobName(plan, s) + "-check", plan.folder() + "/logs/%j_check.out");
  script += "exec " + io::shellQuoted(s.executable) + " farm check " + io::shellQuoted(plan.planPath()) + " --job " +
            job + " --tasks " + arrayList(tasks) + "\n";
  return script;
}

// Throws std::invalid_argument listing the cluster's partitions where
// `partition` is none of them, std::runtime_error where sinfo cannot say.
void checkSlurmPartition(const std::string& partition) {
  if (!io::onPath("sinfo")) {
    throw std::runtime_error("farm slurm: sinfo is not on PATH (Debian 12: apt-get install slurm-client)");
  }
  io::ProcessResult r = io::runProcess({"sinfo", "--noheader", "--format=%R"});
  if (r.exitCode != 0) throw std::runtime_error("farm slurm: sinfo failed, is slurmctld reachable? " + io::trimmed(r.err));
  std::string names;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    line = io::trimmed(line);
    if (line == partition) return;
    if (!line.empty()) names += (names.empty() ? "" : ", ") + line;
  }
  throw std::invalid_argument("farm slurm: --partition " + partition + ": the cluster has no such partition; it has " +
                              (names.empty() ? "none" : names));
}

}  // namespace

std::string slurmJobScript(const FarmPlan& plan, const SlurmSettings& s) {
  std::string script = "#!/bin/bash\n";
  script += "# " + plan.name() + ": frames " + plan.frames.text + " of " + plan.scene + ", " +
            std::to_string(plan.chunk) + " a task. Written by 'snell farm slurm' (snell " + io::version() + ");\n";
  script += "# run that command again and it submits the tasks whose frames are missing.\n";
  script += sbatchHeader(s, slurmJobName(plan, s), plan.folder() + "/logs/%A_%a.out");
  if (s.cpusPerTask) script += "#SBATCH --cpus-per-task=" + std::to_string(s.cpusPerTask) + "\n";
  if (s.gpusPerTask) script += "#SBATCH --gpus-per-task=" + std::to_string(s.gpusPerTask) + "\n";
  for (const std::string& line : s.sbatchLines) script += "#SBATCH " + line + "\n";
  script += "\n# Task i renders line i: array indices stay small (Slurm's limit is 1000 by\n"
            "# default) whatever the frame numbers, which start at 1001 in many shots.\n";
  script += "tasks=(\n";
  for (size_t t = 0; t < plan.tasks(); ++t) script += "  " + plan.taskFrames(t).text + "\n";
  script += ")\n";
  script += "frames=${tasks[$SLURM_ARRAY_TASK_ID]}\n";
  script += "echo \"snell farm: task $SLURM_ARRAY_TASK_ID of job $SLURM_ARRAY_JOB_ID on $(hostname): frames $frames\"\n";
  std::string render = io::shellQuoted(s.executable) + " render " + io::shellQuoted(plan.scene) + " -o " +
                       io::shellQuoted(plan.output) + " --frames \"$frames\" --skip-existing --stats-json " +
                       io::shellQuoted(plan.statsPattern());
  for (const std::string& option : plan.renderOptions) render += " " + io::shellQuoted(option);
  script += render + "\n";
  script += "status=$?\n";
  script += "# The check job reads this: a task that leaves none did not finish.\n";
  script += "echo $status > " + io::shellQuoted(plan.folder() + "/status/") +
            "\"${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\"\n";
  script += "exit $status\n";
  return script;
}

void checkSlurmPlan(const FarmPlan& plan) {
  if (plan.tasks() > 1001) {
    throw std::invalid_argument("farm slurm: " + std::to_string(plan.tasks()) + " tasks of " +
                                std::to_string(plan.chunk) +
                                " frames pass Slurm's default limit of 1001 array tasks (MaxArraySize); give --chunk " +
                                std::to_string((plan.frames.size() + 1000) / 1001) + " or more");
  }
  if (plan.folder().find_first_of(" %\t\n") != std::string::npos) {
    throw std::invalid_argument("farm slurm: " + plan.folder() +
                                ": Slurm's log names cannot hold a space or '%'; write the images elsewhere");
  }
}

std::string submitSlurmTasks(const FarmPlan& plan, const SlurmSettings& s, const std::vector<size_t>& tasks) {
  if (!io::onPath("sbatch")) {
    throw std::runtime_error(
        "farm slurm: sbatch is not on PATH: run on a Slurm submit host (Debian 12: apt-get install slurm-client)");
  }
  if (!s.partition.empty()) checkSlurmPartition(s.partition);
  for (const char* sub : {"logs", "status", "stats"}) fs::create_directories(fs::path(plan.folder()) / sub);
  io::writeJson(plan.planPath(), plan.toJson());
  const std::string jobPath = plan.folder() + "/job.sh";
  io::writeTextFile(jobPath, slurmJobScript(plan, s));
  std::remove(plan.summaryPath().c_str());  // the one this job's check writes is the answer
  int exitCode = 0;
  return submit({"sbatch", "--parsable", "--array=" + arrayList(tasks), jobPath}, {}, exitCode);
}

SlurmCheck submitSlurmCheck(const FarmPlan& plan, const SlurmSettings& s, const std::string& job,
                            const std::vector<size_t>& tasks, bool wait, const std::function<void()>& tick) {
  const std::string checkPath = plan.folder() + "/check.sh";
  io::writeTextFile(checkPath, slurmCheckScript(plan, s, job, tasks));
  std::vector<std::string> argv = {"sbatch", "--parsable", "--dependency=afterany:" + job};
  // --wait: sbatch waits for the check job, which waits for every task.
  if (wait) argv.push_back("--wait");
  argv.push_back(checkPath);
  SlurmCheck check;
  check.job = submit(argv, wait ? tick : std::function<void()>(), check.exitCode);
  return check;
}

}  // namespace snell::farm
