#include "render/method.h"

#include "render/pass_names.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

namespace snell::render {

const std::vector<MethodInfo>& methods() {
  static const std::vector<MethodInfo> all = {
      {.method = Method::Trace,
       .name = "trace",
       .summary = "traced, every pixel, refracting at every interface",
       .output = ViewOutput::Trace,
       .viewportMasked = false},
      {.method = Method::TraceOnce,
       .name = "trace-1",
       .summary = "traced, refracting at the first interface only",
       .output = ViewOutput::Trace,
       .maxBends = 1},
      {.method = Method::Masked, .name = "masked", .summary = "viewport: raster, glass pixels traced"},
      {.method = Method::IrisPlane,
       .name = "iris-plane",
       .summary = "viewport: refracted once onto the plane behind the glass, no trace",
       .screenSpace = ScreenSpace::IrisPlane},
      {.method = Method::NormalOffset,
       .name = "normal-offset",
       .summary = "viewport: picture behind the glass offset by the normal, no trace",
       .screenSpace = ScreenSpace::NormalOffset},
      {.method = Method::RefractionMap,
       .name = "refraction-map",
       .summary = "viewport: a refraction map baked at another pose, no trace",
       .screenSpace = ScreenSpace::RefractionMap},
      {.method = Method::None, .name = "none", .summary = "viewport: glass seen straight through", .refraction = false},
      {.method = Method::DriverRt,
       .name = "driver-rt",
       .summary = "traced like trace, hits from the driver's ray tracing pipeline (the peer)",
       .output = ViewOutput::Trace,
       .driverTrace = true,
       .viewportMasked = false},
  };
  return all;
}

const MethodInfo& methodInfo(Method method) {
  for (const MethodInfo& m : methods()) {
    if (m.method == method) return m;
  }
  throw std::invalid_argument("no method " + std::to_string(int(method)));
}

const char* methodName(Method method) { return methodInfo(method).name; }

std::optional<Method> methodFromName(std::string_view name) {
  for (const MethodInfo& m : methods()) {
    if (name == m.name) return m.method;
  }
  return std::nullopt;
}

std::string methodNames() {
  std::string names;
  for (const MethodInfo& m : methods()) names += (names.empty() ? "" : ", ") + std::string(m.name);
  return names;
}

std::string methodHelp(const std::vector<std::pair<std::string, std::string>>& first) {
  std::vector<std::pair<std::string, std::string>> lines = first;
  for (const MethodInfo& m : methods()) lines.emplace_back(m.name, m.summary);
  size_t width = 0;
  for (const auto& [name, summary] : lines) width = std::max(width, name.size());
  std::string help;
  for (const auto& [name, summary] : lines) help += "  " + name + std::string(width + 2 - name.size(), ' ') + summary + "\n";
  return help;
}

bool drawsComposite(Method method) { return methodInfo(method).output == ViewOutput::Composite; }

ViewRequest methodView(Method method, const FrameSettings& settings, const RasterOptions& raster) {
  const MethodInfo& m = methodInfo(method);
  ViewRequest view;
  view.settings = settings;
  view.raster = raster;
  view.output = m.output;
  view.raster.screenSpace = m.screenSpace;
  if (!m.refraction) view.raster.refraction = false;
  if (m.maxBends) view.settings.maxBends = m.maxBends;
  view.driverTrace = m.driverTrace;
  return view;
}

ViewRequest methodViewport(Method method, const FrameSettings& settings, const RasterOptions& raster) {
  ViewRequest view = methodView(method, settings, raster);
  const MethodInfo& m = methodInfo(method);
  if (m.output == ViewOutput::Trace) {
    view.output = ViewOutput::Composite;
    view.masked = m.viewportMasked;
  }
  return view;
}

AutoMethod::AutoMethod(bool driverRayTracing, bool viewport, uint64_t frames) {
  if (viewport) {
    chosen_ = Method::Masked;
    why_ = "a viewport traces only its glass pixels, which the driver's ray tracing cannot";
  } else if (!driverRayTracing) {
    chosen_ = Method::Trace;
    why_ = "the device has no ray tracing pipelines to compare with";
  } else if (frames < uint64_t(4 * (kTrials + 1))) {
    chosen_ = Method::Trace;
    why_ = "too few frames to time the driver's ray tracing against";
  }
}

Method AutoMethod::next() const {
  if (chosen_) return *chosen_;
  return traceMs_.size() <= driverMs_.size() ? Method::Trace : Method::DriverRt;
}

void AutoMethod::note(Method drawn, const std::vector<vk::PassTime>& passes) {
  if (chosen_) return;
  const char* timed = drawn == Method::DriverRt ? pass::kDriverTrace : pass::kTrace;
  for (const vk::PassTime& p : passes) {
    if (p.name == timed) (drawn == Method::DriverRt ? driverMs_ : traceMs_).push_back(p.milliseconds);
  }
  // Each method's first frame warms its caches (12 ms against 2 ms after, on the H100): it does not count.
  if (int(traceMs_.size()) < kTrials + 1 || int(driverMs_.size()) < kTrials + 1) return;
  auto median = [](std::vector<double> v) {
    v.erase(v.begin());
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  double trace = median(traceMs_), driver = median(driverMs_);
  chosen_ = driver < trace ? Method::DriverRt : Method::Trace;
  char line[160];
  std::snprintf(line, sizeof line, "median of %d frames each: trace %.3f ms, driver-rt %.3f ms", kTrials, trace, driver);
  why_ = line;
}

std::string AutoMethod::describe() const {
  if (!chosen_) return "auto: timing trace against driver-rt";
  return std::string("auto: ") + methodName(*chosen_) + " (" + why_ + ")";
}

MethodChoice::MethodChoice(const std::string& name, bool driverRayTracing, bool viewport, uint64_t frames)
    : name_(name), viewport_(viewport) {
  if (name == "auto") {
    chooser_.emplace(driverRayTracing, viewport, frames);
    return;
  }
  fixed_ = methodFromName(name);
  if (!fixed_) throw std::invalid_argument("no method '" + name + "' (the methods: auto, " + methodNames() + ")");
  if (needsDriverRayTracing(*fixed_) && !driverRayTracing) {
    throw std::invalid_argument("method " + name + " needs the driver's ray tracing (VK_KHR_ray_tracing_pipeline), "
                                "which this device or context does not offer");
  }
}

Method MethodChoice::next() const {
  Method m = chooser_ ? chooser_->next() : *fixed_;
  const bool viewport = viewport_ || drawsComposite(m);
  if (viewport && (m == Method::Trace || m == Method::DriverRt)) m = Method::Masked;
  return m;
}

ViewRequest MethodChoice::view(Method method, const FrameSettings& settings, const RasterOptions& raster) const {
  ViewRequest view = viewport_ ? methodViewport(method, settings, raster) : methodView(method, settings, raster);
  if (settings.transparentBackground && view.output == ViewOutput::Composite) {
    view.settings.background = glm::vec3(0.0f);
    view.settings.backgroundAlpha = 0.0f;
  }
  return view;
}

void MethodChoice::note(Method drawn, const std::vector<vk::PassTime>& passes) {
  if (chooser_) chooser_->note(drawn, passes);
}

std::string MethodChoice::describe() const {
  if (chooser_) return chooser_->describe();
  const MethodInfo& m = methodInfo(next());
  return std::string(m.name) + ": " + m.summary;
}

bool isRefractionPass(const std::string& passName) {
  return passName != pass::kDeform && passName != pass::kRasterDepth && passName != pass::kRasterShading;
}

}  // namespace snell::render
