// Mirrors shaders/common/optics.glsl: Fresnel, per-channel IOR, nested media, the GGX highlight
// and the environment, in double, so that the GPU's optics have an independent ground truth.
#pragma once

#include "ref/prepared_scene.h"
#include "scene/optics.h"
#include "shared/trace.h"

#include <glm/glm.hpp>

#include <cstdint>

namespace snell::ref::detail {

/// Unpolarised dielectric reflectance for cosine c > 0 and eta = n1 / n2; 1 past the critical angle.
double fresnelReflectance(double eta, double c);

/// The transmittance from the transmission amplitudes ts, tp (Born & Wolf),
/// written apart from 1 - R so that R + T = 1 is a check, not an identity.
double fresnelTransmittance(double eta, double c);

double channelIor(double ior, double dispersion, int channel);

/// The media a ray is inside (shared/trace.h: nested dielectrics).
struct Media {
  int material[gpu::kMaxMedia] = {};
  uint32_t count = 0;

  int current(const PreparedScene& prepared) const {
    int best = -1;
    for (uint32_t i = 0; i < count; ++i) {
      if (best < 0 || prepared.material(material[i]).priority >= prepared.material(material[best]).priority) best = int(i);
    }
    return best;
  }
  void enter(int m) {
    if (count == gpu::kMaxMedia) {
      for (uint32_t i = 1; i < gpu::kMaxMedia; ++i) material[i - 1] = material[i];
      --count;
    }
    material[count++] = m;
  }
  int leave(int m) {
    int at = -1;
    for (uint32_t i = 0; i < count; ++i) {
      if (material[i] == m) at = int(i);
    }
    if (at < 0) return -1;
    for (uint32_t i = uint32_t(at) + 1; i < count; ++i) material[i - 1] = material[i];
    --count;
    return at;
  }
};

glm::dvec3 environmentColor(const scene::Optics& optics, const glm::dvec3& d);

/// Every light's GGX highlight on a boundary of normal n (the viewer's side).
glm::dvec3 highlight(const PreparedScene& prepared, const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& d,
                     double roughness, double eta);

}  // namespace snell::ref::detail
