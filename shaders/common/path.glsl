// What the trace pass and the driver's ray tracing pipeline share: the hit,
// the surface at a hit, the refraction rules of shared/trace.h and the whole
// path of one pixel. The scene binding set comes with common/scene.glsl; the
// including shader declares the trace's own bindings of trace.h
// (environment, outImage, aovs, rays) and the push constant `pc`, and
// defines traceClosest() and firstTriangleOf() after this file. An includer
// whose lanes share pixels defines SNELL_PIXEL_WRITER: the one lane that writes;
// one whose pixels are a subgroup's lanes may define SNELL_SUBGROUP_MAX and SNELL_SUBGROUP_SIZE.
#ifndef SNELL_PATH_GLSL
#define SNELL_PATH_GLSL
#ifndef SNELL_PIXEL_WRITER
#define SNELL_PIXEL_WRITER true
#endif
#ifndef SNELL_SUBGROUP_MAX
#define SNELL_SUBGROUP_MAX(v) 0u
#define SNELL_SUBGROUP_SIZE 0u
#endif

const float kInf = 1.0 / 0.0;  // folded to +infinity at compile time
// The largest finite float16. A colour beyond it is no colour that rgba16f
// holds: Vulkan lets a driver store it as the largest finite value
// (lavapipe) or infinity, and SwiftShader stored NaN (bench stress: scale:
// eye x 0.0001, whose point lights shine 10^8 times as bright at 10^-4 of
// the distance). Clamped here, every driver stores what lavapipe did.
const float kHalfMax = 65504.0;

// What the pipeline was specialised for (shared/trace.h: kTraceSpecOptics), and what this dispatch draws.
layout(constant_id = kTraceSpecOptics) const uint kSpecOptics = 0xffffffffu;
layout(constant_id = kTraceSpecFlags) const uint kSpecFlags = 0xffffffffu;
layout(constant_id = kTraceSpecSurface) const uint kSpecSurface = kSurfaceAll;
bool opticsOn(uint bit) { return (kSpecOptics & pc.optics & bit) != 0u; }
bool traceFlag(uint bit) { return (kSpecFlags & pc.flags & bit) != 0u; }
bool surfaceUses(uint bit) { return (kSpecSurface & bit) != 0u; }

uint visits;  // nodes visited by this pixel's whole path (the driver's pipeline cannot count them: 0)
uint boxTests, triangleTests;  // child boxes and triangles tested over the path (trace.comp counts them)
uint deadVisits, culledVisits, leafVisits;  // TraceAov's visits that found nothing, and leaves reached (trace.comp)
uint walkSteps, subgroupSteps, leafSteps;  // traversal and leaf loop passes this lane made, or led for its subgroup (trace.comp)
uint segments;  // closest-hit queries of the path so far
uint tracedPixel;  // row-major index of the pixel being traced

struct Hit {
  float t;
  uint instance;
  uint primitive;  // global triangle index
  vec3 bary;       // weights of v0, v1, v2
};

// The closest hit beyond |leaving| along the ray (leave() below; 0 for a
// camera ray), not on triangle skipPrim of instance skipInstance (the face
// the ray leaves); instance kNoHit on a miss.
Hit traceClosest(vec3 origin, vec3 dir, uint skipInstance, uint skipPrim, float leaving);
// The global index of the first triangle of the instance's geometry.
uint firstTriangleOf(uint instance);

#include "scene.glsl"
#include "shading.glsl"
#include "optics.glsl"

// ------------------------------------------------------------------ shading

// A miss's material (tracePath): no textures; never shaded, only a defined value.
const GpuTextureSlot kNoSlot = GpuTextureSlot(vec4(0.0), vec4(0.0), kNoTexture, 0u, 0.0, 0u);
const GpuMaterial kNoMaterial = GpuMaterial(vec4(0.0), vec4(0.0), vec4(0.0), 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, kNoSlot,
                                            kNoSlot, kNoSlot, kNoSlot, 1.0, 0.0, kAlphaOpaque, 0u);

struct Surface {
  vec3 position;  // camera-relative world space
  vec3 ng;        // geometric normal, unit
  vec3 ns;        // shading normal, unit, on ng's side
  vec4 uvs;
  vec2 density;   // uvDensity() of the triangle, per UV set
  vec2 lods;      // the level of detail of its textures (coneLod), once the ray's cone is known
  uint material;
};

Surface surfaceAt(Hit hit) {
  GpuInstance inst = instances[hit.instance];
  uvec3 i = triangleAt(hit.primitive);
  vec3 p0 = vertexAt(i.x), p1 = vertexAt(i.y), p2 = vertexAt(i.z);
  vec3 p = hit.bary.x * p0 + hit.bary.y * p1 + hit.bary.z * p2;
  vec3 ns = hit.bary.x * normalAt(i.x) + hit.bary.y * normalAt(i.y) + hit.bary.z * normalAt(i.z);
  vec3 ng = cross(p1 - p0, p2 - p0);
  mat3 toWorldNormal = normalToWorld(inst);
  Surface s;
  s.position = pointToWorld(inst, p);
  s.ng = normalize(toWorldNormal * ng);
  ns = toWorldNormal * ns;
  s.ns = dot(ns, ns) > 0.0 ? normalize(ns) : s.ng;
  if (dot(s.ns, s.ng) < 0.0) s.ns = -s.ns;
  vec4 uv0 = texcoords[i.x], uv1 = texcoords[i.y], uv2 = texcoords[i.z];
  s.uvs = hit.bary.x * uv0 + hit.bary.y * uv1 + hit.bary.z * uv2;
  s.density = uvDensity(vectorToWorld(inst, p1 - p0), vectorToWorld(inst, p2 - p0), uv0, uv1, uv2);
  s.lods = vec2(0.0);
  s.material = inst.material;
  return s;
}

// How the triangle's surface curves (trace.h: Textures), signed: the mean
// over its edges of dot(n_j - n_i, p_j - p_i) / |p_j - p_i|^2, its unit world
// vertex normals turned together to ng's side, so it is positive where the
// surface bulges towards ng's side; 0 without normals or with no edge.
float curvatureAt(Hit hit, vec3 ng) {
  GpuInstance inst = instances[hit.instance];
  uvec3 i = triangleAt(hit.primitive);
  mat3 toWorldNormal = normalToWorld(inst);
  vec3 n0 = toWorldNormal * normalAt(i.x), n1 = toWorldNormal * normalAt(i.y), n2 = toWorldNormal * normalAt(i.z);
  if (dot(n0, n0) == 0.0 || dot(n1, n1) == 0.0 || dot(n2, n2) == 0.0) return 0.0;
  n0 = normalize(n0), n1 = normalize(n1), n2 = normalize(n2);
  if (dot(n0 + n1 + n2, ng) < 0.0) n0 = -n0, n1 = -n1, n2 = -n2;
  vec3 p0 = vectorToWorld(inst, vertexAt(i.x)), p1 = vectorToWorld(inst, vertexAt(i.y)),
       p2 = vectorToWorld(inst, vertexAt(i.z));
  vec3 e01 = p1 - p0, e12 = p2 - p1, e20 = p0 - p2;
  vec3 lengths = vec3(dot(e01, e01), dot(e12, e12), dot(e20, e20));
  vec3 turns = vec3(dot(n1 - n0, e01), dot(n2 - n1, e12), dot(n0 - n2, e20));
  float sum = 0.0, edges = 0.0;
  for (int e = 0; e < 3; ++e) {
    if (lengths[e] > 0.0) sum += turns[e] / lengths[e], edges += 1.0;
  }
  float k = edges > 0.0 ? sum / edges : 0.0;
  return abs(k) < 1e30 ? k : 0.0;  // NaN and infinity: 0
}

// The shading normal at a hit bent by its material's normal map, whose texel
// (bytes / 255) was read at the hit (trace.h: Normal maps).
vec3 normalMappedAt(Hit hit, Surface s, GpuMaterial m, vec3 mapTexel) {
  GpuInstance inst = instances[hit.instance];
  uvec3 i = triangleAt(hit.primitive);
  vec3 p0 = vertexAt(i.x);
  vec3 t, b;
  if (!tangentFrame(vectorToWorld(inst, vertexAt(i.y) - p0), vectorToWorld(inst, vertexAt(i.z) - p0),
                    textureUv(m.normal, texcoords[i.x]), textureUv(m.normal, texcoords[i.y]),
                    textureUv(m.normal, texcoords[i.z]), t, b)) {
    return s.ns;
  }
  return normalMapped(s.ns, s.ng, t, b, mapTexel, m.normalScale);
}

// How much of an opaque face is there (trace.h: Alpha): 1 unless its
// material masks or blends by alpha, the factor's times the base texture's.
float coverageOf(GpuMaterial m, float textureAlpha) {
  float alpha = m.baseColorFactor.a * textureAlpha;
  if (m.alphaMode == kAlphaMask) return alpha >= m.alphaCutoff ? 1.0 : 0.0;
  if (m.alphaMode == kAlphaBlend) return clamp(alpha, 0.0, 1.0);
  return 1.0;
}

// Wächter & Binder (Ray Tracing Gems, ch. 6): move the point off the surface
// by a few ulps of its own magnitude (a fixed step near the origin, where ulps
// vanish). Their constants (256 ulps, 1/65536 below 1/32) assume metre-sized
// scenes; an eye is centimetres, where that shifted what the refracted ray saw
// by a visible fraction of an iris texel. The interpolated hit point is good
// to a few ulps, so 32 ulps still clears the surface.
vec3 offsetRay(vec3 p, vec3 n) {
  const float kOrigin = 1.0 / 1024.0, kFloatScale = 1.0 / 1048576.0, kIntScale = 32.0;
  ivec3 of = ivec3(kIntScale * n);
  vec3 pi = intBitsToFloat(floatBitsToInt(p) + mix(of, -of, lessThan(p, vec3(0.0))));
  return mix(pi, p + kFloatScale * n, lessThan(abs(p), vec3(kOrigin)));
}

// What one path of a pixel found.
struct Path {
  vec3 colour;
  uint interfaces;
  uint outcome;
  float firstDistance;
  uint firstInstance, firstPrimitive;
  vec2 landing;  // TraceAov::landingU, landingV
  // Where it crossed glass and ended on an opaque face: that face's material,
  // its base colour texture's value and level of detail, and what the value
  // is multiplied by (TraceAov's weight).
  uint landingMaterial;
  vec3 landingTexel;
  float landingLod;
  vec3 landingWeight;
  float shortestSegment;  // TraceAov::shortestSegment
};

// A ray leaving the surface of `hit` at `s` along dir: its offset origin and
// `leaving`, the distance within which faces are the surface it leaves,
// signed by the side of that surface the ray goes to (+: the side ng points
// to), for traceClosest.
vec3 leave(Surface s, vec3 dir, out float leaving) {
  vec3 origin = offsetRay(s.position, dot(dir, s.ng) > 0.0 ? s.ng : -s.ng);
  // The offset is the hit point's error bound. A face within that distance
  // of the new origin meets the hit point within its rounding: the surface
  // the ray leaves, not a new one. Skipping the hit triangle alone let rays
  // through a cube's edges enter the face across the edge a second time
  // (bench stress: watertight cube).
  leaving = dot(dir, s.ng) > 0.0 ? length(origin - s.position) : -length(origin - s.position);
  return origin;
}

// One path from (origin, dir) for `channel` (0-2: that channel's IOR; -1: all
// channels at the base IOR). With channel -1 it stops and returns true at the
// first dispersive boundary: the pixel is then traced once per channel.
// A reflected ray is traced by the next pass of the same loop, the path's
// continuation parked meanwhile: one traversal call site, because compilers
// that inline (lavapipe's) paid seconds of compile time for a second one.
// The ray's cone (trace.h: Textures) starts `width` wide at the origin and
// opens by `spread` radians.
bool tracePath(vec3 origin, vec3 dir, float width, float spread, int channel, out Path path) {
  path = Path(vec3(0.0), 0u, kOutcomeMiss, -1.0, kNoHit, kNoHit, vec2(uintBitsToFloat(0x7fc00000u)), kNoHit, vec3(0.0),
              0.0, vec3(0.0), kInf);
  bool fresnel = opticsOn(kOpticsFresnel);
  uint reflections = fresnel ? pc.reflections : 0u;
  vec3 throughput = vec3(1.0);
  mediaCount = 0u;
  uint skipInstance = kNoHit, skipPrim = kNoHit;
  float leaving = 0.0;  // a camera ray leaves no surface
  bool reflecting = false;  // this pass traces a reflected ray, weighted by `reflectedWeight`
  vec3 reflectedWeight = vec3(0.0);
  vec3 parkedOrigin = vec3(0.0), parkedDir = vec3(0.0);
  float parkedLeaving = 0.0, parkedWidth = 0.0, parkedSpread = 0.0;
  // maxInterfaces + 1 segments of the path at most, and its reflected rays.
  uint passes = pc.maxInterfaces + 1u + min(reflections, pc.maxInterfaces);
  bool segmentZero = true;
  for (uint pass = 0u; pass < passes; ++pass) {
    Hit hit = traceClosest(origin, dir, skipInstance, skipPrim, leaving);
    ++segments;
    if (traceFlag(kTraceFlagAov) && leaving != 0.0) path.shortestSegment = min(path.shortestSegment, hit.t);
    // Set on a miss too: left unset there, to a compiler they carried the last
    // segment's surface and material through the next walk, live in registers
    // the walk wanted (on an H100 the untextured trace took 128, now 96). The
    // same holds for every out value and every variable a loop sets: each is
    // set on every path (lightAt, bilinear, intersectTriangle).
    Surface s = Surface(vec3(0.0), vec3(0.0), vec3(0.0), vec4(0.0), vec2(0.0), vec2(0.0), 0u);
    GpuMaterial m = kNoMaterial;
    bool opaque = false;
    float hitWidth = width + spread * hit.t;  // the cone where it meets the face
    // The face's base colour texel (and its alpha), its second texture's (an
    // opaque face's emissive one, glass's IOR map), its normal map's and an
    // opaque face's light in two parts (phongParts), each from one call site
    // whatever the branches below use: every call site is compiled in full,
    // and the first image waits for the compile.
    // What the scene does not use (kTraceSpecSurface) is compiled out: a
    // slot without a texture reads 1 and an opaque face covers itself.
    vec3 texel = vec3(1.0), second = vec3(1.0), shine = vec3(0.0), weight = vec3(0.0);
    float coverage = 1.0;
    if (hit.instance != kNoHit) {
      s = surfaceAt(hit);
      s.lods = coneLod(s.density, hitWidth, dot(dir, s.ng));
      m = materials[s.material];
      opaque = !refractive(m);
      vec3 mapTexel = vec3(0.5, 0.5, 1.0);
      // The choice names only slots the scene fills: with the emissive, IOR
      // and normal slots named, a scene of base-colour textures alone (the
      // spheres, the eye) took 168 registers on NVIDIA, not 128.
      bool secondMaps = surfaceUses(kSurfaceEmissiveMaps | kSurfaceIorMaps);
      uint slots = !surfaceUses(kSurfaceTextures) ? 0u : surfaceUses(kSurfaceNormalMaps) ? 3u : secondMaps ? 2u : 1u;
      [[dont_unroll]] for (uint k = 0u; k < slots; ++k) {
        if (k == 1u && !surfaceUses(opaque ? kSurfaceEmissiveMaps : kSurfaceIorMaps)) continue;
        GpuTextureSlot slot = k == 0u || slots == 1u                            ? m.base
                              : k == 2u && surfaceUses(kSurfaceNormalMaps) ? m.normal
                              : secondMaps                                 ? (opaque ? m.emissive : m.iorMap)
                                                                           : m.normal;
        vec4 read = textured(slot, s.uvs, s.lods, k == 0u || (k == 1u && opaque));
        if (k == 0u) {
          texel = read.rgb;
          if (opaque && surfaceUses(kSurfaceAlpha)) coverage = coverageOf(m, read.a);
        } else if (k == 1u) {
          second = read.rgb;
        } else {
          mapTexel = read.rgb;
        }
      }
      // Alpha without textures: the factor's alone.
      if (opaque && surfaceUses(kSurfaceAlpha) && !surfaceUses(kSurfaceTextures)) coverage = coverageOf(m, 1.0);
      if (surfaceUses(kSurfaceNormalMaps) && m.normal.texture != kNoTexture) s.ns = normalMappedAt(hit, s, m, mapTexel);
      if (opaque) shine = phongLight(s.position, s.ns, m, second, dir, pc.lightCount, pc.forward.xyz, weight);
    }
    if (reflecting) {  // an opaque face is shaded; a miss or glass sees the environment
      path.colour += reflectedWeight * (opaque ? shine + weight * texel : environmentColour(dir));
      reflecting = false;
      origin = parkedOrigin;
      dir = parkedDir;
      leaving = parkedLeaving;
      width = parkedWidth;
      spread = parkedSpread;  // the skipped face is the same: the reflection left the face the path leaves
      continue;
    }
    if (hit.instance == kNoHit) {
      path.colour += throughput * pc.background.rgb;
      path.outcome = kOutcomeMiss;
      return false;
    }
    int inside = currentMedium();
    if (inside >= 0 && opticsOn(kOpticsVolume)) {  // Beer-Lambert over the segment
      GpuMaterial volume = materials[media[inside]];
      if (volume.attenuationDistance > 0.0) {
        throughput *= pow(volume.attenuationColor.rgb, vec3(hit.t / volume.attenuationDistance));
      }
    }
    if (segmentZero) {
      segmentZero = false;
      path.firstDistance = hit.t;
      path.firstInstance = hit.instance;
      path.firstPrimitive = hit.primitive - firstTriangleOf(hit.instance);
    }
    if (opaque && coverage == 1.0) {
      if (path.interfaces > 0u) {
        if (m.base.texture != kNoTexture) path.landing = textureUv(m.base, s.uvs);
        path.landingMaterial = s.material;
        path.landingTexel = texel;
        path.landingLod = (m.base.texCoord == 1u ? s.lods.y : s.lods.x) + m.base.lodOffset;
        path.landingWeight = throughput * weight;
      }
      path.colour += throughput * (shine + weight * texel);
      path.outcome = kOutcomeOpaque;
      return false;
    }
    if (path.interfaces == pc.maxInterfaces) {
      path.colour += throughput * pc.background.rgb;
      path.outcome = kOutcomeInterfaceLimit;
      return false;
    }
    if (opaque) {  // a face partly there: its light in proportion, the rest goes on straight
      path.colour += throughput * coverage * (shine + weight * texel);
      throughput *= 1.0 - coverage;
      ++path.interfaces;
      width = hitWidth;
      origin = leave(s, dir, leaving);
      skipInstance = hit.instance;
      skipPrim = hit.primitive;
      continue;
    }
    bool entering = dot(dir, s.ng) < 0.0;
    bool boundary;  // a true boundary: the medium changes here
    float surface = surfaceIor(m, second.r, channel);
    uint other = kNoHit;  // the material of the medium on the far side; kNoHit: air
    if (entering) {
      if (inside >= 0) other = media[inside];
      boundary = inside < 0 || mediumPriority(other) <= m.priority;
      enterMedium(s.material);
    } else {
      int at = leaveMedium(s.material);
      boundary = at < 0 || at == inside;
      int outside = currentMedium();
      if (outside >= 0) other = media[outside];
    }
    float otherIor = other == kNoHit ? 1.0 : mediumIor(other, channel);
    bool dispersive = opticsOn(kOpticsDispersion) &&
                      (m.dispersion > 0.0 || (other != kNoHit && materials[other].dispersion > 0.0));
    if (boundary && channel < 0 && dispersive) return true;
    float n1 = entering ? otherIor : surface, n2 = entering ? surface : otherIor;
    // Past maxBends the ray crosses glass straight (an approximation's path, not physics).
    bool bends = boundary && path.interfaces < pc.maxBends;
    ++path.interfaces;
    vec3 reflected = vec3(0.0);
    float reflectedSpread = 0.0;
    width = hitWidth;
    if (bends) {
      // How far the normal turns across the cone, > 0 where the surface bulges towards the ray.
      float turn = (entering ? 1.0 : -1.0) * curvatureAt(hit, s.ng) * hitWidth;
      vec3 n = entering ? s.ns : -s.ns;
      float eta = n1 / n2;
      float c = -dot(dir, n);
      if (c <= 0.0) {
        n = entering ? s.ng : -s.ng;
        c = -dot(dir, n);
      }
      float k = 1.0 - eta * eta * (1.0 - c * c);
      if (k < 0.0) {
        dir = normalize(dir + 2.0 * c * n);  // total internal reflection keeps everything
        spread += 2.0 * turn;
      } else {
        float r = fresnel ? fresnelReflectance(eta, c) : 0.0;
        if (reflections > 0u) {
          --reflections;
          if (r > 0.0) {
            path.colour += throughput * highlight(s.position, n, dir, m.roughness, eta);
            reflectedWeight = throughput * r;
            reflected = normalize(dir + 2.0 * c * n);
            reflectedSpread = spread + 2.0 * turn;
          }
        }
        dir = normalize(eta * dir + (eta * c - sqrt(k)) * n);
        spread = eta * spread - (1.0 - eta) * turn;  // a surface that converges light narrows the cone
        throughput *= 1.0 - r;
      }
    }
    if (boundary) throughput *= m.baseColorFactor.rgb * texel;  // the base colour (baseColour()) of the texel above
    origin = leave(s, dir, leaving);
    skipInstance = hit.instance;
    skipPrim = hit.primitive;
    if (reflected != vec3(0.0)) {  // trace the reflection next, then go on from here
      parkedOrigin = origin;
      parkedDir = dir;
      parkedLeaving = leaving;
      parkedWidth = width;
      parkedSpread = spread;
      origin = leave(s, reflected, leaving);
      dir = reflected;
      spread = reflectedSpread;
      reflecting = true;
    }
  }
  return false;
}

// One pixel's ray (or its listed ray), its path (three where it meets
// dispersion), and what it writes.
void tracePixel(uvec2 pixel) {
  float sx = (2.0 * (float(pixel.x) + 0.5) / float(pc.width) - 1.0) * pc.right.w + pc.shiftX;
  float sy = (1.0 - 2.0 * (float(pixel.y) + 0.5) / float(pc.height)) * pc.up.w + pc.shiftY;
  vec3 origin = pc.eye.xyz, dir;
  float width = 0.0, spread = 0.0;  // listed rays have no footprint: level 0
  if (traceFlag(kTraceFlagRayList)) {
    GpuRay ray = rays[pixel.y * pc.width + pixel.x];
    origin = ray.origin.xyz;
    dir = ray.direction.xyz;
  } else if (traceFlag(kTraceFlagOrthographic)) {
    origin += sx * pc.right.xyz + sy * pc.up.xyz;
    dir = pc.forward.xyz;
    width = 2.0 * pc.up.w / float(pc.height);
  } else {
    dir = normalize(pc.forward.xyz + sx * pc.right.xyz + sy * pc.up.xyz);
    spread = atan(2.0 * pc.up.w / float(pc.height));
  }
  if (!opticsOn(kOpticsTextureLod)) width = spread = 0.0;

  visits = boxTests = triangleTests = segments = walkSteps = subgroupSteps = 0u;
  deadVisits = culledVisits = leafVisits = leafSteps = 0u;
  tracedPixel = pixel.y * pc.width + pixel.x;
  // One call site for the path (a compiler that inlines would copy it per
  // call): the first pass at the base IOR, then, where it met dispersion,
  // red, blue and green, each keeping its channel (the AOVs are green's).
  Path path;
  vec3 colour = vec3(0.0);
  int channel = -1;
  for (int pass = 0; pass < 4; ++pass) {
    bool split = tracePath(origin, dir, width, spread, channel, path);
    if (channel < 0) {
      colour = path.colour;
      if (!split) break;
      channel = 0;
      continue;
    }
    colour[channel] = path.colour[channel];
    channel = channel == 0 ? 2 : 1;
  }
  path.colour = colour;

  // Every lane of the subgroup is here (main calls this once, outside any branch that lanes take apart).
  uint subgroupVisits = traceFlag(kTraceFlagAov) ? SNELL_SUBGROUP_MAX(visits) : 0u;
  if (!(SNELL_PIXEL_WRITER)) return;
  imageStore(outImage, ivec2(pixel), vec4(clamp(path.colour, -kHalfMax, kHalfMax), 1.0));
  if (traceFlag(kTraceFlagAov)) {
    // The colour less its landing's textured part is the shine (every channel's path, so dispersion too).
    vec3 shine = path.interfaces > 0u ? path.colour - path.landingWeight * path.landingTexel : vec3(0.0);
    vec3 weight = path.interfaces > 0u ? path.landingWeight : vec3(0.0);
    aovs[pixel.y * pc.width + pixel.x] = TraceAov(path.firstDistance, path.firstInstance, path.firstPrimitive,
                                                  path.interfaces, path.outcome, visits, path.landing.x, path.landing.y,
                                                  path.landingMaterial, path.landingLod, shine.r, shine.g, shine.b,
                                                  weight.r, weight.g, weight.b, segments, boxTests, triangleTests,
                                                  walkSteps, subgroupSteps, subgroupVisits, SNELL_SUBGROUP_SIZE,
                                                  path.shortestSegment, deadVisits, culledVisits, leafVisits, leafSteps);
  }
}

#endif
