// Mirrors shaders/common/path.glsl: Tracer::path is tracePath and trace() is tracePixel, kept
// step for step alike so that a GPU-versus-CPU difference points at one rule.
#include "ref/path.h"

#include "ref/optics.h"

#include <algorithm>
#include <cmath>

namespace snell::ref::detail {

namespace {

// A secondary ray starts on the face it leaves; besides that face (excluded
// by id), it ignores hits closer than this fraction of the larger of its
// origin's magnitude and the scene's size, which is far above double
// rounding of the hit point (~1e-16 relative) and far below any feature.
constexpr double kSecondaryEpsilon = 1e-9;

struct Tracer {
  const PreparedScene& prepared;
  const ReferenceSettings& settings;

  double tMinFrom(const glm::dvec3& origin) const {
    return kSecondaryEpsilon * std::max(maxAbs(origin), prepared.size());
  }

  double surfaceIor(const ResolvedMaterial& m, const TriangleData& tri, const SurfacePoint& at, int channel) const {
    double ior = m.baseIor;
    if (m.ior.texture) ior = std::max(1.0, ior + m.iorOffset + m.iorScale * textureColor(m.ior, tri, at, false).r);
    return channelIor(ior, m.dispersion, channel);
  }

  double mediumIor(int material, int channel) const {
    const ResolvedMaterial& m = prepared.material(material);
    return channelIor(m.baseIor, m.dispersion, channel);
  }

  /// The point a hit lands on and its shading normal, turned to the
  /// geometric normal's side (the geometric normal where the shading one is 0).
  static void surfaceAt(const TriangleData& tri, double b0, double b1, double b2, glm::dvec3& p, glm::dvec3& ns) {
    p = b0 * tri.v[0] + b1 * tri.v[1] + b2 * tri.v[2];
    ns = unitOrZero(b0 * tri.n[0] + b1 * tri.n[1] + b2 * tri.n[2]);
    if (ns == glm::dvec3(0.0)) ns = tri.ng;
    if (glm::dot(ns, tri.ng) < 0.0) ns = -ns;
  }

  /// Where a ray meets `tri`: its weights and level of detail terms (level 0 with Optics::textureLod off).
  SurfacePoint pointOf(const Hit& hit, const TriangleData& tri, double width, double spread, const glm::dvec3& d) const {
    SurfacePoint at{1.0 - hit.b1 - hit.b2, hit.b1, hit.b2, glm::dvec2(-kInfinity)};  // off: level 0
    if (settings.optics.textureLod) at.lods = coneLods(tri, width + spread * hit.t, d);
    return at;
  }

  /// What a reflected ray from p, its cone `width` wide there and opening by
  /// `spread`, sees: the opaque face it meets, else the environment.
  /// `shortest`: the shortest segment so far (PixelResult::shortestSegment), this one included.
  glm::dvec3 reflected(const glm::dvec3& p, const glm::dvec3& d, uint32_t from, double width, double spread,
                       double& shortest) const {
    Hit hit = prepared.intersect(p, d, tMinFrom(p), from);
    shortest = std::min(shortest, hit.found() ? hit.t : kInfinity);
    if (hit.found()) {
      const TriangleData& tri = prepared.triangle(hit.triangle);
      const ResolvedMaterial& m = prepared.material(tri.material);
      if (!m.refractive) {  // alpha is not looked at: an opaque face is shaded whole (trace.h: Alpha)
        const SurfacePoint at = pointOf(hit, tri, width, spread, d);
        glm::dvec3 q, ns;
        surfaceAt(tri, at.b0, at.b1, at.b2, q, ns);
        ns = normalMapped(m, tri, at, ns);
        return shadeOpaque(prepared, q, ns, d, m.baseFactor * textureColor(m.base, tri, at),
                           m.emissiveFactor * textureColor(m.emissive, tri, at));
      }
    }
    return environmentColor(settings.optics, d);
  }

  /// One path for `channel` (0-2, or -1: every channel at the base IOR).
  /// With channel -1, returns false at the first dispersive boundary: the
  /// caller traces the pixel once per channel.
  /// The ray's cone (trace.h: Textures) is `width` wide at the origin and opens by `spread`.
  bool path(glm::dvec3 origin, glm::dvec3 d, double width, double spread, int channel, PixelResult& result) const {
    result = PixelResult{};
    const bool fresnel = settings.optics.fresnel;
    uint32_t reflections = fresnel ? settings.optics.reflections : 0u;
    glm::dvec3 throughput(1.0);
    Media media;
    double tMin = 0.0;  // primary rays: any t > 0
    uint32_t excluded = std::numeric_limits<uint32_t>::max();
    for (bool primary = true;; primary = false) {
      Hit hit = prepared.intersect(origin, d, tMin, excluded);
      if (!primary) result.shortestSegment = std::min(result.shortestSegment, hit.found() ? hit.t : kInfinity);
      if (!hit.found()) {
        result.color += throughput * settings.background;
        result.outcome = gpu::kOutcomeMiss;
        return true;
      }
      const int inside = media.current(prepared);
      if (inside >= 0 && settings.optics.volume) {  // Beer-Lambert over the segment
        const ResolvedMaterial& volume = prepared.material(media.material[inside]);
        if (volume.attenuationDistance > 0.0) {
          for (int c = 0; c < 3; ++c) throughput[c] *= std::pow(volume.attenuationColor[c], hit.t / volume.attenuationDistance);
        }
      }
      const TriangleData& tri = prepared.triangle(hit.triangle);
      if (primary) {
        result.distance = hit.t;
        result.instance = tri.item;
        result.primitive = tri.primitive;
      }
      const SurfacePoint here = pointOf(hit, tri, width, spread, d);
      width += spread * hit.t;  // the cone where it meets the face
      const glm::dvec3& ng = tri.ng;
      glm::dvec3 p, ns;
      surfaceAt(tri, here.b0, here.b1, here.b2, p, ns);

      const ResolvedMaterial& material = prepared.material(tri.material);
      ns = normalMapped(material, tri, here, ns);
      const glm::dvec4 baseTexel = textureRgba(material.base, tri, here);
      const glm::dvec3 base = material.baseFactor * glm::dvec3(baseTexel);
      const double coverage = material.refractive ? 1.0 : coverageOf(material, baseTexel.a);
      if (!material.refractive && coverage == 1.0) {
        if (result.interfaces > 0 && material.base.texture) result.landing = textureUv(material.base, tri, here);
        const glm::dvec3 emissive = material.emissiveFactor * textureColor(material.emissive, tri, here);
        result.color += throughput * shadeOpaque(prepared, p, ns, d, base, emissive);
        result.outcome = gpu::kOutcomeOpaque;
        return true;
      }
      if (result.interfaces >= settings.maxInterfaces) {
        result.color += throughput * settings.background;  // ends as a miss
        result.outcome = gpu::kOutcomeInterfaceLimit;
        return true;
      }
      if (!material.refractive) {  // a face partly there: its light in proportion, the rest goes on straight
        const glm::dvec3 emissive = material.emissiveFactor * textureColor(material.emissive, tri, here);
        result.color += throughput * coverage * shadeOpaque(prepared, p, ns, d, base, emissive);
        throughput *= 1.0 - coverage;
        ++result.interfaces;
        origin = p;
        excluded = hit.triangle;
        tMin = tMinFrom(origin);
        continue;
      }

      const bool entering = glm::dot(d, ng) < 0.0;
      bool boundary;  // a true boundary: the medium changes here
      double n1, n2;
      auto dispersive = [&](int other) {
        return settings.optics.dispersion &&
               (material.dispersion > 0.0 || (other >= 0 && prepared.material(media.material[other]).dispersion > 0.0));
      };
      if (entering) {
        boundary = inside < 0 || prepared.material(media.material[inside]).priority <= material.priority;
        if (boundary && channel < 0 && dispersive(inside)) return false;
        n1 = inside < 0 ? 1.0 : mediumIor(media.material[inside], channel);
        n2 = surfaceIor(material, tri, here, channel);
        media.enter(tri.material);
      } else {
        const int at = media.leave(tri.material);
        boundary = at < 0 || at == inside;
        const int outside = media.current(prepared);
        if (boundary && channel < 0 && dispersive(outside)) return false;
        n1 = surfaceIor(material, tri, here, channel);
        n2 = outside < 0 ? 1.0 : mediumIor(media.material[outside], channel);
      }
      const bool bends = boundary && result.interfaces < settings.maxBends;
      ++result.interfaces;
      if (bends) {
        glm::dvec3 n = entering ? ns : -ns;
        const double eta = n1 / n2;
        double c = -glm::dot(d, n);
        if (c <= 0.0) {
          n = entering ? ng : -ng;
          c = -glm::dot(d, n);
        }
        const double k = 1.0 - eta * eta * (1.0 - c * c);
        // How far the normal turns across the cone, > 0 where the surface bulges towards the ray.
        const double turn = (entering ? 1.0 : -1.0) * tri.curvature * width;
        glm::dvec3 next;
        if (k < 0.0) {
          next = d + 2.0 * c * n;  // total internal reflection keeps everything
          spread += 2.0 * turn;
        } else {
          const double r = fresnel ? fresnelReflectance(eta, c) : 0.0;
          if (fresnel) {
            result.energyError = std::max(result.energyError, std::abs(r + fresnelTransmittance(eta, c) - 1.0));
          }
          if (reflections > 0) {
            --reflections;
            if (r > 0.0) {
              result.color += throughput * (r * reflected(p, unitOrZero(d + 2.0 * c * n), hit.triangle, width,
                                                          spread + 2.0 * turn, result.shortestSegment) +
                                            highlight(prepared, p, n, d, material.roughness, eta));
            }
          }
          next = eta * d + (eta * c - std::sqrt(k)) * n;
          spread = eta * spread - (1.0 - eta) * turn;  // a surface that converges light narrows the cone
          throughput *= 1.0 - r;
        }
        next = unitOrZero(next);
        if (next != glm::dvec3(0.0)) d = next;
      }
      if (boundary) throughput *= base;

      origin = p;
      excluded = hit.triangle;
      tMin = tMinFrom(origin);
    }
  }
};

}  // namespace

PixelResult trace(const PreparedScene& prepared, const glm::dvec3& origin, const glm::dvec3& d, double width,
                  double spread, const ReferenceSettings& settings) {
  const Tracer tracer{prepared, settings};
  PixelResult result;
  if (tracer.path(origin, d, width, spread, -1, result)) return result;
  PixelResult red, blue;
  tracer.path(origin, d, width, spread, 0, red);
  tracer.path(origin, d, width, spread, 1, result);
  tracer.path(origin, d, width, spread, 2, blue);
  result.color = {red.color.r, result.color.g, blue.color.b};
  result.energyError = std::max({red.energyError, result.energyError, blue.energyError});
  return result;
}

}  // namespace snell::ref::detail
