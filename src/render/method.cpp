#include "render/method.h"

#include <algorithm>
#include <cstdio>

namespace snell::render {

const std::vector<MethodInfo>& methods() {
  static const std::vector<MethodInfo> all = {
      {Method::Trace, "trace", "traced, every pixel, refracting at every interface"},
      {Method::TraceOnce, "trace-1", "traced, refracting at the first interface only"},
      {Method::Masked, "masked", "viewport: raster, glass pixels traced"},
      {Method::IrisPlane, "iris-plane", "viewport: refracted once onto the plane behind the glass, no trace"},
      {Method::NormalOffset, "normal-offset", "viewport: picture behind the glass offset by the normal, no trace"},
      {Method::RefractionMap, "refraction-map", "viewport: a refraction map baked at another pose, no trace"},
      {Method::None, "none", "viewport: glass seen straight through"},
      {Method::DriverRt, "driver-rt", "traced like trace, hits from the driver's ray tracing pipeline (the peer)"},
  };
  return all;
}

const char* methodName(Method method) {
  for (const MethodInfo& m : methods()) {
    if (m.method == method) return m.name;
  }
  return "?";
}

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

bool drawsComposite(Method method) {
  return method != Method::Trace && method != Method::TraceOnce && method != Method::DriverRt;
}

ViewRequest methodView(Method method, const FrameSettings& settings, const RasterOptions& raster) {
  ViewRequest view;
  view.settings = settings;
  view.raster = raster;
  view.raster.screenSpace = ScreenSpace::Off;
  switch (method) {
    case Method::Trace: break;
    case Method::DriverRt: view.driverTrace = true; break;
    case Method::TraceOnce: view.settings.maxBends = 1; break;
    case Method::Masked: view.output = ViewOutput::Composite; break;
    case Method::IrisPlane:
      view.output = ViewOutput::Composite;
      view.raster.screenSpace = ScreenSpace::IrisPlane;
      break;
    case Method::NormalOffset:
      view.output = ViewOutput::Composite;
      view.raster.screenSpace = ScreenSpace::NormalOffset;
      break;
    case Method::RefractionMap:
      view.output = ViewOutput::Composite;
      view.raster.screenSpace = ScreenSpace::RefractionMap;
      break;
    case Method::None:
      view.output = ViewOutput::Composite;
      view.raster.refraction = false;
      break;
  }
  return view;
}

ViewRequest methodViewport(Method method, const FrameSettings& settings, const RasterOptions& raster) {
  ViewRequest view = methodView(method, settings, raster);
  if (method == Method::Trace || method == Method::TraceOnce || method == Method::DriverRt) {
    view.output = ViewOutput::Composite;
    view.masked = method == Method::TraceOnce;
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
  const char* pass = drawn == Method::DriverRt ? "driver trace" : "trace";
  for (const vk::PassTime& p : passes) {
    if (p.name == pass) (drawn == Method::DriverRt ? driverMs_ : traceMs_).push_back(p.milliseconds);
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

bool isRefractionPass(const std::string& passName) {
  return passName != "deform" && passName != "raster depth" && passName != "raster shading";
}

}  // namespace snell::render
