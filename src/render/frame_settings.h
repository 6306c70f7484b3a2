// What one view of a frame looks like: its size, camera and background. The
// trace and the raster pass both draw from it.
#pragma once

#include "scene/optics.h"
#include "scene/view.h"
#include "shared/trace.h"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace snell::render {

/// The hit-replay ablation (`snell bench cost`): record each segment's closest
/// hit, then trace the same view again reading them instead of traversing.
enum class HitReplay : uint8_t { Off, Record, Replay };

struct FrameSettings {
  uint32_t width = 0, height = 0;
  scene::View view;
  glm::vec3 background{scene::kDefaultBackground};
  uint32_t maxInterfaces = gpu::kDefaultMaxInterfaces;
  /// Interfaces that bend the ray; past them it crosses glass straight
  /// (1: the talk's single bend towards the iris; 0: refraction off).
  uint32_t maxBends = gpu::kAllBends;
  /// When not empty: width * height primary rays in world space, pixel i
  /// (row-major) tracing rays[i] instead of the camera's ray through it.
  std::vector<scene::Ray> rays;
  /// Fresnel, reflected rays, highlights and the environment they see.
  scene::Optics optics;
  /// The composite's alpha where nothing is drawn (0: a host composites the image over its own).
  float backgroundAlpha = 1.0f;
  /// A host draws the picture over its own: where the picture is the
  /// composite, its background is 0 with alpha 0 (MethodChoice::view); the
  /// trace's image, which has no coverage to show it by, keeps the background.
  bool transparentBackground = false;
  /// Benchmarks only: a replay must follow a record of the same view and pose.
  HitReplay hitReplay = HitReplay::Off;
  friend bool operator==(const FrameSettings&, const FrameSettings&) = default;
};

}  // namespace snell::render
