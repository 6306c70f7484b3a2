// A shot as an Open Job Description template (see openjd.h).
#include "farm/openjd.h"

#include "io/image_file.h"
#include "io/version.h"
#include "io/yaml.h"

#include <filesystem>
#include <stdexcept>

namespace snell::farm {

namespace fs = std::filesystem;

io::Json openJdTemplate(const FarmPlan& plan, const std::string& name, uint32_t gpusPerTask) {
  const std::string directory = fs::path(plan.output).parent_path().string();
  const std::string fileName = fs::path(plan.output).filename().string();
  io::Json args = {"render", "{{Param.SceneFile}}", "-o", "{{Param.OutputDirectory}}/{{Param.OutputName}}", "--frames",
                   "{{Task.Param.Frame}}", "--skip-existing"};
  for (const std::string& option : plan.renderOptions) args.push_back(option);

  io::Json t;
  t["specificationVersion"] = "jobtemplate-2023-09";
  t["extensions"] = {"TASK_CHUNKING"};
  t["name"] = name.empty() ? "snell " + plan.name() : name;
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
  if (gpusPerTask > 0) {
    step["hostRequirements"]["amounts"] = io::Json::array({{{"name", "amount.worker.gpu"}, {"min", gpusPerTask}}});
  }
  step["script"]["actions"]["onRun"] = {
      {"command", "snell"},
      {"args", args},
      {"cancelation", {{"mode", "NOTIFY_THEN_TERMINATE"}, {"notifyPeriodInSeconds", 30}}}};
  t["steps"] = io::Json::array({step});

  return t;
}

void checkOpenJdTemplatePath(const std::string& path) {
  const std::string ext = fs::path(path).extension().string();
  if (ext != ".yaml" && ext != ".yml" && ext != ".json") {
    throw std::invalid_argument("farm openjd: -o " + path + ": a template ends in .yaml, .yml or .json");
  }
}

void writeOpenJdTemplate(const std::string& path, const io::Json& jobTemplate) {
  checkOpenJdTemplatePath(path);
  const bool json = fs::path(path).extension() == ".json";
  io::writeTextFile(path, json ? io::jsonText(jobTemplate)
                               : "# Open Job Description job template (jobtemplate-2023-09 with TASK_CHUNKING)\n" +
                                     io::yamlText(jobTemplate));
}

}  // namespace snell::farm
