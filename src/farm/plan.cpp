// A shot's chunks, its farm folder and its check (see plan.h).
#include "farm/plan.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

namespace snell::farm {

namespace fs = std::filesystem;

namespace {

// The file name with its '#'s or %0Nd and the extension cut out, and the
// separators they leave at the ends trimmed: "shot.####.exr" is "shot".
std::string stemWithoutSlot(const std::string& fileName) {
  std::string stem = fs::path(fileName).stem().string();
  std::string cut;
  for (size_t i = 0; i < stem.size(); ++i) {
    if (stem[i] == '#') continue;
    if (stem[i] == '%') {
      size_t q = i + 1;
      while (q < stem.size() && std::isdigit(static_cast<unsigned char>(stem[q]))) ++q;
      if (q < stem.size() && stem[q] == 'd') {
        i = q;
        continue;
      }
    }
    cut += stem[i];
  }
  auto separator = [](char c) { return c == '.' || c == '_' || c == '-' || c == ' '; };
  while (!cut.empty() && separator(cut.back())) cut.pop_back();
  while (!cut.empty() && separator(cut.front())) cut.erase(cut.begin());
  return cut.empty() ? "frames" : cut;
}

FrameList listOf(std::vector<long> frames) {
  FrameList list;
  list.frames = std::move(frames);
  list.text = list.format();
  return list;
}

int readStatus(const std::string& path) {
  std::ifstream in(path);
  int code = -1;
  if (!(in >> code)) return -1;
  return code;
}

}  // namespace

FarmPlan FarmPlan::make(const std::string& scene, const std::string& output, FrameList frames, uint32_t chunk,
                        std::vector<std::string> renderOptions) {
  if (chunk == 0) throw std::invalid_argument("--chunk must be 1 or more frames");
  checkFramePattern("-o", output, frames.size());
  FarmPlan plan;
  plan.scene = fs::absolute(scene).lexically_normal().string();
  plan.output = fs::absolute(output).lexically_normal().string();
  plan.frames = std::move(frames);
  plan.chunk = chunk;
  plan.renderOptions = std::move(renderOptions);
  return plan;
}

std::string FarmPlan::name() const { return stemWithoutSlot(fs::path(output).filename().string()); }

std::string FarmPlan::folder() const { return (fs::path(output).parent_path() / ".snell-farm" / name()).string(); }

std::string FarmPlan::statsPattern() const {
  return (fs::path(folder()) / "stats" / fs::path(output).filename().replace_extension(".json")).string();
}

std::string FarmPlan::logPath(const std::string& job, size_t task) const {
  return folder() + "/logs/" + job + "_" + std::to_string(task) + ".out";
}

std::string FarmPlan::statusPath(const std::string& job, size_t task) const {
  return folder() + "/status/" + job + "_" + std::to_string(task);
}

FrameList FarmPlan::taskFrames(size_t task) const {
  size_t first = std::min(task * chunk, frames.size());
  size_t last = std::min(first + chunk, frames.size());
  return listOf({frames.frames.begin() + long(first), frames.frames.begin() + long(last)});
}

std::vector<long> FarmPlan::missingFrames() const {
  std::vector<long> missing;
  for (long f : frames.frames) {
    // Images are renamed into place whole, so a regular file is a finished frame.
    if (!fs::is_regular_file(framePath(output, f))) missing.push_back(f);
  }
  return missing;
}

std::vector<size_t> FarmPlan::tasksToRun() const {
  std::vector<size_t> run;
  for (size_t t = 0; t < tasks(); ++t) {
    for (long f : taskFrames(t).frames) {
      if (!fs::is_regular_file(framePath(output, f))) {
        run.push_back(t);
        break;
      }
    }
  }
  return run;
}

io::Json FarmPlan::toJson() const {
  io::Json j = io::reportHead("farm-plan", nullptr);
  j["scene"] = scene;
  j["output"] = output;
  j["frames"] = frames.text;
  j["chunk"] = chunk;
  j["render_options"] = renderOptions;
  io::Json tasks = io::Json::array();
  for (size_t t = 0; t < this->tasks(); ++t) tasks.push_back(taskFrames(t).text);
  j["tasks"] = tasks;
  return j;
}

FarmPlan FarmPlan::read(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be read (a farm plan is .snell-farm/NAME/plan.json beside the images)");
  io::Json j = io::Json::parse(in, nullptr, false);
  if (j.is_discarded() || !j.is_object()) throw std::runtime_error(path + ": not a JSON farm plan");
  try {
    FarmPlan plan;
    plan.scene = j.at("scene").get<std::string>();
    plan.output = j.at("output").get<std::string>();
    plan.frames = FrameList::parse("frames", j.at("frames").get<std::string>());
    plan.chunk = j.at("chunk").get<uint32_t>();
    plan.renderOptions = j.at("render_options").get<std::vector<std::string>>();
    if (plan.chunk == 0) throw std::runtime_error("chunk is 0");
    return plan;
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": not a farm plan snell can read: " + e.what());
  }
}

FarmCheck checkFarm(const FarmPlan& plan, const std::string& job, const std::vector<size_t>& tasks) {
  FarmCheck check;
  check.missing = plan.missingFrames();
  check.written = plan.frames.size() - check.missing.size();
  io::Json taskList = io::Json::array();
  for (size_t t : tasks) {
    TaskOutcome outcome{t, plan.taskFrames(t), readStatus(plan.statusPath(job, t)), plan.logPath(job, t)};
    if (outcome.exitCode != 0) check.failed.push_back(outcome);
    taskList.push_back({{"task", t},
                        {"frames", outcome.frames.text},
                        {"exit_code", outcome.exitCode < 0 ? io::Json() : io::Json(outcome.exitCode)},
                        {"log", outcome.log}});
  }

  // What the frames' own records say: time spent, and on which devices.
  double renderMs = 0.0;
  std::map<std::string, size_t> devices;
  for (long f : plan.frames.frames) {
    std::ifstream in(framePath(plan.statsPattern(), f));
    if (!in) continue;
    io::Json stats = io::Json::parse(in, nullptr, false);
    if (stats.is_discarded() || !stats.is_object()) continue;
    renderMs += stats.value("frame_ms", 0.0);
    if (stats.contains("device") && stats["device"].is_object()) ++devices[stats["device"].value("name", "?")];
  }

  const std::string name = plan.name();
  if (check.ok()) {
    check.message = name + ": all " + std::to_string(plan.frames.size()) + " frames written (" + plan.frames.text + ")";
  } else {
    check.message = name + ": " + std::to_string(check.written) + " of " + std::to_string(plan.frames.size()) +
                    " frames written";
    if (!check.missing.empty()) check.message += "; missing frames " + listOf(check.missing).text;
    for (const TaskOutcome& t : check.failed) {
      check.message += "; task " + std::to_string(t.task) + " (frames " + t.frames.text + ") " +
                       (t.exitCode < 0 ? std::string("did not finish (cancelled, out of time or its node lost)")
                                       : "exited " + std::to_string(t.exitCode)) +
                       ", log " + t.log;
    }
  }

  io::Json& j = check.summary;
  j = io::reportHead("farm-summary", nullptr);
  j["shot"] = name;
  j["output"] = plan.output;
  j["frames"] = plan.frames.text;
  j["job"] = job.empty() ? io::Json() : io::Json(job);
  j["ok"] = check.ok();
  j["frames_asked"] = plan.frames.size();
  j["frames_written"] = check.written;
  j["missing"] = check.missing;
  j["tasks"] = taskList;
  j["failed_tasks"] = check.failed.size();
  j["render_seconds"] = renderMs / 1000.0;
  io::Json deviceCounts = io::Json::object();
  for (const auto& [device, count] : devices) deviceCounts[device] = count;
  j["frames_by_device"] = deviceCounts;
  j["message"] = check.message;
  return check;
}

std::string arrayList(const std::vector<size_t>& indices) {
  std::string out;
  for (size_t i = 0; i < indices.size();) {
    size_t j = i + 1;
    while (j < indices.size() && indices[j] == indices[j - 1] + 1) ++j;
    out += (out.empty() ? "" : ",") + std::to_string(indices[i]);
    if (j - i > 1) out += "-" + std::to_string(indices[j - 1]);
    i = j;
  }
  return out;
}

}  // namespace snell::farm
