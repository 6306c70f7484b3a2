// Mirrors shaders/common/optics.glsl: trace.h's Fresnel, media and environment rules written
// twice, here in double and there in float, so each checks the other.
#include "ref/optics.h"

#include "ref/shading.h"

#include <algorithm>
#include <cmath>

namespace snell::ref::detail {

double fresnelReflectance(double eta, double c) {
  double k = 1.0 - eta * eta * (1.0 - c * c);
  if (k < 0.0) return 1.0;
  double ct = std::sqrt(k);
  double rs = (eta * c - ct) / (eta * c + ct), rp = (eta * ct - c) / (eta * ct + c);
  return 0.5 * (rs * rs + rp * rp);
}

double fresnelTransmittance(double eta, double c) {
  double k = 1.0 - eta * eta * (1.0 - c * c);
  if (k < 0.0) return 0.0;
  double ct = std::sqrt(k);
  double ts = 2.0 * eta * c / (eta * c + ct), tp = 2.0 * eta * c / (eta * ct + c);
  return (ct / (eta * c)) * 0.5 * (ts * ts + tp * tp);
}

double channelIor(double ior, double dispersion, int channel) {
  if (channel < 0 || channel == 1 || dispersion <= 0.0) return ior;
  double spread = 0.025 * dispersion * (ior - 1.0);
  return channel == 0 ? ior - spread : ior + spread;
}

namespace {

glm::dvec3 studioGradient(const glm::dvec3& d) {
  const glm::dvec3 ground(gpu::kStudioGround[0], gpu::kStudioGround[1], gpu::kStudioGround[2]);
  const glm::dvec3 horizon(gpu::kStudioHorizon[0], gpu::kStudioHorizon[1], gpu::kStudioHorizon[2]);
  const glm::dvec3 zenith(gpu::kStudioZenith[0], gpu::kStudioZenith[1], gpu::kStudioZenith[2]);
  return d.y >= 0.0 ? glm::mix(horizon, zenith, d.y) : glm::mix(horizon, ground, std::min(1.0, -4.0 * d.y));
}

}  // namespace

glm::dvec3 environmentColor(const scene::Optics& optics, const glm::dvec3& d) {
  if (!optics.environment) return studioGradient(d);
  const scene::Environment& env = *optics.environment;
  const int64_t w = env.width, h = env.height;
  double u = 0.5 + std::atan2(d.x, -d.z) / (2.0 * kPi), v = std::acos(std::clamp(d.y, -1.0, 1.0)) / kPi;
  double x = u * double(w) - 0.5, y = v * double(h) - 0.5;
  int64_t x0 = floorIndex(x), y0 = floorIndex(y);
  double fx = x - double(x0), fy = y - double(y0);
  auto texel = [&](int64_t tx, int64_t ty) {
    tx = ((tx % w) + w) % w;
    ty = std::clamp<int64_t>(ty, 0, h - 1);
    return glm::dvec3(env.texels[size_t(ty * w + tx)]);
  };
  glm::dvec3 top = glm::mix(texel(x0, y0), texel(x0 + 1, y0), fx);
  glm::dvec3 bottom = glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), fx);
  return glm::mix(top, bottom, fy);
}

glm::dvec3 highlight(const PreparedScene& prepared, const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& d,
                     double roughness, double eta) {
  const glm::dvec3 v = -d;
  const double a = std::max(roughness * roughness, double(gpu::kMinAlpha)), a2 = a * a;
  const double nv = std::max(glm::dot(n, v), 1e-4);
  glm::dvec3 sum(0.0);
  for (const ResolvedLight& light : prepared.lights()) {
    glm::dvec3 l, e;
    if (!lightAt(light, p, l, e) || !(glm::dot(n, l) > 0.0)) continue;
    glm::dvec3 h = glm::normalize(l + v);
    double nh = glm::dot(n, h), vh = glm::dot(v, h);
    if (!(nh > 0.0) || !(vh > 0.0)) continue;
    double dd = nh * nh * (a2 - 1.0) + 1.0;
    sum += e * (a2 / (kPi * dd * dd)) * fresnelReflectance(eta, vh) / (4.0 * nv);
  }
  return sum;
}

}  // namespace snell::ref::detail
