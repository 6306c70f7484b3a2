// What the trace pass and the driver's ray tracing pipeline share: the hit,
// the surface at a hit, the refraction rules of shared/trace.h and the whole
// path of one pixel. The including shader declares the buffers of trace.h's
// bindings (instances, positions, normals, texcoords, indices, materials,
// textures, texels, lights, outImage, aovs, rays), the push constant `pc`, and
// defines traceClosest() and firstTriangleOf() after this file.
#ifndef SNELL_PATH_GLSL
#define SNELL_PATH_GLSL

const float kInf = 1.0 / 0.0;  // folded to +infinity at compile time

uint visits;  // nodes visited by this pixel's whole path (the driver's pipeline cannot count them: 0)

struct Hit {
  float t;
  uint instance;
  uint primitive;  // global triangle index
  vec3 bary;       // weights of v0, v1, v2
};

vec3 vertexAt(uint v) {
  return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

// The closest hit beyond tMin along the ray, not on triangle skipPrim of
// instance skipInstance (the face the ray leaves); instance kNoHit on a miss.
Hit traceClosest(vec3 origin, vec3 dir, uint skipInstance, uint skipPrim, float tMin);
// The global index of the first triangle of the instance's geometry.
uint firstTriangleOf(uint instance);

#include "../../common/shading.glsl"

// ------------------------------------------------------------------ shading

struct Surface {
  vec3 position;  // camera-relative world space
  vec3 ng;        // geometric normal, unit
  vec3 ns;        // shading normal, unit, on ng's side
  vec4 uvs;
  uint material;
};

Surface surfaceAt(Hit hit) {
  GpuInstance inst = instances[hit.instance];
  uint i0 = indices[3u * hit.primitive], i1 = indices[3u * hit.primitive + 1u], i2 = indices[3u * hit.primitive + 2u];
  vec3 p0 = vertexAt(i0), p1 = vertexAt(i1), p2 = vertexAt(i2);
  vec3 p = hit.bary.x * p0 + hit.bary.y * p1 + hit.bary.z * p2;
  vec3 n0 = vec3(normals[3u * i0], normals[3u * i0 + 1u], normals[3u * i0 + 2u]);
  vec3 n1 = vec3(normals[3u * i1], normals[3u * i1 + 1u], normals[3u * i1 + 2u]);
  vec3 n2 = vec3(normals[3u * i2], normals[3u * i2 + 1u], normals[3u * i2 + 2u]);
  vec3 ns = hit.bary.x * n0 + hit.bary.y * n1 + hit.bary.z * n2;
  vec3 ng = cross(p1 - p0, p2 - p0);
  // Object to world; normals by the inverse transpose, i.e. worldToObject's columns.
  mat3 toWorldNormal = transpose(mat3(inst.worldToObject[0].xyz, inst.worldToObject[1].xyz, inst.worldToObject[2].xyz));
  Surface s;
  s.position = vec3(dot(inst.objectToWorld[0], vec4(p, 1.0)), dot(inst.objectToWorld[1], vec4(p, 1.0)),
                    dot(inst.objectToWorld[2], vec4(p, 1.0)));
  s.ng = normalize(toWorldNormal * ng);
  ns = toWorldNormal * ns;
  s.ns = dot(ns, ns) > 0.0 ? normalize(ns) : s.ng;
  if (dot(s.ns, s.ng) < 0.0) s.ns = -s.ns;
  s.uvs = hit.bary.x * texcoords[i0] + hit.bary.y * texcoords[i1] + hit.bary.z * texcoords[i2];
  s.material = inst.material;
  return s;
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

// One pixel's ray (or its listed ray), its whole path, and what it writes.
void tracePixel(uvec2 pixel) {

  float sx = (2.0 * (float(pixel.x) + 0.5) / float(pc.width) - 1.0) * pc.right.w + pc.shiftX;
  float sy = (1.0 - 2.0 * (float(pixel.y) + 0.5) / float(pc.height)) * pc.up.w + pc.shiftY;
  vec3 origin = pc.eye.xyz, dir;
  if ((pc.flags & kTraceFlagRayList) != 0u) {
    GpuRay ray = rays[pixel.y * pc.width + pixel.x];
    origin = ray.origin.xyz;
    dir = ray.direction.xyz;
  } else if ((pc.flags & kTraceFlagOrthographic) != 0u) {
    origin += sx * pc.right.xyz + sy * pc.up.xyz;
    dir = pc.forward.xyz;
  } else {
    dir = normalize(pc.forward.xyz + sx * pc.right.xyz + sy * pc.up.xyz);
  }

  visits = 0u;
  vec3 throughput = vec3(1.0);
  vec3 colour = vec3(0.0);
  uint interfaces = 0u;
  uint outcome = kOutcomeMiss;
  float firstDistance = -1.0;
  uint firstInstance = kNoHit, firstPrimitive = kNoHit;
  uint skipInstance = kNoHit, skipPrim = kNoHit;
  float tMin = 0.0;
  // Each pass of the loop is one segment; maxInterfaces + 1 segments at most.
  for (uint segment = 0u; segment <= pc.maxInterfaces; ++segment) {
    Hit hit = traceClosest(origin, dir, skipInstance, skipPrim, tMin);
    if (hit.instance == kNoHit) {
      colour = throughput * pc.background.rgb;
      outcome = kOutcomeMiss;
      break;
    }
    if (segment == 0u) {
      firstDistance = hit.t;
      firstInstance = hit.instance;
      firstPrimitive = hit.primitive - firstTriangleOf(hit.instance);
    }
    Surface s = surfaceAt(hit);
    GpuMaterial m = materials[s.material];
    if (m.emissiveFactor.w <= 0.0) {
      colour = throughput * phong(s.position, s.ns, s.uvs, m, dir, pc.lightCount, pc.forward.xyz);
      outcome = kOutcomeOpaque;
      break;
    }
    if (interfaces == pc.maxInterfaces) {
      colour = throughput * pc.background.rgb;
      outcome = kOutcomeInterfaceLimit;
      break;
    }
    bool entering = dot(dir, s.ng) < 0.0;
    vec3 n = entering ? s.ns : -s.ns;
    float ior = m.baseUvRow0.w;
    float eta = entering ? 1.0 / ior : ior;
    float c = -dot(dir, n);
    if (c <= 0.0) {
      n = entering ? s.ng : -s.ng;
      c = -dot(dir, n);
    }
    float k = 1.0 - eta * eta * (1.0 - c * c);
    // Past maxBends the ray crosses glass straight (an approximation's path, not physics).
    if (interfaces < pc.maxBends) dir = normalize(k < 0.0 ? dir + 2.0 * c * n : eta * dir + (eta * c - sqrt(k)) * n);
    throughput *= baseColour(m, s.uvs);
    ++interfaces;
    origin = offsetRay(s.position, dot(dir, s.ng) > 0.0 ? s.ng : -s.ng);
    // The offset is the hit point's error bound. A face within that distance
    // of the new origin meets the hit point within its rounding: the surface
    // the ray leaves, not a new one. Skipping the hit triangle alone let rays
    // through a cube's edges enter the face across the edge a second time
    // (bench stress: watertight cube).
    tMin = length(origin - s.position);
    skipInstance = hit.instance;
    skipPrim = hit.primitive;
  }

  imageStore(outImage, ivec2(pixel), vec4(colour, 1.0));
  if ((pc.flags & kTraceFlagAov) != 0u) {
    aovs[pixel.y * pc.width + pixel.x] =
        TraceAov(firstDistance, firstInstance, firstPrimitive, interfaces, outcome, visits, 0u, 0u);
  }
}

#endif
