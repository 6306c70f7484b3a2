// The trace pass: one ray per pixel from the camera (at or near the origin:
// the scene is rebased to the camera), through the top-level tree into each instance's
// bottom-level tree; refracted at transmissive faces, reflected when Snell's
// law has no solution, Phong-shaded where it lands. The contract it follows
// is written out in shaders/shared/trace.h; src/ref is its double twin.
#version 460
#extension GL_GOOGLE_include_directive : require
#include "../shared/bvh.h"
#include "../shared/trace.h"
#include "bvh/bvh_node.glsl"

layout(local_size_x = 64) in;  // one kTraceTile x kTraceTile tile of pixels
layout(push_constant) uniform Push { TracePush pc; };

// Nodes are 40 bytes: read as five 8-byte words rather than ten 4-byte ones.
layout(std430, binding = kTraceBindingTlasNodes) readonly buffer TlasNodes { uvec2 tlasWords[]; };
layout(std430, binding = kTraceBindingTlasGroups) readonly buffer TlasGroups { BvhGroup tlasGroups[]; };
layout(std430, binding = kTraceBindingInstances) readonly buffer Instances { GpuInstance instances[]; };
layout(std430, binding = kTraceBindingBlasNodes) readonly buffer BlasNodes { uvec2 blasWords[]; };
layout(std430, binding = kTraceBindingBlasGroups) readonly buffer BlasGroups { BvhGroup blasGroups[]; };
layout(std430, binding = kTraceBindingPositions) readonly buffer Positions { float positions[]; };
layout(std430, binding = kTraceBindingNormals) readonly buffer Normals { float normals[]; };
layout(std430, binding = kTraceBindingTexcoords) readonly buffer Texcoords { vec4 texcoords[]; };
layout(std430, binding = kTraceBindingIndices) readonly buffer Indices { uint indices[]; };
layout(std430, binding = kTraceBindingMaterials) readonly buffer Materials { GpuMaterial materials[]; };
layout(std430, binding = kTraceBindingTextures) readonly buffer Textures { GpuTexture textures[]; };
layout(std430, binding = kTraceBindingTexels) readonly buffer Texels { uint texels[]; };
layout(std430, binding = kTraceBindingLights) readonly buffer Lights { GpuLight lights[]; };
layout(binding = kTraceBindingImage, rgba16f) uniform writeonly image2D outImage;
layout(std430, binding = kTraceBindingAov) writeonly buffer Aovs { TraceAov aovs[]; };
layout(std430, binding = kTraceBindingRays) readonly buffer Rays { GpuRay rays[]; };
layout(std430, binding = kTraceBindingPixels) readonly buffer Pixels {
  TracePixelListHeader list;
  uint listed[];
};

const float kInf = 1.0 / 0.0;  // folded to +infinity at compile time
const uint kStackSize = 64u;

// ---------------------------------------------------------------- traversal

uint stack[kStackSize];
uint visits;  // nodes visited by this pixel's whole path
uint budget;  // nodes this segment may still visit, top and bottom levels together

struct Hit {
  float t;
  uint instance;
  uint primitive;  // global triangle index
  vec3 bary;       // weights of v0, v1, v2
};

// Woop, Benthin & Wald 2013: the ray's shear, computed once per space.
struct ShearedRay {
  vec3 origin;
  ivec3 k;    // kx, ky, kz: kz is the dominant axis of the direction
  vec3 shear; // Sx, Sy, Sz
  vec3 invDir;
};

ShearedRay shearRay(vec3 origin, vec3 dir) {
  ShearedRay r;
  r.origin = origin;
  vec3 a = abs(dir);
  int kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
  int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  if (dir[kz] < 0.0) { int tmp = kx; kx = ky; ky = tmp; }  // keeps the winding
  r.k = ivec3(kx, ky, kz);
  r.shear = vec3(dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
  // Zero components would make 0 * inf = NaN in the slab test; a tiny
  // stand-in keeps the box test conservative.
  for (int i = 0; i < 3; ++i) r.invDir[i] = 1.0 / (abs(dir[i]) < 1e-30 ? (dir[i] < 0.0 ? -1e-30 : 1e-30) : dir[i]);
  return r;
}

// Slab test against [lo, hi], grown by the rounding bound of the test itself
// (3 ulps, Ize 2013) so a ray through a shared edge cannot slip past both boxes.
float enterBox(ShearedRay r, vec3 lo, vec3 hi, float tMax) {
  vec3 t0 = (lo - r.origin) * r.invDir, t1 = (hi - r.origin) * r.invDir;
  vec3 tNear = min(t0, t1), tFar = max(t0, t1);
  float enter = max(max(tNear.x, tNear.y), max(tNear.z, 0.0));
  float leave = min(min(tFar.x, tFar.y), min(tFar.z, tMax)) * 1.0000004;
  return enter <= leave ? enter : kInf;  // false for NaN boxes too
}

vec3 vertexAt(uint v) {
  return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

// Watertight ray/triangle test; returns t (or kInf) and the barycentrics.
float intersectTriangle(ShearedRay r, uint tri, float tMax, out vec3 bary) {
  precise vec3 A = vertexAt(indices[3u * tri]) - r.origin;
  precise vec3 B = vertexAt(indices[3u * tri + 1u]) - r.origin;
  precise vec3 C = vertexAt(indices[3u * tri + 2u]) - r.origin;
  int kx = r.k.x, ky = r.k.y, kz = r.k.z;
  // precise: a fused multiply-add rounds one side of an edge differently from
  // the triangle across it, and rays slipped between them on NVIDIA (golden
  // eye_front). Unfused, both triangles compute the same edge value.
  precise float Ax = A[kx] - r.shear.x * A[kz], Ay = A[ky] - r.shear.y * A[kz];
  precise float Bx = B[kx] - r.shear.x * B[kz], By = B[ky] - r.shear.y * B[kz];
  precise float Cx = C[kx] - r.shear.x * C[kz], Cy = C[ky] - r.shear.y * C[kz];
  precise float U = Cx * By - Cy * Bx;
  precise float V = Ax * Cy - Ay * Cx;
  precise float W = Bx * Ay - By * Ax;
  if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return kInf;
  float det = U + V + W;
  if (det == 0.0) return kInf;
  float T = U * r.shear.z * A[kz] + V * r.shear.z * B[kz] + W * r.shear.z * C[kz];
  if (det < 0.0 ? (T >= 0.0 || T < tMax * det) : (T <= 0.0 || T > tMax * det)) return kInf;
  float inv = 1.0 / det;
  bary = vec3(U, V, W) * inv;
  return T * inv;
}

BvhNode nodeFromWords(uvec2 w0, uvec2 w1, uvec2 w2, uvec2 w3, uvec2 w4) {
  BvhNode n;
  n.origin = float[3](uintBitsToFloat(w0.x), uintBitsToFloat(w0.y), uintBitsToFloat(w1.x));
  n.scale = w1.y;
  n.quant = uint[3](w2.x, w2.y, w3.x);
  n.child = uint[2](w3.y, w4.x);
  n.parent = w4.y;
  return n;
}

BvhNode tlasNode(uint i) {
  uint w = 5u * i;
  return nodeFromWords(tlasWords[w], tlasWords[w + 1u], tlasWords[w + 2u], tlasWords[w + 3u], tlasWords[w + 4u]);
}

BvhNode blasNode(uint i) {
  uint w = 5u * i;
  return nodeFromWords(blasWords[w], blasWords[w + 1u], blasWords[w + 2u], blasWords[w + 3u], blasWords[w + 4u]);
}

// Pushes the children the ray enters before tMax, the nearer on top. A full
// stack drops them (only a corrupted tree is that deep): the ray still ends.
void pushChildren(BvhNode node, ShearedRay r, float tMax, inout uint sp) {
  vec3 lo0, hi0, lo1, hi1;
  decodeChild(node, 0u, lo0, hi0);
  decodeChild(node, 1u, lo1, hi1);
  // An empty child (its triangles dropped as non-finite) is never entered.
  float t0 = lo0.x <= hi0.x ? enterBox(r, lo0, hi0, tMax) : kInf;
  float t1 = lo1.x <= hi1.x ? enterBox(r, lo1, hi1, tMax) : kInf;
  bool swapOrder = t1 < t0;
  uint nearRef = swapOrder ? node.child[1] : node.child[0], farRef = swapOrder ? node.child[0] : node.child[1];
  if (max(t0, t1) < kInf && sp < kStackSize) stack[sp++] = farRef;
  if (min(t0, t1) < kInf && sp < kStackSize) stack[sp++] = nearRef;
}

// One instance's tree, with the ray in its object space (t is shared: the
// direction is not renormalised). Uses the stack above `base`. References
// outside the group's own nodes and triangles (only a corrupted tree has
// them) are skipped, so a bad tree costs visits, never a wild read.
void traverseBlas(uint instance, vec3 origin, vec3 dir, uint skipPrim, float tMin, uint base, inout Hit hit) {
  GpuInstance inst = instances[instance];
  BvhGroup group = blasGroups[inst.geometry];
  if (group.root == kBvhNone) return;
  uint end = group.first + group.count;
  vec3 o = vec3(dot(inst.worldToObject[0], vec4(origin, 1.0)), dot(inst.worldToObject[1], vec4(origin, 1.0)),
                dot(inst.worldToObject[2], vec4(origin, 1.0)));
  vec3 d = vec3(dot(inst.worldToObject[0].xyz, dir), dot(inst.worldToObject[1].xyz, dir),
                dot(inst.worldToObject[2].xyz, dir));
  ShearedRay r = shearRay(o, d);
  uint sp = base;
  stack[sp++] = group.root;
  while (sp > base && budget > 0u) {
    --budget;
    uint ref = stack[--sp];
    ++visits;
    if ((ref & kBvhLeafBit) != 0u) {
      uint tri = ref & ~kBvhLeafBit;
      if (tri == skipPrim || tri < group.first || tri >= end) continue;  // skipPrim: the face this ray leaves
      vec3 bary;
      float t = intersectTriangle(r, tri, hit.t, bary);
      if (t < hit.t && t > tMin) hit = Hit(t, instance, tri, bary);
      continue;
    }
    if (ref < group.first || ref + 1u >= end) continue;
    pushChildren(blasNode(ref), r, hit.t, sp);
  }
}

// tMin: hits this close to the origin are the surface the ray leaves.
Hit traceClosest(vec3 origin, vec3 dir, uint skipInstance, uint skipPrim, float tMin) {
  Hit hit = Hit(kInf, kNoHit, kNoHit, vec3(0.0));
  BvhGroup top = tlasGroups[0];
  if (top.root == kBvhNone) return hit;
  uint nodeEnd = top.count - 1u;
  ShearedRay r = shearRay(origin, dir);
  uint sp = 0u;
  stack[sp++] = top.root;
  // One budget for the whole segment: a corrupted bottom level cannot spend
  // it again in every instance the top level leads to.
  budget = kTraceMaxVisits;
  while (sp > 0u && budget > 0u) {
    --budget;
    uint ref = stack[--sp];
    ++visits;
    if ((ref & kBvhLeafBit) != 0u) {
      uint instance = ref & ~kBvhLeafBit;
      if (instance >= top.count) continue;
      traverseBlas(instance, origin, dir, instance == skipInstance ? skipPrim : kNoHit, tMin, sp, hit);
      continue;
    }
    if (ref >= nodeEnd) continue;
    pushChildren(tlasNode(ref), r, hit.t, sp);
  }
  return hit;
}

#include "../common/shading.glsl"

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
      firstPrimitive = hit.primitive - blasGroups[instances[hit.instance].geometry].first;
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

void main() {
  uint tile = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if ((pc.flags & kTraceFlagPixelList) != 0u) {
    // The masked trace: each workgroup takes pixelsPerGroup listed pixels
    // (listed tile by tile, so neighbours stay together).
    uint first = tile * pc.pixelsPerGroup;
    for (uint i = first + gl_LocalInvocationID.x; i < min(first + pc.pixelsPerGroup, list.count); i += gl_WorkGroupSize.x) {
      tracePixel(uvec2(listed[i] & 0xffffu, listed[i] >> 16));
    }
    return;
  }
  uvec2 pixel = uvec2(tile % pc.tilesX, tile / pc.tilesX) * kTraceTile +
          uvec2(gl_LocalInvocationID.x % kTraceTile, gl_LocalInvocationID.x / kTraceTile);
  if (pixel.x >= pc.width || pixel.y >= pc.height) return;
  tracePixel(pixel);
}
