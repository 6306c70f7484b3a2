// `snell farm`: a shot on a render farm that already exists. `slurm` submits
// it to Slurm as an array job, one task per chunk of frames, and a check job
// after it; `check` says which frames are missing and which tasks failed;
// `openjd` writes an Open Job Description template (Deadline Cloud). Every
// task is a plain `snell render --skip-existing`, so submitting the same
// command again renders only what is missing. The jobs themselves are the
// farm layer's (src/farm); this is their command line.
#include "cli/commands.h"
#include "farm/openjd.h"
#include "farm/plan.h"
#include "farm/slurm.h"
#include "io/image_file.h"
#include "io/json.h"
#include "io/process.h"
#include "io/progress.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>

namespace snell::cli {

namespace {

namespace fs = std::filesystem;

using farm::FarmCheck;
using farm::FarmPlan;
using farm::FrameList;

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
  farm::SlurmSettings settings;
  bool dryRun = false, wait = false;
};

int runSlurm(SlurmOptions& o, const std::vector<std::string>& renderOptions) {
  FarmPlan plan = usageErrors([&] { return FarmPlan::make(o.scene, o.output, *o.frames, o.chunk, {}); });
  std::vector<std::string> options = renderOptions;
  // A task given several GPUs renders its chunk on all of them (render --devices).
  bool devicesGiven = std::any_of(options.begin(), options.end(), [](const std::string& w) { return w.rfind("--devices", 0) == 0; });
  if (o.settings.gpusPerTask > 1 && !devicesGiven) options.insert(options.end(), {"--devices", "all"});
  plan.renderOptions = taskRenderOptions(plan.scene, plan.output, plan.frames, options);
  usageErrors([&] { farm::checkSlurmPlan(plan); });
  o.settings.executable = io::thisExecutable("snell");  // the same build on every node
  o.settings.workingDirectory = std::filesystem::current_path().string();
  std::vector<size_t> tasks = plan.tasksToRun();

  if (o.dryRun) {
    std::printf("%s", farm::slurmJobScript(plan, o.settings).c_str());
    if (tasks.empty()) {
      std::printf("# every frame exists: nothing would be submitted\n");
    } else {
      std::printf("# would submit: sbatch --array=%s %s/job.sh, then 'snell farm check' after it (afterany)\n",
                  farm::arrayList(tasks).c_str(), plan.folder().c_str());
    }
    return kExitOk;
  }
  if (tasks.empty()) {
    FarmCheck check = farm::checkFarm(plan, "", {});
    std::printf("%s: nothing to submit\n", check.message.c_str());
    return kExitOk;
  }
  const std::string job = usageErrors([&] { return farm::submitSlurmTasks(plan, o.settings, tasks); });
  std::printf("submitted job %s: %zu task(s) of up to %u frames (%zu of %zu frames missing), logs in %s/logs\n",
              job.c_str(), tasks.size(), plan.chunk, plan.missingFrames().size(), plan.frames.size(),
              plan.folder().c_str());
  if (!o.wait) {
    farm::SlurmCheck check = farm::submitSlurmCheck(plan, o.settings, job, tasks, false, {});
    std::printf("job %s checks it into %s; follow with: squeue -j %s,%s\n", check.job.c_str(),
                plan.summaryPath().c_str(), job.c_str(), check.job.c_str());
    return kExitOk;
  }

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
  farm::SlurmCheck check = farm::submitSlurmCheck(plan, o.settings, job, tasks, true, tick);
  tick();
  std::ifstream in(plan.summaryPath());
  io::Json summary = in ? io::Json::parse(in, nullptr, false) : io::Json();
  std::string message = summary.is_object() ? summary.value("message", std::string()) : std::string();
  if (message.empty()) {
    throw std::runtime_error("farm slurm: job " + job + "'s check wrote no summary (sbatch --wait exited " +
                             std::to_string(check.exitCode) + "); see " + plan.folder() + "/logs");
  }
  if (check.exitCode != 0) {
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
    for (long t : usageErrors([&] { return FrameList::parse("--tasks", o.tasks); }).frames) {
      if (size_t(t) >= plan.tasks()) {
        throw UsageError{"farm check: --tasks " + o.tasks + ": the plan has tasks 0-" + std::to_string(plan.tasks() - 1)};
      }
      tasks.push_back(size_t(t));
    }
  }
  FarmCheck check = farm::checkFarm(plan, o.job, tasks);
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

int runOpenJd(OpenJdOptions& o, const std::vector<std::string>& renderOptions) {
  usageErrors([&] { farm::checkOpenJdTemplatePath(o.output); });
  io::checkWritable(o.output);
  FarmPlan plan = usageErrors([&] { return FarmPlan::make(o.scene, o.images, *o.frames, o.chunk, {}); });
  plan.renderOptions = taskRenderOptions(plan.scene, plan.output, plan.frames, renderOptions);
  farm::writeOpenJdTemplate(o.output, farm::openJdTemplate(plan, o.name, o.gpusPerTask));
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
          "--frames", [&frames](const std::string& v) { frames = usageErrors([&] { return FrameList::parse("--frames", v); }); },
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
  slurm->add_option("--gpus-per-task", s->settings.gpusPerTask,
                    "GPUs Slurm gives each task (GRES; default: none asked);\nwith 2 or more, each task renders on all of them (--devices all)")
      ->type_name("N");
  slurm->add_option("--cpus-per-task", s->settings.cpusPerTask, "CPUs each task gets; lavapipe renders on that many threads")
      ->type_name("N");
  slurm->add_option("--partition", s->settings.partition, "the partition to run in (default: the cluster's)")->type_name("P");
  slurm->add_option("--time", s->settings.timeLimit, "each task's time limit, as sbatch takes it (30, 1:00:00, 1-0)")
      ->type_name("LIMIT");
  slurm->add_option("--job-name", s->settings.jobName, "the job's name in squeue (default snell-NAME)")->type_name("NAME");
  slurm->add_option("--sbatch", s->settings.sbatchLines, "a further #SBATCH line for the tasks (repeatable): --account=lighting")
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
