// `snell bench shot`: a shot's frames over every GPU of the machine. The
// crowd of the procedural eye (default 100 characters) at 3840x2160 for 240
// frames, written as PNG or EXR to a local folder, rendered as `snell render
// --devices` renders it: first on one device, then on all of them, side by
// side in one run. It reports frames per second of each and the speed-up,
// each worker's frames, load, tree builds, GPU waits and writes, the host's
// peak memory, and whether the two runs wrote the same pixels.
#include "cli/commands.h"
#include "cli/render_shot.h"

#include "io/environment.h"
#include "io/image_file.h"
#include "io/json.h"
#include "scene/gltf_writer.h"
#include "scene/procedural_eye.h"
#include "vk/context.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

namespace snell::cli {

namespace {

namespace fs = std::filesystem;

struct Options {
  uint32_t crowd = 100, frames = 240, width = 3840, height = 2160;
  std::string devices = "all", format = "png", folder, json;
  bool keep = false;
};

// The host's peak resident memory since the last reset (VmHWM); the reset
// (clear_refs 5) lets each run report its own.
uint64_t peakResidentBytes() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stoull(line.substr(6)) * 1024;
  }
  return 0;
}
void resetPeakResident() { std::ofstream("/proc/self/clear_refs") << "5"; }

struct Run {
  std::string devices;
  render::ShotReport report;
  uint64_t peakBytes = 0;
  std::map<long, std::string> hashes;  // frame: image_hash
};

Run renderRun(const Options& o, const std::string& scenePath, const std::string& devices, const std::string& name) {
  fs::path folder = fs::path(o.folder) / name;
  fs::remove_all(folder);
  fs::create_directories(folder / "stats");
  RenderOptions r;
  r.shot.input = scenePath;
  r.shot.width = o.width;
  r.shot.height = o.height;
  r.output = (folder / ("shot.####." + o.format)).string();
  r.frames = FrameList::parse("--frames", "1-" + std::to_string(o.frames));
  r.statsJson = (folder / "stats/shot.####.json").string();
  r.devices = devices;
  r.method = render::Method::Trace;
  r.timePasses = true;
  Run run;
  run.devices = devices;
  resetPeakResident();
  int code = renderShot(r, &run.report);
  if (code != kExitOk) throw std::runtime_error("bench shot: the render on --devices " + devices + " exited " + std::to_string(code));
  run.peakBytes = peakResidentBytes();
  for (long f : r.frames->frames) {
    std::ifstream in(framePath(r.statsJson, f));
    io::Json stats = io::Json::parse(in, nullptr, false);
    if (stats.is_object()) run.hashes[f] = stats.value("image_hash", std::string());
  }
  if (!o.keep) fs::remove_all(folder);
  return run;
}

double framesPerSecond(const Run& run) {
  return run.report.seconds > 0 ? double(run.report.frames) / run.report.seconds : 0.0;
}

int runBench(Options& o) {
  if (o.format != "png" && o.format != "exr") throw UsageError{"bench shot: --format is png or exr, got '" + o.format + "'"};
  if (!o.json.empty()) io::checkWritable(o.json);
  if (o.folder.empty()) o.folder = (fs::temp_directory_path() / "snell-bench-shot").string();
  fs::create_directories(o.folder);
  std::string why;
  std::vector<uint32_t> all = vk::devicesForList(o.devices, io::deviceEnvironment(), why);
  std::string allList;
  for (uint32_t d : all) allList += (allList.empty() ? "" : ",") + std::to_string(d);

  scene::EyeOptions eye;
  eye.crowd = o.crowd;
  const std::string scenePath = (fs::path(o.folder) / "crowd.glb").string();
  scene::saveGltf(scene::makeEye(eye), scenePath);
  std::printf("bench shot: a crowd of %u at %ux%u, %u frames as %s into %s; devices %s (%s)\n", o.crowd, o.width,
              o.height, o.frames, o.format.c_str(), o.folder.c_str(), allList.c_str(), why.c_str());

  // Compiled pipelines in the cache for both runs: one small frame on each device first.
  {
    Options warm = o;
    warm.frames = uint32_t(all.size());
    warm.width = 64, warm.height = 36;
    renderRun(warm, scenePath, allList, "warm-up");
  }
  std::vector<Run> runs;
  runs.push_back(renderRun(o, scenePath, std::to_string(all.front()), "one-device"));
  if (all.size() > 1) runs.push_back(renderRun(o, scenePath, allList, "all-devices"));

  const double base = framesPerSecond(runs.front());
  std::printf("\n%-10s %7s %9s %9s %8s %12s\n", "devices", "frames", "seconds", "frames/s", "speed-up", "peak host");
  for (const Run& run : runs) {
    std::printf("%-10s %7zu %9.2f %9.2f %7.2fx %8llu MiB\n", run.devices.c_str(), run.report.frames,
                run.report.seconds, framesPerSecond(run), base > 0 ? framesPerSecond(run) / base : 0.0,
                static_cast<unsigned long long>(run.peakBytes >> 20));
    for (size_t k = 0; k < run.report.workers.size(); ++k) {
      const render::ShotWorker& w = run.report.workers[k];
      std::printf("  worker %zu %s: %zu frames, load %.2f s, trees %.1f ms on the GPU, GPU waits %.2f s, writes %.2f s\n",
                  k, w.device.c_str(), w.frames, w.loadSeconds, w.treeMs, w.gpuWaitSeconds, w.sinkSeconds);
    }
  }
  bool identical = runs.size() < 2 || runs[0].hashes == runs[1].hashes;
  if (runs.size() > 1) {
    std::printf("pixels of one device and of %zu devices: %s\n", all.size(), identical ? "identical" : "DIFFERENT");
  }

  if (!o.json.empty()) {
    vk::DeviceReport survey = vk::surveyDevices(std::to_string(all.front()), io::deviceEnvironment());
    io::Json j = io::reportHead("bench-shot", &survey.devices[all.front()]);
    j["crowd"] = o.crowd;
    j["width"] = o.width;
    j["height"] = o.height;
    j["frames"] = o.frames;
    j["format"] = o.format;
    io::Json list = io::Json::array();
    for (const Run& run : runs) {
      io::Json workers = io::Json::array();
      for (const render::ShotWorker& w : run.report.workers) {
        workers.push_back({{"device", w.device},
                           {"frames", w.frames},
                           {"load_seconds", w.loadSeconds},
                           {"tree_gpu_ms", w.treeMs},
                           {"gpu_wait_seconds", w.gpuWaitSeconds},
                           {"write_seconds", w.sinkSeconds},
                           {"frames_per_second", double(w.frames) / run.report.seconds}});
      }
      list.push_back({{"devices", run.devices},
                      {"frames_written", run.report.frames},
                      {"seconds", run.report.seconds},
                      {"frames_per_second", framesPerSecond(run)},
                      {"speed_up", base > 0 ? framesPerSecond(run) / base : 0.0},
                      {"peak_host_bytes", run.peakBytes},
                      {"workers", workers}});
    }
    j["runs"] = list;
    j["pixels_identical"] = identical;
    io::writeJson(o.json, j);
  }
  return identical ? kExitOk : kExitFailure;
}

}  // namespace

void addBenchShot(CLI::App& bench, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* sub = bench.add_subcommand("shot", "a shot's frames on one device, then on every device of the machine");
  describe(*sub,
           "Renders a shot as 'snell render --devices' does: the procedural eye's crowd\n"
           "(--crowd, 100 characters) at 3840x2160 for 240 frames, written to a local\n"
           "folder, on one device and then on every device --devices names, side by side.\n"
           "Reports frames per second and the speed-up, each worker's frames, load, GPU\n"
           "time building trees, GPU waits and writes, the host's peak memory, and\n"
           "whether both runs wrote the same pixels (exit 1 if not). A first small frame\n"
           "on each device fills the pipeline cache, so neither run pays compiles.");
  sub->footer(kHelpFooter);
  sub->add_option("--crowd", o->crowd, "characters in the crowd (default 100)")->type_name("N")->check(CLI::Range(1u, 10000u));
  sub->add_option("--frames", o->frames, "frames of the shot (default 240)")->type_name("N")->check(CLI::Range(1u, 100000u));
  addSize(*sub, "--size", o->width, o->height, "image size (default 3840x2160)");
  sub->add_option("--devices", o->devices, "the devices of the second run, as render --devices (default all)")
      ->type_name("LIST");
  sub->add_option("--format", o->format, "png or exr (default png)")->type_name("F");
  sub->add_option("--folder", o->folder, "where the frames are written (default $TMPDIR/snell-bench-shot)")
      ->type_name("DIR");
  sub->add_flag("--keep", o->keep, "keep the frames written (default: removed after each run)");
  sub->add_option("--json", o->json, "write the results as JSON to FILE")->type_name("FILE");
  sub->callback([o, &run] { run = [o] { return runBench(*o); }; });
}

}  // namespace snell::cli
