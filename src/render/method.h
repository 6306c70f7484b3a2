// The ways of drawing refraction a user can pick and compare: in
// `snell render --method`, the viewer's drop-down and `snell bench methods`.
// Each is a real path through the Renderer, from the full trace to
// screen-space approximations that build no tree at all.
#pragma once

#include "render/raster_pass.h"
#include "render/renderer.h"

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace snell::render {

enum class Method {
  Trace,         ///< every pixel traced through up to maxInterfaces crossings
  TraceOnce,     ///< traced, bending at the first interface only (the talk's shader)
  Masked,        ///< the viewport: raster, and the trace of the glass pixels alone
  IrisPlane,     ///< raster: refracted once, met with the plane behind the glass (game engines' eyes)
  NormalOffset,  ///< raster: the picture behind the glass displaced by the normal (GPU Gems 2, ch. 19)
  RefractionMap, ///< raster: a refraction map baked by the trace at another pose, the texture behind read where it says (Sky)
  None,          ///< raster, glass seen straight through
  DriverRt,      ///< traced like `trace`, the hits found by the driver's own ray tracing (the peer)
};

struct MethodInfo {
  Method method;
  const char* name;     ///< as typed on the command line
  const char* summary;  ///< one line for --help and charts
};

/// Every method, cheapest last; driver-rt, the peer, after them.
const std::vector<MethodInfo>& methods();
const char* methodName(Method method);
std::optional<Method> methodFromName(std::string_view name);
/// "trace, trace-1, ..." for messages.
std::string methodNames();

/// Whether the method needs the driver's ray tracing (vk::ContextDesc::driverRayTracing).
inline bool needsDriverRayTracing(Method method) { return method == Method::DriverRt; }

/// Whether the method's image is the viewport composite (raster) rather than the trace image.
bool drawsComposite(Method method);

/// The view that draws `settings` with `method`. `raster` carries the
/// composite's depth range and options (fitDepthRange) and, for
/// refraction-map, the baked map; the method sets the rest.
ViewRequest methodView(Method method, const FrameSettings& settings, const RasterOptions& raster);

/// The same, always as the viewport composite (the viewer's): `trace` traces
/// every pixel under the raster, `trace-1` the glass pixels with one bend.
ViewRequest methodViewport(Method method, const FrameSettings& settings, const RasterOptions& raster);

/// The passes that draw refraction, as opposed to those every viewport pays
/// (deform, the raster pass's own depth and shading). The one list every
/// benchmark sums; bench frame and bench scale add deform to it.
bool isRefractionPass(const std::string& passName);

}  // namespace snell::render
