// The trace pass: one ray per pixel from the camera (at or near the origin:
// the scene is rebased to the camera), through the top-level tree into each instance's
// bottom-level tree; refracted at transmissive faces, reflected when Snell's
// law has no solution, Phong-shaded where it lands. The contract it follows
// is written out in shaders/shared/trace.h; src/ref is its double twin.
#version 460
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#extension GL_KHR_shader_subgroup_shuffle : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "../shared/bvh.h"
#include "../shared/trace.h"
#include "bvh/bvh_node.glsl"

layout(local_size_x = 64) in;  // one kTraceTile x kTraceTile tile of pixels
#include "../common/dispatch.glsl"
layout(push_constant) uniform Push { TracePush pc; };
layout(constant_id = kTraceSpecLanes) const uint kLanes = 1u;
layout(constant_id = kTraceSpecChildBoxes) const bool kExactChildBoxes = false;
layout(constant_id = kTraceSpecWideWalk) const bool kWideWalk = false;

// Nodes are 40 bytes: read as five 8-byte words rather than ten 4-byte ones.
layout(std430, binding = kTraceBindingTlasNodes) readonly buffer TlasNodes { uvec2 tlasWords[]; };
layout(std430, binding = kTraceBindingTlasGroups) readonly buffer TlasGroups { BvhGroup tlasGroups[]; };
layout(std430, binding = kTraceBindingBlasNodes) readonly buffer BlasNodes { uvec2 blasWords[]; };
layout(std430, binding = kTraceBindingBlasGroups) readonly buffer BlasGroups { BvhGroup blasGroups[]; };
layout(std430, binding = kTraceBindingTlasChildBoxes) readonly buffer TlasChildBoxes { vec4 tlasChildBoxes[]; };
layout(std430, binding = kTraceBindingBlasChildBoxes) readonly buffer BlasChildBoxes { vec4 blasChildBoxes[]; };
layout(std430, binding = kTraceBindingBlasWideRecords) readonly buffer BlasWide { vec4 blasWide[]; };  // BvhWideEntry[]
layout(std430, binding = kTraceBindingEnvironment) readonly buffer Environment { vec4 environment[]; };
layout(binding = kTraceBindingImage, rgba16f) uniform writeonly image2D outImage;
layout(std430, binding = kTraceBindingAov) writeonly buffer Aovs { TraceAov aovs[]; };
layout(std430, binding = kTraceBindingRays) readonly buffer Rays { GpuRay rays[]; };
layout(std430, binding = kTraceBindingHits) buffer HitRecords { TraceHitRecord hitRecords[]; };
layout(std430, binding = kTraceBindingPixels) readonly buffer Pixels {
  TracePixelListHeader list;
  uint listed[];
};

// Hit, the surface at a hit, shading and the path of one pixel, shared with
// the driver's ray tracing pipeline (src/peer/driver_tracer.h); this shader
// brings traceClosest, its own traversal. Lanes that share a pixel all run
// its path (their hits are the same), and the first of them writes it.
uint clusterLane() { return gl_SubgroupInvocationID & (kLanes - 1u); }
#define SNELL_PIXEL_WRITER (clusterLane() == 0u)
#define SNELL_SUBGROUP_MAX(v) subgroupMax(v)
#define SNELL_SUBGROUP_SIZE gl_SubgroupSize
#include "../common/path.glsl"

// ---------------------------------------------------------------- traversal

uint stack[kTraceStackSize];
uint budget;  // nodes this segment may still visit, top and bottom levels together

// One pass of a traversal loop, counted for the AOV (TraceAov::walkSteps):
// by this lane, and by the subgroup's lowest lane still in the loop for the
// whole subgroup, so the host can tell how many lanes each pass kept busy.
void countStep() {
  if (!traceFlag(kTraceFlagAov)) return;
  ++walkSteps;
  if (subgroupElect()) ++subgroupSteps;
}

// One pass of a leaf loop, whose lanes each test a triangle (TraceAov::leafSteps;
// the lane's own tests are its leafVisits): the subgroup's other lanes wait.
void countLeafStep() {
  if (traceFlag(kTraceFlagAov) && subgroupElect()) ++leafSteps;
}

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

// Watertight ray/triangle test; returns t (or kInf) and the barycentrics.
// det > 0 where the ray meets the triangle's front (counter-clockwise seen
// from the ray's origin, in the instance's own space): with cullSign 1 a
// back is missed, with 0 neither. A ray leaving a surface (`leaving`, from
// path.glsl's leave(): the error bound of its origin, signed by the side of
// that surface it goes to) misses every face whose plane passes within that
// bound of its origin and that it would cross towards the same side: at an
// edge the ray crossed, the face across it. Its hit point lies a rounding
// error from the origin's side of that plane, so it is met at distance
// error / cos along a ray that runs nearly parallel to it, past any bound
// along the ray (bench stress: 7 in 10^6 rays through the corners of the
// cube's boxes came back in through the neighbouring face). A face crossed
// the other way, out of the side the ray went to, is a corner the ray
// clips, and is hit.
float intersectTriangle(ShearedRay r, uint tri, float leaving, float tMax, float cullSign, out vec3 bary) {
  bary = vec3(0.0);  // set on every return (path.glsl: tracePath's surface)
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
  if (det == 0.0 || det * cullSign < 0.0) return kInf;
  float T = U * r.shear.z * A[kz] + V * r.shear.z * B[kz] + W * r.shear.z * C[kz];
  if (det < 0.0 ? (T >= 0.0 || T < tMax * det) : (T <= 0.0 || T > tMax * det)) return kInf;
  if (det * leaving < 0.0) {  // towards the side it went to: det < 0 crosses to the front
    // In the instance's space, where a unit of world distance along the ray
    // is the direction's length (d[kz] = 1 / shear.z). The normal is made
    // unit first, so no product underflows at a micrometre's scale.
    vec3 N = cross(B - A, C - A);
    float planeDistance = abs(dot(N, A)) * inversesqrt(dot(N, N));
    if (planeDistance <= abs(leaving) * length(vec3(r.shear.xy, 1.0)) / abs(r.shear.z)) return kInf;
  }
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

// A node's two children's boxes as the walk tests them: lo0 hi0 lo1 hi1 in
// three vec4s, as shared/bvh.h keeps exact child boxes.
struct ChildBoxes {
  vec4 a, b, c;
};

// Node `slot` of a level: its exact child boxes where the trees keep them,
// else its own quantised ones, decoded.
ChildBoxes childBoxes(BvhNode node, uint slot, bool top) {
  if (kExactChildBoxes) {
    uint i = 3u * slot;
    return top ? ChildBoxes(tlasChildBoxes[i], tlasChildBoxes[i + 1u], tlasChildBoxes[i + 2u])
               : ChildBoxes(blasChildBoxes[i], blasChildBoxes[i + 1u], blasChildBoxes[i + 2u]);
  }
  vec3 lo0, hi0, lo1, hi1;
  decodeChild(node, 0u, lo0, hi0);
  decodeChild(node, 1u, lo1, hi1);
  return ChildBoxes(vec4(lo0, hi0.x), vec4(hi0.yz, lo1.xy), vec4(lo1.z, hi1));
}

// The children of `node` the ray enters before tMax, nearer first: their
// entry distances (kInf where missed or empty) and references.
void enterChildren(BvhNode node, ChildBoxes b, ShearedRay r, float tMax, out float tNear, out float tFar,
                   out uint nearRef, out uint farRef) {
  vec3 lo0 = b.a.xyz, hi0 = vec3(b.a.w, b.b.xy), lo1 = vec3(b.b.zw, b.c.x), hi1 = b.c.yzw;
  // An empty child (its triangles dropped as non-finite) is never entered:
  // an exact one is the point at +infinity, which no slab enters, a decoded
  // one has its low x above its high x.
  float t0 = kExactChildBoxes || lo0.x <= hi0.x ? enterBox(r, lo0, hi0, tMax) : kInf;
  float t1 = kExactChildBoxes || lo1.x <= hi1.x ? enterBox(r, lo1, hi1, tMax) : kInf;
  bool swapOrder = t1 < t0;
  tNear = min(t0, t1);
  tFar = max(t0, t1);
  nearRef = swapOrder ? node.child[1] : node.child[0];
  farRef = swapOrder ? node.child[0] : node.child[1];
}

// A visit that entered no child, counted for the AOV (TraceAov::deadVisits),
// and whether the nearest hit alone culled them: the ray enters one beyond
// it. Only the AOV's pipelines test the node's children again.
void countDeadVisit(BvhNode node, ChildBoxes b, ShearedRay r, float tNear) {
  if (!traceFlag(kTraceFlagAov) || tNear < kInf) return;
  ++deadVisits;
  float t0, t1;
  uint ref0, ref1;
  enterChildren(node, b, r, kInf, t0, t1, ref0, ref1);
  if (t0 < kInf) ++culledVisits;
}

// A 4-wide visit that entered nothing, counted as countDeadVisit counts a
// binary one: culled where the ray enters an entry beyond the nearest hit.
void countDeadWideVisit(uint ref, ShearedRay r) {
  ++deadVisits;
  for (uint i = 0u; i < 4u; ++i) {
    if (enterBox(r, blasWide[8u * ref + 2u * i].xyz, blasWide[8u * ref + 2u * i + 1u].xyz, kInf) < kInf) {
      ++culledVisits;
      return;
    }
  }
}

// The ray in an instance's object space.
ShearedRay objectRay(uint instance, vec3 origin, vec3 dir) {
  GpuInstance inst = instances[instance];
  vec3 o = vec3(dot(inst.worldToObject[0], vec4(origin, 1.0)), dot(inst.worldToObject[1], vec4(origin, 1.0)),
                dot(inst.worldToObject[2], vec4(origin, 1.0)));
  vec3 d = vec3(dot(inst.worldToObject[0].xyz, dir), dot(inst.worldToObject[1].xyz, dir),
                dot(inst.worldToObject[2].xyz, dir));
  return shearRay(o, d);
}

// Which faces of the instance the ray passes (intersectTriangle's cullSign):
// the backs of a single-sided material's, where the scene has one, on every
// ray of the path: glass of IOR 1 must show what no glass shows. Facing is
// the instance's own: a mirroring transform keeps a face's front (glTF's rule).
float cullSignOf(uint instance) {
  if (!surfaceUses(kSurfaceSingleSided)) return 0.0;
  return (instances[instance].flags & kInstanceCullBackFaces) == 0u ? 0.0 : 1.0;
}

// A triangle of the instance's tree: the closest hit so far if nearer.
// tMax: hit.t, or less where another lane of the pixel has a nearer hit.
void testTriangle(ShearedRay r, uint instance, uint tri, uint skipPrim, uint first, uint end, float leaving, float tMax,
                  float cullSign, inout Hit hit) {
  ++leafVisits;
  if (tri == skipPrim || tri < first || tri >= end) return;  // skipPrim: the face this ray leaves
  ++triangleTests;
  vec3 bary;
  float t = intersectTriangle(r, tri, leaving, tMax, cullSign, bary);
  if (t < tMax && t > abs(leaving)) hit = Hit(t, instance, tri, bary);
}

// One instance's tree, with the ray in its object space (t is shared: the
// direction is not renormalised). Uses the stack above `base`. The nearer
// child entered goes on at once (no stack round trip) and the farther is
// pushed; a leaf child's triangle is tested before the next node, from one
// call site (lavapipe compiles each call site of the test in full).
// References outside the group's own nodes and triangles (only a corrupted
// tree has them) are skipped, so a bad tree costs visits, never a wild read.
void traverseBlas(uint instance, vec3 origin, vec3 dir, uint skipPrim, float leaving, uint base, inout Hit hit) {
  BvhGroup group = blasGroups[instances[instance].geometry];
  if (group.root == kBvhNone) return;
  uint end = group.first + group.count;
  ShearedRay r = objectRay(instance, origin, dir);
  const float cullSign = cullSignOf(instance);
  uint sp = base;
  uint ref = group.root;
  bool haveNode = (ref & kBvhLeafBit) == 0u;
  uint leaves[2] = uint[2](ref & ~kBvhLeafBit, 0u);
  uint leafCount = haveNode ? 0u : 1u;
  for (;;) {
    countStep();
    for (uint k = 0u; k < leafCount; ++k) {
      countLeafStep();
      testTriangle(r, instance, leaves[k], skipPrim, group.first, end, leaving, hit.t, cullSign, hit);
    }
    leafCount = 0u;
    // The budget before anything else: a walk that always goes on to a nearer
    // child (a corrupted tree's cycle) never pops, and must stop all the same.
    if (budget == 0u) break;
    if (!haveNode) {
      if (sp == base) break;
      ref = stack[--sp];
    }
    haveNode = false;
    --budget;
    ++visits;
    if (ref < group.first || ref + 1u >= end) continue;
    float tNear, tFar;
    uint nearRef, farRef;
    boxTests += 2u;
    BvhNode node = blasNode(ref);
    ChildBoxes boxes = childBoxes(node, ref, false);
    enterChildren(node, boxes, r, hit.t, tNear, tFar, nearRef, farRef);
    countDeadVisit(node, boxes, r, tNear);
    if (tFar < kInf) {
      if ((farRef & kBvhLeafBit) != 0u) leaves[leafCount++] = farRef & ~kBvhLeafBit;
      else if (sp < kTraceStackSize) stack[sp++] = farRef;  // a full stack drops it: only a corrupted tree is that deep
    }
    if (tNear < kInf) {
      if ((nearRef & kBvhLeafBit) != 0u) leaves[leafCount++] = nearRef & ~kBvhLeafBit;
      else ref = nearRef, haveNode = true;
    }
  }
}

// Two entries of a 4-wide visit in order of entry distance.
void orderPair(inout float ta, inout uint ra, inout float tb, inout uint rb) {
  if (tb < ta) {
    float t = ta;
    ta = tb;
    tb = t;
    uint r = ra;
    ra = rb;
    rb = r;
  }
}

// A 4-wide visit near the top of the stack pushes as the binary walk does,
// at most one entry a level: of entries 1-3 (the nearest, 0, goes on at
// once), those on the nearest's side stay, and the other side's entered
// entries become one, their parent, whose own record holds them again. So a
// tree no deeper than the binary walk's stack allows loses no entry 4 wide
// either (pushing three a visit would need 3 d / 2 entries for a tree of
// depth d, and the builder's trees of a million triangles reach 57). It
// rewrites the visit's entries in place, so the walk keeps one push site:
// AMD's compiler holds the stack in registers, where each site costs about a
// hundred instructions.
void narrowToBinary(uint node, inout float t[4], inout uint refs[4]) {
  // Entries 0 and 1 are child 0's side (BvhWideEntry::parent), 2 and 3 child 1's.
  uint side0[2] = uint[2](floatBitsToUint(blasWide[8u * node].w), floatBitsToUint(blasWide[8u * node + 2u].w));
  uint parents[2] = uint[2](floatBitsToUint(blasWide[8u * node + 1u].w), floatBitsToUint(blasWide[8u * node + 5u].w));
  uint nearSide = refs[0] == side0[0] || refs[0] == side0[1] ? 0u : 1u;
  bool otherKept = false;
  for (uint i = 3u; i > 0u; --i) {
    uint side = refs[i] == side0[0] || refs[i] == side0[1] ? 0u : 1u;
    if (t[i] == kInf || side == nearSide) continue;
    if (otherKept) t[i] = kInf;
    refs[i] = parents[side];
    otherKept = true;
  }
}

// One instance's tree walked 4 wide, where the bottom level keeps records:
// a visit reads the node's record of its grandchildren (shared/bvh.h,
// BvhWideEntry) and tests four boxes, so the walk visits every other level,
// and a chain of dependent node reads is 39-45% shorter than traverseBlas's
// for the same child tests (bench/results/walk-counts.md, step 2e). Leaves
// entered are tested before the next visit, the nearest node entered goes on
// at once, and the others are pushed farthest first (five exchanges sort
// four). The same stack, budget and bounds as traverseBlas; near the top of
// the stack a visit pushes binary-wise (narrowToBinary).
void traverseBlasWide(uint instance, vec3 origin, vec3 dir, uint skipPrim, float leaving, uint base, inout Hit hit) {
  BvhGroup group = blasGroups[instances[instance].geometry];
  if (group.root == kBvhNone) return;
  uint end = group.first + group.count;
  ShearedRay r = objectRay(instance, origin, dir);
  const float cullSign = cullSignOf(instance);
  uint sp = base;
  uint ref = group.root;
  bool haveNode = (ref & kBvhLeafBit) == 0u;
  uint leaves[4] = uint[4](ref & ~kBvhLeafBit, 0u, 0u, 0u);
  uint leafCount = haveNode ? 0u : 1u;
  for (;;) {
    countStep();
    for (uint k = 0u; k < leafCount; ++k) {
      countLeafStep();
      testTriangle(r, instance, leaves[k], skipPrim, group.first, end, leaving, hit.t, cullSign, hit);
    }
    leafCount = 0u;
    if (budget == 0u) break;  // before anything else, as in traverseBlas
    if (!haveNode) {
      if (sp == base) break;
      ref = stack[--sp];
    }
    haveNode = false;
    --budget;
    ++visits;
    if (ref < group.first || ref + 1u >= end) continue;
    float t[4];
    uint refs[4];
    for (uint i = 0u; i < 4u; ++i) {
      vec4 lo = blasWide[8u * ref + 2u * i], hi = blasWide[8u * ref + 2u * i + 1u];
      refs[i] = floatBitsToUint(lo.w);
      t[i] = enterBox(r, lo.xyz, hi.xyz, hit.t);
      if (refs[i] != kBvhNone) ++boxTests;
      if (t[i] < kInf && (refs[i] & kBvhLeafBit) != 0u) {
        leaves[leafCount++] = refs[i] & ~kBvhLeafBit;
        t[i] = kInf;
      }
    }
    orderPair(t[0], refs[0], t[1], refs[1]);
    orderPair(t[2], refs[2], t[3], refs[3]);
    orderPair(t[0], refs[0], t[2], refs[2]);
    orderPair(t[1], refs[1], t[3], refs[3]);
    orderPair(t[1], refs[1], t[2], refs[2]);
    if (traceFlag(kTraceFlagAov) && t[0] == kInf && leafCount == 0u) countDeadWideVisit(ref, r);
    if (sp + 3u > kTraceStackSize) narrowToBinary(ref, t, refs);
    for (uint i = 3u; i > 0u; --i) {
      if (t[i] < kInf && sp < kTraceStackSize) stack[sp++] = refs[i];  // a full stack drops it: only a corrupted tree is that deep
    }
    if (t[0] < kInf) ref = refs[0], haveNode = true;
  }
}

// leaving: 0 for a camera ray; for a ray leaving a surface, hits this close
// to the origin (and the faces intersectTriangle names) are that surface.
Hit traverse(vec3 origin, vec3 dir, uint skipInstance, uint skipPrim, float leaving) {
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
    countStep();
    --budget;
    uint ref = stack[--sp];
    ++visits;
    if ((ref & kBvhLeafBit) != 0u) {
      uint instance = ref & ~kBvhLeafBit;
      if (instance >= top.count) continue;
      if (kWideWalk) {
        traverseBlasWide(instance, origin, dir, instance == skipInstance ? skipPrim : kNoHit, leaving, sp, hit);
      } else {
        traverseBlas(instance, origin, dir, instance == skipInstance ? skipPrim : kNoHit, leaving, sp, hit);
      }
      continue;
    }
    if (ref >= nodeEnd) continue;
    float tNear, tFar;
    uint nearRef, farRef;
    boxTests += 2u;
    BvhNode node = tlasNode(ref);
    ChildBoxes boxes = childBoxes(node, ref, true);
    enterChildren(node, boxes, r, hit.t, tNear, tFar, nearRef, farRef);
    countDeadVisit(node, boxes, r, tNear);
    // The nearer on top. A full stack drops them (only a corrupted tree is that deep): the ray still ends.
    if (tFar < kInf && sp < kTraceStackSize) stack[sp++] = farRef;
    if (tNear < kInf && sp < kTraceStackSize) stack[sp++] = nearRef;
  }
  return hit;
}

// ------------------------------------------------- several lanes, one ray

// The masked viewport traces few rays, and then a ray's chain of dependent
// node visits, not the GPU's throughput, sets the time. With kLanes > 1 that
// many neighbouring lanes of a subgroup trace one ray: each walks its own
// part of both levels, nearer child first; a lane that runs out of nodes
// takes the farther child another lane just found, and every step the lanes
// cull with the nearest hit any of them has. They end together, and all take
// the nearest hit (the lowest lane's where two are equally near).

uint stackInstance[kTraceStackSize];  // the instance of each stacked bottom-level node; kNoHit: top level

uint clusterBits(bool b) {  // one bit per lane of this ray, its first lane lowest
  uvec4 ballot = subgroupBallot(b);
  uint first = gl_SubgroupInvocationID - clusterLane();
  return (ballot[first >> 5u] >> (first & 31u)) & ((1u << kLanes) - 1u);
}

float clusterMin(float v) {
  for (uint m = 1u; m < kLanes; m <<= 1u) v = min(v, subgroupShuffleXor(v, m));
  return v;
}

uint clusterSum(uint v) {
  for (uint m = 1u; m < kLanes; m <<= 1u) v += subgroupShuffleXor(v, m);
  return v;
}

uint nthBit(uint mask, uint rank) {  // the lane of `mask` with `rank` set bits below it
  for (uint i = 0u; i < rank; ++i) mask &= mask - 1u;
  return findLSB(mask);
}

Hit traverseLanes(vec3 origin, vec3 dir, uint skipInstance, uint skipPrim, float leaving) {
  Hit hit = Hit(kInf, kNoHit, kNoHit, vec3(0.0));
  BvhGroup top = tlasGroups[0];
  if (top.root == kBvhNone) return hit;
  uint visitsBefore = visits, boxesBefore = boxTests, trianglesBefore = triangleTests;
  uint deadBefore = deadVisits, culledBefore = culledVisits, leavesBefore = leafVisits;
  uint nodeEnd = top.count - 1u;
  ShearedRay world = shearRay(origin, dir);
  ShearedRay r = world;
  uint rInstance = kNoHit;  // the space r is in
  uint sp = 0u;
  // The node in hand and its instance (kNoHit: a top-level node); the first lane starts at the root.
  uint ref = clusterLane() == 0u ? top.root : kNoHit, inst = kNoHit;
  float nearest = kInf;  // the nearest hit of any lane, as of the last step
  budget = kTraceMaxVisits;  // each lane's own: a corrupted tree costs kLanes budgets at most
  for (;;) {
    if (ref == kNoHit && sp > 0u) {
      --sp;
      ref = stack[sp];
      inst = stackInstance[sp];
    }
    uint farRefGiven = kNoHit, farInst = kNoHit;
    if (ref != kNoHit && budget > 0u) {
      --budget;
      ++visits;
      uint node = ref, nodeInst = inst;
      ref = kNoHit;
      float tMax = min(hit.t, nearest);
      float tNear, tFar;
      uint nearRef, farRef;
      if (nodeInst == kNoHit) {
        if ((node & kBvhLeafBit) != 0u) {  // an instance: on into its tree
          uint instance = node & ~kBvhLeafBit;
          uint root = instance < top.count ? blasGroups[instances[instance].geometry].root : kBvhNone;
          if (root != kBvhNone) ref = root, inst = instance;
        } else if (node < nodeEnd) {
          boxTests += 2u;
          BvhNode n = tlasNode(node);
          ChildBoxes boxes = childBoxes(n, node, true);
          enterChildren(n, boxes, world, tMax, tNear, tFar, nearRef, farRef);
          countDeadVisit(n, boxes, world, tNear);
          if (tNear < kInf) ref = nearRef;
          if (tFar < kInf) farRefGiven = farRef;
        }
      } else {
        BvhGroup group = blasGroups[instances[nodeInst].geometry];
        uint end = group.first + group.count;
        uint skip = nodeInst == skipInstance ? skipPrim : kNoHit;
        if (rInstance != nodeInst) {
          r = objectRay(nodeInst, origin, dir);
          rInstance = nodeInst;
        }
        uint leaves[2] = uint[2](0u, 0u);
        uint leafCount = 0u;
        if ((node & kBvhLeafBit) != 0u) {  // a tree of one triangle
          leaves[leafCount++] = node & ~kBvhLeafBit;
        } else if (node >= group.first && node + 1u < end) {
          boxTests += 2u;
          BvhNode n = blasNode(node);
          ChildBoxes boxes = childBoxes(n, node, false);
          enterChildren(n, boxes, r, tMax, tNear, tFar, nearRef, farRef);
          countDeadVisit(n, boxes, r, tNear);
          if (tNear < kInf) {
            if ((nearRef & kBvhLeafBit) != 0u) leaves[leafCount++] = nearRef & ~kBvhLeafBit;
            else ref = nearRef, inst = nodeInst;
          }
          if (tFar < kInf) {
            if ((farRef & kBvhLeafBit) != 0u) leaves[leafCount++] = farRef & ~kBvhLeafBit;
            else farRefGiven = farRef, farInst = nodeInst;
          }
        }
        for (uint k = 0u; k < leafCount; ++k) {
          testTriangle(r, nodeInst, leaves[k], skip, group.first, end, leaving, min(hit.t, nearest), cullSignOf(nodeInst),
                       hit);
        }
      }
    }
    if (budget == 0u) ref = farRefGiven = kNoHit, sp = 0u;
    if (ref == kNoHit && farRefGiven != kNoHit) {  // nothing nearer in hand: the farther child goes on here
      ref = farRefGiven;
      inst = farInst;
      farRefGiven = kNoHit;
    }
    // Lanes left with nothing take the farther children the others found, in rank order.
    bool idle = ref == kNoHit && sp == 0u;
    uint idleLanes = clusterBits(idle), givingLanes = clusterBits(farRefGiven != kNoHit);
    uint below = (1u << clusterLane()) - 1u;
    uint from = clusterLane();
    if (idle && bitCount(idleLanes & below) < bitCount(givingLanes)) {
      from = nthBit(givingLanes, bitCount(idleLanes & below));
    }
    uint first = gl_SubgroupInvocationID - clusterLane();
    uint takenRef = subgroupShuffle(farRefGiven, first + from);
    uint takenInst = subgroupShuffle(farInst, first + from);
    if (from != clusterLane()) ref = takenRef, inst = takenInst;
    if (farRefGiven != kNoHit && bitCount(givingLanes & below) >= bitCount(idleLanes) && sp < kTraceStackSize) {
      stack[sp] = farRefGiven;  // no lane free to take it (a full stack drops it: only a corrupted tree is that deep)
      stackInstance[sp] = farInst;
      ++sp;
    }
    nearest = clusterMin(hit.t);
    if (clusterBits(ref != kNoHit || sp > 0u) == 0u) break;
  }
  // Every lane takes the nearest hit, from the lowest lane that has it.
  uint holders = clusterBits(hit.instance != kNoHit && hit.t == nearest);
  uint from = gl_SubgroupInvocationID - clusterLane() + (holders == 0u ? 0u : findLSB(holders));
  Hit taken = Hit(subgroupShuffle(hit.t, from), subgroupShuffle(hit.instance, from),
                  subgroupShuffle(hit.primitive, from),
                  vec3(subgroupShuffle(hit.bary.x, from), subgroupShuffle(hit.bary.y, from),
                       subgroupShuffle(hit.bary.z, from)));
  visits = visitsBefore + clusterSum(visits - visitsBefore);
  boxTests = boxesBefore + clusterSum(boxTests - boxesBefore);
  triangleTests = trianglesBefore + clusterSum(triangleTests - trianglesBefore);
  deadVisits = deadBefore + clusterSum(deadVisits - deadBefore);
  culledVisits = culledBefore + clusterSum(culledVisits - culledBefore);
  leafVisits = leavesBefore + clusterSum(leafVisits - leavesBefore);
  return holders == 0u ? Hit(kInf, kNoHit, kNoHit, vec3(0.0)) : taken;
}

// The traversal, or, for the hit-replay ablation (shared/trace.h), its recorded answer.
Hit traceClosest(vec3 origin, vec3 dir, uint skipInstance, uint skipPrim, float leaving) {
  uint slot = tracedPixel * kTraceReplaySegments + segments;
  bool recorded = segments < kTraceReplaySegments;
  if (traceFlag(kTraceFlagReplayHits) && recorded) {
    TraceHitRecord h = hitRecords[slot];
    return Hit(h.t, h.instance, h.primitive, h.bary.xyz);
  }
  Hit hit = kLanes > 1u ? traverseLanes(origin, dir, skipInstance, skipPrim, leaving)
                        : traverse(origin, dir, skipInstance, skipPrim, leaving);
  if (traceFlag(kTraceFlagRecordHits) && recorded && SNELL_PIXEL_WRITER) {
    hitRecords[slot] = TraceHitRecord(hit.t, hit.instance, hit.primitive, 0.0, vec4(hit.bary, 0.0));
  }
  return hit;
}

uint firstTriangleOf(uint instance) { return blasGroups[instances[instance].geometry].first; }

void main() {
  uint group = workgroupIndex();
  uvec2 pixel;
  if (traceFlag(kTraceFlagPixelList)) {
    // The masked trace: one listed pixel per invocation (listed tile by tile,
    // so neighbours stay together). One call of tracePixel, outside any loop:
    // lavapipe's compiler took three times as long over it inside one.
    // With several lanes a pixel, they are neighbours in one subgroup (the
    // pipeline asks for full subgroups): all of a pixel's lanes go on or return.
    uint i = kLanes == 1u ? group * gl_WorkGroupSize.x + gl_LocalInvocationID.x
                          : (group * gl_WorkGroupSize.x + gl_SubgroupID * gl_SubgroupSize + gl_SubgroupInvocationID) /
                                kLanes;
    if (i >= list.count) return;
    pixel = uvec2(listed[i] & 0xffffu, listed[i] >> 16);
  } else {
    pixel = uvec2(group % pc.tilesX, group / pc.tilesX) * kTraceTile +
            uvec2(gl_LocalInvocationID.x % kTraceTile, gl_LocalInvocationID.x / kTraceTile);
    if (pixel.x >= pc.width || pixel.y >= pc.height) return;
  }
  tracePixel(pixel);
}
