// The ways of drawing refraction a user can pick and compare: in
// `snell render --method`, the viewer's drop-down and `snell bench methods`.
// Each is a real path through the Renderer, from the full trace to
// screen-space approximations that build no tree at all.
#pragma once

#include "render/raster_pass.h"
#include "render/renderer.h"
#include "vk/commands.h"

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
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

/// A method is this one entry: what it is called, what --help says of it, and
/// the view it asks the Renderer for. Adding a method is adding an entry (and
/// its enumerator); methodView(), the commands' help and the viewer's
/// drop-down follow from the table.
struct MethodInfo {
  Method method;
  const char* name;     ///< as typed on the command line
  const char* summary;  ///< one line for --help and charts
  ViewOutput output = ViewOutput::Composite;     ///< whose image it is: the trace's, or the viewport's
  ScreenSpace screenSpace = ScreenSpace::Off;    ///< a composite's approximation instead of the trace
  bool refraction = true;                        ///< off: glass seen straight through
  uint32_t maxBends = 0;                         ///< bends before crossing straight; 0: as the settings say
  bool driverTrace = false;                      ///< hits from the driver's ray tracing (the peer)
  bool viewportMasked = true;                    ///< a traced method in the viewport: trace the glass pixels alone
};

/// Every method, cheapest last; driver-rt, the peer, after them.
const std::vector<MethodInfo>& methods();
const MethodInfo& methodInfo(Method method);
const char* methodName(Method method);
std::optional<Method> methodFromName(std::string_view name);
/// "trace, trace-1, ..." for messages.
std::string methodNames();
/// One line per method, "  NAME  summary", for the commands' --help; `first`
/// lines (a command's own choices, such as auto) come before, aligned with them.
std::string methodHelp(const std::vector<std::pair<std::string, std::string>>& first = {});

/// Whether the method needs the driver's ray tracing (vk::ContextDesc::driverRayTracing).
inline bool needsDriverRayTracing(Method method) { return methodInfo(method).driverTrace; }

/// Whether the method's image is the viewport composite (raster) rather than the trace image.
bool drawsComposite(Method method);

/// The view that draws `settings` with `method`. `raster` carries the
/// composite's options (its depth range only to override the Renderer's fit)
/// and, for refraction-map, the baked map; the method sets the rest.
ViewRequest methodView(Method method, const FrameSettings& settings, const RasterOptions& raster);

/// The same, always as the viewport composite (the viewer's): `trace` traces
/// every pixel under the raster, `trace-1` the glass pixels with one bend.
ViewRequest methodViewport(Method method, const FrameSettings& settings, const RasterOptions& raster);

/// --method auto: a full trace's hits from whichever of snell's trace and the
/// driver's ray tracing measures faster on this device. Without the
/// driver's ray tracing, or for a viewport (whose masked trace the driver
/// cannot draw), it is trace (masked for a viewport) from the start;
/// otherwise the first frames alternate between the two, and the median GPU
/// time of each one's trace pass over kTrials frames (after a first that
/// warms its caches) picks. The trace stays the
/// reference: on a tie it wins.
class AutoMethod {
 public:
  static constexpr int kTrials = 3;
  /// `frames`: how many frames the caller will draw (a short sequence is
  /// not worth the trials: trace).
  AutoMethod(bool driverRayTracing, bool viewport, uint64_t frames = UINT64_MAX);
  /// The method the next frame draws with.
  Method next() const;
  /// A frame drawn with `drawn` is done: its pass times count towards the choice.
  void note(Method drawn, const std::vector<vk::PassTime>& passes);
  bool decided() const { return chosen_.has_value(); }
  /// One line for --stats, progress and JSON: what auto draws with, and why.
  std::string describe() const;

 private:
  std::optional<Method> chosen_;
  std::string why_;
  std::vector<double> traceMs_, driverMs_;
};

/// A method as a caller names it (auto, or one of methods()) made into each
/// frame's method and view: the name checked, auto's timing, and a viewport's
/// substitution (a traced method shown as a viewport traces only its glass
/// pixels). The API, the CLI and the shots choose through it.
class MethodChoice {
 public:
  /// `viewport`: the caller shows the composite. Throws std::invalid_argument
  /// for an unknown name (listing the methods), or for a method that needs the
  /// driver's ray tracing on a context without it.
  MethodChoice(const std::string& name, bool driverRayTracing, bool viewport, uint64_t frames = UINT64_MAX);
  const std::string& name() const { return name_; }
  bool isAuto() const { return chooser_.has_value(); }
  bool viewport() const { return viewport_; }
  /// The method the next frame draws with.
  Method next() const;
  /// The view that draws `settings` with `method` (next()'s), as the caller
  /// shows it (a composite's background made transparent where asked).
  ViewRequest view(Method method, const FrameSettings& settings, const RasterOptions& raster) const;
  /// A frame drawn with `drawn` is done: auto hears its pass times.
  void note(Method drawn, const std::vector<vk::PassTime>& passes);
  /// What auto draws with and why, or the method and its summary.
  std::string describe() const;

 private:
  std::string name_;
  bool viewport_;
  std::optional<Method> fixed_;
  std::optional<AutoMethod> chooser_;
};

/// The passes that draw refraction, as opposed to those every viewport pays
/// (deform, the raster pass's own depth and shading). The one list every
/// benchmark sums; bench frame and bench scale add deform to it.
bool isRefractionPass(const std::string& passName);

}  // namespace snell::render
