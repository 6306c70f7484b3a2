// How light leaves the glass, beyond the bend: Fresnel, the reflected rays
// and the environment they see (shaders/shared/trace.h states the rules).
// Both the GPU frame (render::FrameSettings) and the reference take one.
#pragma once

#include "shared/trace.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace snell::scene {

/// An equirectangular environment: linear RGB, row 0 looking up (+Y), the
/// middle column looking down -Z.
struct Environment {
  std::string source;  ///< the file it came from, for messages
  uint32_t width = 0, height = 0;
  std::vector<glm::vec3> texels;  ///< width * height
};

/// A small HDR sky for tests and benchmarks: blue above, grey ground below,
/// and a sun 40 times brighter than the sky, low in front (+Z, up, right), so
/// the reflected rays carry a catch light of their own. `width` x width/2 texels.
Environment proceduralSky(uint32_t width = 1024);

/// The widest environment the trace keeps: a wider one is halved until it fits.
inline constexpr uint32_t kMaxEnvironmentWidth = 4096;
/// Makes an environment ready to draw, whoever decoded it (a file, a host's
/// pixels): throws std::runtime_error naming its source where its texels do
/// not fill its size or one is negative or not finite, then box-filters it
/// to half its size until it is at most kMaxEnvironmentWidth texels wide.
void fitEnvironment(Environment& env);

struct Optics {
  bool fresnel = true;  ///< R and T at every boundary, the reflected ray and the lights' highlights
  uint32_t reflections = gpu::kDefaultReflections;  ///< boundaries per path that send a reflected ray
  std::shared_ptr<const Environment> environment;  ///< null: the studio gradient
  /// Traced rays read textures at their cone's level of detail (trace.h:
  /// Textures); false reads level 0 everywhere, what the filtering is measured
  /// against (the raster pass filters either way).
  bool textureLod = true;
  bool dispersion = true;  ///< dispersive materials split the colours (off: none does)
  bool volume = true;      ///< volumes attenuate (off: every material is thin-walled)
  friend bool operator==(const Optics&, const Optics&) = default;
};

}  // namespace snell::scene
