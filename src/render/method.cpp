#include "render/method.h"

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

bool isRefractionPass(const std::string& passName) {
  return passName != "deform" && passName != "raster depth" && passName != "raster shading";
}

}  // namespace snell::render
