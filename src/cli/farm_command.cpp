// `snell farm`: a shot on a render farm that already exists. `slurm` submits
// it to Slurm as an array job, one task per chunk of frames, and a check job
// after it; `check` says which frames are missing and which tasks failed;
// `openjd` writes an Open Job Description template (Deadline Cloud). Every
// task is a plain `snell render --skip-existing`, so submitting the same
// command again renders only what is missing.
#include "cli/commands.h"
#include "cli/farm_plan.h"
#include "io/image_file.h"
#include "io/json.h"
#include "io/progress.h"
#include "io/version.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace snell::cli {

namespace {

namespace fs = std::filesystem;

// ------------------------------------------------------------ child processes

struct ProcessResult {
  int exitCode = 0;
  std::string out, err;
};

// Runs `argv` (no shell) to the end, collecting what it prints; `tick` runs
// about once a second meanwhile (progress while `sbatch --wait` waits).
ProcessResult runProcess(const std::vector<std::string>& argv, const std::function<void()>& tick = {}) {
  int outPipe[2], errPipe[2];
  if (::pipe2(outPipe, O_CLOEXEC) != 0) throw std::runtime_error("cannot make a pipe for " + argv[0]);
  if (::pipe2(errPipe, O_CLOEXEC) != 0) {
    ::close(outPipe[0]), ::close(outPipe[1]);
    throw std::runtime_error("cannot make a pipe for " + argv[0]);
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, outPipe[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, errPipe[1], STDERR_FILENO);
  std::vector<char*> words;
  for (const std::string& w : argv) words.push_back(const_cast<char*>(w.c_str()));
  words.push_back(nullptr);
  pid_t pid = 0;
  int spawned = ::posix_spawnp(&pid, argv[0].c_str(), &actions, nullptr, words.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(outPipe[1]);
  ::close(errPipe[1]);
  if (spawned != 0) {
    ::close(outPipe[0]), ::close(errPipe[0]);
    throw std::runtime_error("cannot run " + argv[0] + ": " + std::strerror(spawned));
  }
  ProcessResult result;
  pollfd fds[2] = {{outPipe[0], POLLIN, 0}, {errPipe[0], POLLIN, 0}};
  std::string* sinks[2] = {&result.out, &result.err};
  auto lastTick = std::chrono::steady_clock::now();
  for (int open = 2; open > 0;) {
    int ready = ::poll(fds, 2, 1000);
    if (ready < 0 && errno != EINTR) break;
    for (int k = 0; k < 2 && ready > 0; ++k) {
      if (fds[k].fd < 0 || fds[k].revents == 0) continue;
      char buffer[4096];
      ssize_t n = ::read(fds[k].fd, buffer, sizeof buffer);
      if (n > 0) {
        sinks[k]->append(buffer, size_t(n));
      } else if (n == 0 || errno != EINTR) {
        ::close(fds[k].fd);
        fds[k].fd = -1;  // poll skips it from now on
        --open;
      }
    }
    if (tick && std::chrono::steady_clock::now() - lastTick >= std::chrono::seconds(1)) {
      tick();
      lastTick = std::chrono::steady_clock::now();
    }
  }
  for (pollfd& f : fds) {
    if (f.fd >= 0) ::close(f.fd);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

bool onPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string dirs = path ? path : "";
  for (size_t start = 0; start <= dirs.size();) {
    size_t colon = dirs.find(':', start);
    std::string dir = dirs.substr(start, colon == std::string::npos ? std::string::npos : colon - start);
    if (!dir.empty() && ::access((dir + "/" + program).c_str(), X_OK) == 0) return true;
    if (colon == std::string::npos) break;
    start = colon + 1;
  }
  return false;
}

std::string trimmed(std::string text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back()))) text.pop_back();
  size_t first = text.find_first_not_of(" \t\r\n");
  return first == std::string::npos ? "" : text.substr(first);
}

// The running snell, so tasks run the same build on every node (an installed
// package puts it at the same path on each).
std::string thisExecutable() {
  std::error_code error;
  fs::path self = fs::read_symlink("/proc/self/exe", error);
  return error ? std::string("snell") : self.string();
}

// --------------------------------------------------------- the render command

// What every task adds to its own `snell render`: the user's render options,
// checked now as render would check them (the scene loads, the options agree),
// and what makes a frame's pixels the same in every task.
std::vector<std::string> taskRenderOptions(const std::string& scene, const std::string& output, const FrameList& frames,
                                           std::vector<std::string> options) {
  Args args = {scene, "-o", output, "--frames", frames.text};
  args.insert(args.end(), options.begin(), options.end());
  RenderCheck check = checkRender(args);
  // auto times trace against driver-rt in each task, so tasks could choose differently.
  if (check.autoMethod) options.insert(options.end(), {"--method", "trace"});
  // refraction-map bakes at the first frame a task renders unless told the shot's.
  if (check.method == "refraction-map" && !check.bakeTimeGiven) {
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "%.17g", double(frames.frames.front()) / check.fps);
    options.insert(options.end(), {"--bake-time", seconds});
  }
  return options;
}

// ---------------------------------------------------------------------- slurm

struct SlurmOptions {
  std::string scene, output;
  std::optional<FrameList> frames;
  uint32_t chunk = 10;
  uint32_t gpusPerTask = 0, cpusPerTask = 0;
  std::string partition, timeLimit, jobName;
  std::vector<std::string> sbatchLines;
  bool dryRun = false, wait = false;
};

std::string sbatchHeader(const SlurmOptions& o, const std::string& jobName, const std::string& log) {
  std::string s = "#SBATCH --job-name=" + jobName + "\n";
  s += "#SBATCH --output=" + log + "\n";
  s += "#SBATCH --chdir=" + fs::current_path().string() + "\n";
  if (!o.partition.empty()) s += "#SBATCH --partition=" + o.partition + "\n";
  if (!o.timeLimit.empty()) s += "#SBATCH --time=" + o.timeLimit + "\n";
  return s;
}

std::string jobScript(const FarmPlan& plan, const SlurmOptions& o, const std::string& jobName) {
  std::string s = "#!/bin/bash\n";
  s += "# " + plan.name() + ": frames " + plan.frames.text + " of " + plan.scene + ", " + std::to_string(plan.chunk) +
       " a task. Written by 'snell farm slurm' (snell " + io::version() + ");\n";
  s += "# run that command again and it submits the tasks whose frames are missing.\n";
  s += sbatchHeader(o, jobName, plan.folder() + "/logs/%A_%a.out");
  if (o.cpusPerTask) s += "#SBATCH --cpus-per-task=" + std::to_string(o.cpusPerTask) + "\n";
  if (o.gpusPerTask) s += "#SBATCH --gpus-per-task=" + std::to_string(o.gpusPerTask) + "\n";
  for (const std::string& line : o.sbatchLines) s += "#SBATCH " + line + "\n";
  s += "\n# Task i renders line i: array indices stay small (Slurm's limit is 1000 by\n"
       "# default) whatever the frame numbers, which start at 1001 in many shots.\n";
  s += "tasks=(\n";
  for (size_t t = 0; t < plan.tasks(); ++t) s += "  " + plan.taskFrames(t).text + "\n";
  s += ")\n";
  s += "frames=${tasks[$SLURM_ARRAY_TASK_ID]}\n";
  s += "echo \"snell farm: task $SLURM_ARRAY_TASK_ID of job $SLURM_ARRAY_JOB_ID on $(hostname): frames $frames\"\n";
  std::string render = io::shellQuoted(thisExecutable()) + " render " + io::shellQuoted(plan.scene) + " -o " +
                       io::shellQuoted(plan.output) + " --frames \"$frames\" --skip-existing --stats-json " +
                       io::shellQuoted(plan.statsPattern());
  for (const std::string& option : plan.renderOptions) render += " " + io::shellQuoted(option);
  s += render + "\n";
  s += "status=$?\n";
  s += "# The check job reads this: a task that leaves none did not finish.\n";
  s += "echo $status > " + io::shellQuoted(plan.folder() + "/status/") + "\"${SLURM_ARRAY_JOB_ID}_${SLURM_ARRAY_TASK_ID}\"\n";
  s += "exit $status\n";
  return s;
}

std::string checkScript(const FarmPlan& plan, const SlurmOptions& o, const std::string& jobName, const std::string& job,
                        const std::vector<size_t>& tasks) {
  std::string s = "#!/bin/bash\n";
  s += "# Runs after every task of job " + job + " however it ended (afterany), so that the\n";
  s += "# summary names the frames missing and the tasks that failed; exits 1 if any did.\n";
  s += sbatchHeader(o, jobName + "-check", plan.folder() + "/logs/%j_check.out");
  s += "exec " + io::shellQuoted(thisExecutable()) + " farm check " + io::shellQuoted(plan.planPath()) + " --job " + job +
       " --tasks " + arrayList(tasks) + "\n";
  return s;
}

void checkPartition(const std::string& partition) {
  if (!onPath("sinfo")) throw std::runtime_error("farm slurm: sinfo is not on PATH (Debian 12: apt-get install slurm-client)");
  ProcessResult r = runProcess({"sinfo", "--noheader", "--format=%R"});
  if (r.exitCode != 0) throw std::runtime_error("farm slurm: sinfo failed, is slurmctld reachable? " + trimmed(r.err));
  std::string names;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    line = trimmed(line);
    if (line == partition) return;
    if (!line.empty()) names += (names.empty() ? "" : ", ") + line;
  }
  throw UsageError{"farm slurm: --partition " + partition + ": the cluster has no such partition; it has " +
                   (names.empty() ? "none" : names)};
}

// sbatch's job id: "123" or "123;cluster" with --parsable.
std::string submit(const std::vector<std::string>& argv, const std::function<void()>& tick, int& exitCode) {
  ProcessResult r = runProcess(argv, tick);
  exitCode = r.exitCode;
  std::string id = trimmed(r.out.substr(0, r.out.find(';')));
  if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos) {
    throw std::runtime_error("farm slurm: sbatch refused the job: " +
                             trimmed(r.err.empty() ? r.out : r.err));
  }
  return id;
}

int runSlurm(SlurmOptions& o, const std::vector<std::string>& renderOptions) {
  FarmPlan plan = FarmPlan::make(o.scene, o.output, *o.frames, o.chunk, {});
  std::vector<std::string> options = renderOptions;
  // A task given several GPUs renders its chunk on all of them (render --devices).
  bool devicesGiven = std::any_of(options.begin(), options.end(), [](const std::string& w) { return w.rfind("--devices", 0) == 0; });
  if (o.gpusPerTask > 1 && !devicesGiven) options.insert(options.end(), {"--devices", "all"});
  plan.renderOptions = taskRenderOptions(plan.scene, plan.output, plan.frames, options);
  if (plan.tasks() > 1001) {
    throw UsageError{"farm slurm: " + std::to_string(plan.tasks()) + " tasks of " + std::to_string(plan.chunk) +
                     " frames pass Slurm's default limit of 1001 array tasks (MaxArraySize); give --chunk " +
                     std::to_string((plan.frames.size() + 1000) / 1001) + " or more"};
  }
  if (plan.folder().find_first_of(" %\t\n") != std::string::npos) {
    throw UsageError{"farm slurm: " + plan.folder() + ": Slurm's log names cannot hold a space or '%'; write the images elsewhere"};
  }
  const std::string jobName = o.jobName.empty() ? "snell-" + plan.name() : o.jobName;
  std::vector<size_t> tasks = plan.tasksToRun();

  if (o.dryRun) {
    std::printf("%s", jobScript(plan, o, jobName).c_str());
    if (tasks.empty()) {
      std::printf("# every frame exists: nothing would be submitted\n");
    } else {
      std::printf("# would submit: sbatch --array=%s %s/job.sh, then 'snell farm check' after it (afterany)\n",
                  arrayList(tasks).c_str(), plan.folder().c_str());
    }
    return kExitOk;
  }
  if (tasks.empty()) {
    FarmCheck check = checkFarm(plan, "", {});
    std::printf("%s: nothing to submit\n", check.message.c_str());
    return kExitOk;
  }
  if (!onPath("sbatch")) {
    throw std::runtime_error("farm slurm: sbatch is not on PATH: run on a Slurm submit host (Debian 12: apt-get install slurm-client)");
  }
  if (!o.partition.empty()) checkPartition(o.partition);

  for (const char* sub : {"logs", "status", "stats"}) fs::create_directories(fs::path(plan.folder()) / sub);
  io::writeJson(plan.planPath(), plan.toJson());
  const std::string jobPath = plan.folder() + "/job.sh";
  io::writeTextFile(jobPath, jobScript(plan, o, jobName));
  std::remove(plan.summaryPath().c_str());  // the one this job's check writes is the answer
  int exitCode = 0;
  std::string job = submit({"sbatch", "--parsable", "--array=" + arrayList(tasks), jobPath}, {}, exitCode);
  const std::string checkPath = plan.folder() + "/check.sh";
  io::writeTextFile(checkPath, checkScript(plan, o, jobName, job, tasks));
  std::vector<std::string> checkArgs = {"sbatch", "--parsable", "--dependency=afterany:" + job};
  std::printf("submitted job %s: %zu task(s) of up to %u frames (%zu of %zu frames missing), logs in %s/logs\n",
              job.c_str(), tasks.size(), plan.chunk, plan.missingFrames().size(), plan.frames.size(),
              plan.folder().c_str());
  if (!o.wait) {
    checkArgs.push_back(checkPath);
    std::string check = submit(checkArgs, {}, exitCode);
    std::printf("job %s checks it into %s; follow with: squeue -j %s,%s\n", check.c_str(), plan.summaryPath().c_str(),
                job.c_str(), check.c_str());
    return kExitOk;
  }

  // --wait: sbatch waits for the check job, which waits for every task.
  checkArgs.insert(checkArgs.end(), {"--wait", checkPath});
  std::fflush(stdout);
  const size_t missing = plan.missingFrames().size();
  io::Progress progress("frames", missing, quiet());
  size_t shown = SIZE_MAX;
  auto tick = [&] {
    size_t done = missing - std::min(missing, plan.missingFrames().size());
    if (done != shown) progress.update(done, "job " + job);
    shown = done;
  };
  tick();
  submit(checkArgs, tick, exitCode);
  tick();
  std::ifstream in(plan.summaryPath());
  io::Json summary = in ? io::Json::parse(in, nullptr, false) : io::Json();
  std::string message = summary.is_object() ? summary.value("message", std::string()) : std::string();
  if (message.empty()) {
    throw std::runtime_error("farm slurm: job " + job + "'s check wrote no summary (sbatch --wait exited " +
                             std::to_string(exitCode) + "); see " + plan.folder() + "/logs");
  }
  if (exitCode != 0) {
    std::fprintf(stderr, "snell: error: %s\n", message.c_str());
    return kExitFailure;
  }
  std::printf("%s\n", message.c_str());
  return kExitOk;
}

// ---------------------------------------------------------------------- check

struct CheckOptions {
  std::string plan, job, tasks;
};

int runCheck(const CheckOptions& o) {
  FarmPlan plan = FarmPlan::read(o.plan);
  std::vector<size_t> tasks;
  if (!o.tasks.empty()) {
    for (long t : FrameList::parse("--tasks", o.tasks).frames) {
      if (size_t(t) >= plan.tasks()) {
        throw UsageError{"farm check: --tasks " + o.tasks + ": the plan has tasks 0-" + std::to_string(plan.tasks() - 1)};
      }
      tasks.push_back(size_t(t));
    }
  }
  FarmCheck check = checkFarm(plan, o.job, tasks);
  io::writeJson(plan.summaryPath(), check.summary);
  if (!check.ok()) {
    std::fprintf(stderr, "snell: error: %s\n", check.message.c_str());
    return kExitFailure;
  }
  std::printf("%s; summary %s\n", check.message.c_str(), plan.summaryPath().c_str());
  return kExitOk;
}

// --------------------------------------------------------------------- openjd

struct OpenJdOptions {
  std::string scene, images, output, name;
  std::optional<FrameList> frames;
  uint32_t chunk = 10;
  uint32_t gpusPerTask = 1;
};

std::string yamlScalar(const io::Json& value) {
  if (!value.is_string()) return value.dump();
  std::string quoted = "'";
  for (char c : value.get<std::string>()) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  return quoted + "'";
}

// Block-style YAML of a JSON tree; every string single-quoted, so no value
// reads back as a number, a boolean or a comment.
void emitYaml(const io::Json& node, const std::string& indent, std::string& out) {
  if (node.is_object()) {
    for (auto it = node.begin(); it != node.end(); ++it) {
      const io::Json& value = it.value();
      out += indent + it.key() + ":";
      if (value.is_object() && !value.empty()) {
        out += "\n";
        emitYaml(value, indent + "  ", out);
      } else if (value.is_array() && !value.empty()) {
        out += "\n";
        emitYaml(value, indent, out);
      } else {
        out += " " + (value.is_structured() ? std::string(value.is_array() ? "[]" : "{}") : yamlScalar(value)) + "\n";
      }
    }
  } else if (node.is_array()) {
    for (const io::Json& item : node) {
      if (item.is_structured() && !item.empty()) {
        std::string inner;
        emitYaml(item, indent + "  ", inner);
        out += indent + "- " + inner.substr(indent.size() + 2);
      } else {
        out += indent + "- " + (item.is_structured() ? std::string(item.is_array() ? "[]" : "{}") : yamlScalar(item)) + "\n";
      }
    }
  }
}

int runOpenJd(OpenJdOptions& o, const std::vector<std::string>& renderOptions) {
  std::string ext = fs::path(o.output).extension().string();
  bool yaml = ext == ".yaml" || ext == ".yml";
  if (!yaml && ext != ".json") throw UsageError{"farm openjd: -o " + o.output + ": a template ends in .yaml, .yml or .json"};
  io::checkWritable(o.output);
  FarmPlan plan = FarmPlan::make(o.scene, o.images, *o.frames, o.chunk, {});
  std::vector<std::string> options = taskRenderOptions(plan.scene, plan.output, plan.frames, renderOptions);
  const std::string directory = fs::path(plan.output).parent_path().string();
  const std::string fileName = fs::path(plan.output).filename().string();

  io::Json args = {"render", "{{Param.SceneFile}}", "-o", "{{Param.OutputDirectory}}/{{Param.OutputName}}", "--frames",
                   "{{Task.Param.Frame}}", "--skip-existing"};
  for (const std::string& option : options) args.push_back(option);

  io::Json t;
  t["specificationVersion"] = "jobtemplate-2023-09";
  t["extensions"] = {"TASK_CHUNKING"};
  t["name"] = o.name.empty() ? "snell " + plan.name() : o.name;
  t["description"] = "Written by 'snell farm openjd' (snell " + std::string(io::version()) +
                     "). Each task runs 'snell render --skip-existing' on a chunk of frames, so a retry renders only "
                     "what is missing; SIGTERM drops the frame under way and keeps those written.";
  t["parameterDefinitions"] = io::Json::array({
      {{"name", "SceneFile"}, {"type", "PATH"}, {"objectType", "FILE"}, {"dataFlow", "IN"}, {"default", plan.scene},
       {"description", "The glTF scene to render."}},
      {{"name", "OutputDirectory"}, {"type", "PATH"}, {"objectType", "DIRECTORY"}, {"dataFlow", "OUT"},
       {"default", directory}, {"description", "Where the images go."}},
      {{"name", "OutputName"}, {"type", "STRING"}, {"default", fileName},
       {"description", "The images' file name, with '#'s or %04d for the frame number; .png or .exr."}},
      {{"name", "Frames"}, {"type", "STRING"}, {"default", plan.frames.format(":")},
       {"description", "The frames, as an Open Job Description range: 1-240, 1-240:4, 1,5,10-20."}},
      {{"name", "ChunkSize"}, {"type", "INT"}, {"default", plan.chunk}, {"minValue", 1},
       {"description", "Frames per task."}},
  });
  io::Json step;
  step["name"] = "Render";
  step["parameterSpace"]["taskParameterDefinitions"] = io::Json::array(
      {{{"name", "Frame"},
        {"type", "CHUNK[INT]"},
        {"range", "{{Param.Frames}}"},
        // NONCONTIGUOUS: a chunk of a stepped or broken list ("1-9:4,20") is still one task.
        {"chunks", {{"defaultTaskCount", "{{Param.ChunkSize}}"}, {"rangeConstraint", "NONCONTIGUOUS"}}}}});
  // render will not write into a folder that is not there (a typo's guard);
  // on a worker, the step makes it first.
  io::Json folder;
  folder["name"] = "ImageFolder";
  folder["description"] = "Makes the image folder on the worker.";
  folder["script"]["actions"]["onEnter"]["command"] = "mkdir";
  folder["script"]["actions"]["onEnter"]["args"] = {"-p", "{{Param.OutputDirectory}}"};
  step["stepEnvironments"] = io::Json::array({folder});
  if (o.gpusPerTask > 0) {
    step["hostRequirements"]["amounts"] = io::Json::array({{{"name", "amount.worker.gpu"}, {"min", o.gpusPerTask}}});
  }
  step["script"]["actions"]["onRun"] = {
      {"command", "snell"},
      {"args", args},
      {"cancelation", {{"mode", "NOTIFY_THEN_TERMINATE"}, {"notifyPeriodInSeconds", 30}}}};
  t["steps"] = io::Json::array({step});

  std::string text;
  if (yaml) {
    text = "# Open Job Description job template (jobtemplate-2023-09 with TASK_CHUNKING)\n";
    emitYaml(t, "", text);
  } else {
    text = io::jsonText(t);
  }
  io::writeTextFile(o.output, text);
  std::printf("wrote %s: %s, frames %s in tasks of %u, %s\n", o.output.c_str(), plan.name().c_str(),
              plan.frames.format(":").c_str(), plan.chunk,
              o.gpusPerTask ? ("on workers with " + std::to_string(o.gpusPerTask) + " GPU(s)").c_str() : "on any worker");
  return kExitOk;
}

// ------------------------------------------------------------ the commands

constexpr const char* kFarmDescription =
    "A shot on a render farm that already exists. 'snell farm slurm' submits it to\n"
    "Slurm; 'snell farm openjd' writes a job template for Open Job Description\n"
    "farms (Deadline Cloud). Every task is 'snell render --skip-existing' over a\n"
    "chunk of frames, so the same command again renders only what is missing, and\n"
    "a frame's pixels are the same whichever task, retry or node renders it.";

constexpr const char* kSlurmDescription =
    "Submits the shot to Slurm as an array job, task i rendering chunk i of the\n"
    "frames, and a check job after every task (however it ended) that writes\n"
    "summary.json: the frames written, those missing, the tasks that failed.\n"
    "Scripts, logs, per-frame records (--stats-json) and the summary live in\n"
    ".snell-farm/NAME beside the images. Submitting again submits only the tasks\n"
    "with a missing frame. Options this command does not know are render's\n"
    "('snell render --help'), checked before anything is submitted; without a\n"
    "--method the tasks trace (auto could choose differently in each). GPUs: a\n"
    "task draws the GPU Slurm gives it (CUDA_VISIBLE_DEVICES), or with no GPU\n"
    "lavapipe on --cpus-per-task threads.";

constexpr const char* kOpenJdDescription =
    "Writes an Open Job Description job template (jobtemplate-2023-09 with the\n"
    "TASK_CHUNKING extension) for farms that run them, Deadline Cloud's among\n"
    "them. The scene, image folder and name, frames and chunk size become job\n"
    "parameters, with what is given here as their defaults; each task runs\n"
    "'snell render --skip-existing' over its chunk. Options this command does\n"
    "not know are render's, checked now. Nothing is run: submit the template\n"
    "with your farm's tools.";

void addFramesAndChunk(CLI::App& command, std::optional<FrameList>& frames, uint32_t& chunk) {
  command
      .add_option_function<std::string>(
          "--frames", [&frames](const std::string& v) { frames = FrameList::parse("--frames", v); },
          "the shot's frames: 1001-1240, 1-240x4, 1:240:4, 1,5,10-20")
      ->type_name("LIST")
      ->required();
  command.add_option("--chunk", chunk, "frames per task (default 10)")->type_name("N")->check(CLI::PositiveNumber);
}

}  // namespace

void addFarm(CLI::App& parent, Runner& run) {
  CLI::App* farm = parent.add_subcommand("farm", "send a shot to a render farm: 'snell farm slurm|openjd|check'");
  describe(*farm, kFarmDescription);
  farm->footer(kHelpFooter);
  farm->require_subcommand(1);

  auto s = std::make_shared<SlurmOptions>();
  CLI::App* slurm = farm->add_subcommand("slurm", "submit the shot to Slurm as an array job");
  describe(*slurm, kSlurmDescription);
  slurm->footer(kHelpFooter);
  slurm->allow_extras();  // render's options, which the tasks pass on
  slurm->fallthrough(false);
  slurm->add_option("scene", s->scene, "the glTF scene (.gltf or .glb); render options go after it")
      ->required()
      ->check(CLI::ExistingFile)
      ->type_name("SCENE");
  slurm->add_option("-o,--output", s->output, "the images: a name with '#'s or %04d for the frame (shot.####.exr)")
      ->required()
      ->type_name("PATTERN");
  addFramesAndChunk(*slurm, s->frames, s->chunk);
  slurm->add_option("--gpus-per-task", s->gpusPerTask,
                    "GPUs Slurm gives each task (GRES; default: none asked);\nwith 2 or more, each task renders on all of them (--devices all)")
      ->type_name("N");
  slurm->add_option("--cpus-per-task", s->cpusPerTask, "CPUs each task gets; lavapipe renders on that many threads")
      ->type_name("N");
  slurm->add_option("--partition", s->partition, "the partition to run in (default: the cluster's)")->type_name("P");
  slurm->add_option("--time", s->timeLimit, "each task's time limit, as sbatch takes it (30, 1:00:00, 1-0)")
      ->type_name("LIMIT");
  slurm->add_option("--job-name", s->jobName, "the job's name in squeue (default snell-NAME)")->type_name("NAME");
  slurm->add_option("--sbatch", s->sbatchLines, "a further #SBATCH line for the tasks (repeatable): --account=lighting")
      ->type_name("OPTION")
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
      ->allow_extra_args(false);
  slurm->add_flag("--dry-run", s->dryRun, "print the batch script and what would be submitted; submit nothing");
  slurm->add_flag("--wait", s->wait,
                  "wait for the job and the check; exit 0 only if every frame\nwas written and every task exited 0");
  slurm->callback([s, slurm, &run] {
    std::vector<std::string> renderOptions = slurm->remaining();
    run = [s, renderOptions] { return runSlurm(*s, renderOptions); };
  });

  auto c = std::make_shared<CheckOptions>();
  CLI::App* check = farm->add_subcommand("check", "say which frames of a farm job are missing and which tasks failed");
  describe(*check,
           "Reads a shot's plan (.snell-farm/NAME/plan.json beside its images), looks for\n"
           "every frame's image and, with --job, at how each task of that job ended; writes\n"
           "summary.json beside the plan and exits 1 naming what is missing. 'snell farm\n"
           "slurm' runs it as the job after the tasks.");
  check->footer(kHelpFooter);
  check->add_option("plan", c->plan, "the plan.json 'snell farm slurm' wrote")->required()->type_name("PLAN");
  check->add_option("--job", c->job, "the array job whose tasks to check")->type_name("ID");
  check->add_option("--tasks", c->tasks, "its tasks (array indices): 0-23 or 0,4")->type_name("LIST")->needs("--job");
  check->callback([c, &run] { run = [c] { return runCheck(*c); }; });

  auto j = std::make_shared<OpenJdOptions>();
  CLI::App* openjd = farm->add_subcommand("openjd", "write an Open Job Description template (Deadline Cloud)");
  describe(*openjd, kOpenJdDescription);
  openjd->footer(kHelpFooter);
  openjd->allow_extras();
  openjd->fallthrough(false);
  openjd->add_option("scene", j->scene, "the glTF scene (the SceneFile parameter's default)")
      ->required()
      ->check(CLI::ExistingFile)
      ->type_name("SCENE");
  openjd->add_option("-o,--output", j->output, "the template to write: .yaml or .json")->required()->type_name("FILE");
  openjd->add_option("--images", j->images, "the images: a name with '#'s or %04d for the frame (shot.####.exr)")
      ->required()
      ->type_name("PATTERN");
  addFramesAndChunk(*openjd, j->frames, j->chunk);
  openjd->add_option("--gpus-per-task", j->gpusPerTask, "GPUs a worker must have (default 1; 0: any worker, lavapipe)")
      ->type_name("N");
  openjd->add_option("--name", j->name, "the job's name (default 'snell NAME')")->type_name("NAME");
  openjd->callback([j, openjd, &run] {
    std::vector<std::string> renderOptions = openjd->remaining();
    run = [j, renderOptions] { return runOpenJd(*j, renderOptions); };
  });
}

}  // namespace snell::cli
