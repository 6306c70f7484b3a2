// What a run records and writes: a record per finished frame (its CPU time,
// GPU passes and what the renderer did), memory samples around scene
// switches, the summary printed at the end and the --json report (the
// "snell.view/1" head of io::reportHead, then the medians), and
// screenshots: --screenshot's file and the screenshot key's timestamped ones.
#include "viewer_state.h"

#include "io/environment.h"
#include "io/image_file.h"
#include "io/json.h"

#include <cstdio>
#include <ctime>
#include <exception>
#include <filesystem>

namespace snell::viewer {

void Viewer::noteFrame(const render::FrameResult& result, double cpuMs) {
  lastPasses_ = result.passes;
  lastStats_ = result.stats;
  FrameRecord record;
  record.cpuMs = cpuMs;
  record.stats = result.stats;
  for (const vk::PassTime& p : lastPasses_) record.gpuMs[p.name] += p.milliseconds;
  if (records_.size() == kKeptRecords) records_.pop_front();
  records_.push_back(record);
  ++framesDrawn_;
}

void Viewer::sampleMemory(uint64_t frame) {
  // The frames before are finished, so what they retired is freed first.
  if (pendingFrame_) noteFrame(renderer_->wait(pendingFrame_), pendingCpuMs_);
  pendingFrame_ = 0;
  context_->collectRetired();
  MemorySample s{frame, io::hostResidentBytes(), context_->memoryInUse(), scene_->source};
  memorySamples_.push_back(s);
  // tests/tools/viewer_soak.sh reads these lines.
  std::printf("memory at frame %llu (%s): host %.1f MiB resident, GPU %.1f MiB in use\n", (unsigned long long)frame,
              s.scene.c_str(), double(s.hostBytes) / 1048576.0, double(s.deviceBytes) / 1048576.0);
}

// The medians of the frames kept (the first few skipped) on standard output,
// and with --json in a file.
void Viewer::report(double seconds) const {
  std::vector<double> cpu;
  std::map<std::string, std::vector<double>> gpu;
  std::vector<double> gpuTotal, pixels, dispatches;
  uint64_t deformed = 0, refit = 0, rebuilt = 0, viewsDrawn = 0, viewsKept = 0;
  // The first frames build the tree and warm caches: the medians skip them.
  size_t skip = std::min<size_t>(records_.size() / 10, 10);
  for (size_t i = skip; i < records_.size(); ++i) {
    const render::FrameStats& st = records_[i].stats;
    pixels.push_back(double(st.pixelsTraced));
    dispatches.push_back(st.dispatches);
    deformed += st.itemsDeformed;
    refit += st.treesRefit;
    rebuilt += st.treesBuilt;
    viewsDrawn += st.viewsRendered;
    viewsKept += st.viewsSkipped;
    cpu.push_back(records_[i].cpuMs);
    double total = 0;
    for (const auto& [name, ms] : records_[i].gpuMs) {
      gpu[name].push_back(ms);
      total += ms;
    }
    gpuTotal.push_back(total);
  }
  std::printf("\n%-12s %10s\n", "pass", "median ms");
  for (const auto& [name, v] : gpu) std::printf("%-12s %10.3f\n", name.c_str(), io::median(v));
  std::printf("%-12s %10.3f\n%-12s %10.3f\n", "GPU total", io::median(gpuTotal), "frame (CPU)", io::median(cpu));
  std::printf("over %zu frames: %llu items deformed, %llu trees refit, %llu rebuilt, views drawn %llu, kept %llu; "
              "median %.0f pixels traced, %.0f dispatches a frame\n",
              cpu.size(), static_cast<unsigned long long>(deformed), static_cast<unsigned long long>(refit),
              static_cast<unsigned long long>(rebuilt), static_cast<unsigned long long>(viewsDrawn),
              static_cast<unsigned long long>(viewsKept), io::median(pixels), io::median(dispatches));
  if (options_.json.empty()) return;

  io::Json j = io::reportHead("view", &context_->facts());
  j["scene"] = sceneName_;
  j["width"] = windowImage_.width();
  j["height"] = windowImage_.height();
  j["viewports"] = toggles_.split ? 2 : 1;
  j["refraction"] = toggles_.refraction;
  j["ui"] = toggles_.ui;
  j["frames"] = framesDrawn_;
  j["frames_in_medians"] = cpu.size();
  j["wall_seconds"] = seconds;
  j["median_frame_ms"] = io::median(cpu);
  j["median_gpu_total_ms"] = io::median(gpuTotal);
  j["items_deformed"] = deformed;
  j["trees_refit"] = refit;
  j["trees_rebuilt"] = rebuilt;
  j["views_drawn"] = viewsDrawn;
  j["views_kept"] = viewsKept;
  j["median_pixels_traced"] = io::median(pixels);
  j["median_dispatches"] = io::median(dispatches);
  io::Json passes = io::Json::object();
  for (const auto& [name, v] : gpu) passes[name] = io::median(v);
  j["median_pass_ms"] = passes;
  io::Json samples = io::Json::array();
  for (const MemorySample& m : memorySamples_) {
    samples.push_back(io::Json{{"frame", m.frame},
                               {"scene", m.scene},
                               {"host_resident_bytes", m.hostBytes},
                               {"device_bytes", m.deviceBytes}});
  }
  j["memory_samples"] = samples;
  io::writeJson(options_.json, j);
  std::printf("wrote %s\n", options_.json.c_str());
}

void Viewer::writeScreenshot(const std::string& path) const {
  io::Rgb8Image image{windowImage_.width(), windowImage_.height(), {}};
  size_t pixels = size_t(image.width) * image.height;
  image.rgb.resize(pixels * 3);
  const auto* rgba = reinterpret_cast<const uint8_t*>(screenshotBuffer_.mapped().data());
  for (size_t i = 0; i < pixels; ++i) {
    for (int c = 0; c < 3; ++c) image.rgb[3 * i + size_t(c)] = rgba[4 * i + size_t(c)];
  }
  io::writeRgb8(path, image);  // complete or not at all
  std::printf("wrote %s: %ux%u\n", path.c_str(), image.width, image.height);
}

namespace {

// snell-view-YYYYMMDD-HHMMSS.png in the current folder, local time; -2, -3...
// after it when that second already has one.
std::string screenshotName() {
  std::time_t now = std::time(nullptr);
  std::tm local{};
  localtime_r(&now, &local);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &local);
  std::string name = std::string("snell-view-") + stamp + ".png";
  for (int n = 2; std::filesystem::exists(name) && n < 1000; ++n) {
    name = std::string("snell-view-") + stamp + "-" + std::to_string(n) + ".png";
  }
  return name;
}

}  // namespace

void Viewer::saveScreenshot() {
  std::string name = screenshotName();
  try {
    writeScreenshot(name);
    notify("saved " + name);
  } catch (const std::exception& e) {
    // A full disk or a read-only folder: said, and the viewer goes on.
    message_ = std::string("screenshot not saved: ") + e.what();
    notify("screenshot not saved (see the overlay or the terminal)");
    std::fprintf(stderr, "snell-view: screenshot not saved: %s\n", e.what());
  }
}

}  // namespace snell::viewer
