// The tracing contract, shared by shaders/comp/trace.comp (float, GPU) and
// src/ref (double, CPU). Both implement the rules below independently; only
// the constants and the GPU record layouts live here.
//
// Rays. One per pixel through its centre: for pixel (x, y), y = 0 the top row,
//   sx = (2 (x + 0.5) / W - 1) * tanHalfFovY * W / H + shiftX,  sy = (1 - 2 (y + 0.5) / H) * tanHalfFovY + shiftY,
//   (shift: the film back's 2D pan, View::shift; zero unless a viewer pans it)
//   perspective:  origin = eye, direction = normalize(forward + sx right + sy up);
//   orthographic: origin = eye + right sx' + up sy' with tanHalfFovY replaced by
//                 the half height, direction = forward.
// (scene/view.h resolves eye, right, up, forward and the fov; both tracers use it.)
// Ray lists: instead of the camera, pixel i (row-major) may take its primary
// ray from a list (origin, direction), for tests that aim rays at exact points.
//
// Hits. The closest triangle with t > 0 along the ray; a secondary ray never
// hits the triangle it leaves, nor any face that meets its origin within the
// hit point's rounding (the GPU: closer than the offset the ray starts from,
// or whose plane passes within that offset of its origin where the ray would
// cross it towards the side it went to, as the face across an edge it
// crossed does; the reference: closer than 1e-9 of the scene's size). Triangle tests are
// watertight in both: a ray through a shared edge or vertex hits one of its triangles. Barycentrics (b0, b1, b2) of
// p = b0 v0 + b1 v1 + b2 v2. In world space:
//   Ng = normalize(cross(v1 - v0, v2 - v0)), the geometric normal;
//   Ns = normalize(b0 n0 + b1 n1 + b2 n2), the shading normal (Ng where that is zero),
//        flipped to Ng's side when dot(Ns, Ng) < 0.
// Object-space normals go to world by the inverse transpose of the instance matrix.
// Normal maps (glTF normalTexture, tangent space): where a material has one, Ns
//   is bent before anything reads it, on glass and opaque faces alike. The
//   frame comes from the triangle (no tangent attribute): with world edges
//   e1 = v1 - v0, e2 = v2 - v0 and the corners' UVs of the map's set through
//   its transform, d1 = uv1 - uv0, d2 = uv2 - uv0, det = d1.x d2.y - d2.x d1.y:
//   T = (e1 d2.y - e2 d1.y) / det, B = -(e2 d1.x - e1 d2.x) / det (B runs up
//   the image, as v runs down it); no bend where det = 0 or T, B are not finite.
//   t = normalize(T - Ns dot(Ns, T)) (no bend where that is zero), b = cross(Ns, t),
//   negated where dot(b, B) < 0 (mirrored UVs); m = (2 texel - 1) * (scale, scale, 1)
//   with texel the map's RGB read as data (bytes / 255, filtered as below);
//   Ns' = normalize(m.x t + m.y b + m.z Ns), flipped to Ng's side.
//   (Per-triangle frames equal MikkTSpace's wherever UVs are affine across
//   neighbouring triangles; elsewhere they differ by the vertex smoothing.)
// Alpha (glTF alphaMode) of an opaque face: alpha = baseColorFactor.a * the base
//   texture's alpha (bytes / 255, filtered like its colour); coverage = 1 for
//   OPAQUE, alpha >= alphaCutoff ? 1 : 0 for MASK, clamp(alpha, 0, 1) for BLEND.
//   Where coverage < 1 the path adds throughput * coverage * (the face's
//   opaque shading, below), goes on straight with throughput *= 1 - coverage
//   from the hit (leaving that face, as secondary rays do), and counts an
//   interface (the limit below ends it as a miss). Reflected rays shade such
//   a face whole, and glass ignores alpha.
//
// Refractive faces (material transmission > 0) are the boundaries of media
// (Schmidt & Budge 2002, "Simple Nested Dielectrics in Ray Traced Images"):
//   each ray carries the stack of media it is inside (kMaxMedia entries, the
//   oldest dropped when full); the current medium is the entry of highest
//   priority (GpuMaterial priority, larger wins; ties to the latest entered),
//   air (IOR 1) when the stack is empty.
//   entering = dot(d, Ng) < 0. Entering m: a true boundary unless the current
//   medium's priority is higher than m's; m is pushed either way. Leaving m:
//   m's latest entry is removed; a true boundary if it was the current medium
//   (or m was not on the stack: a ray that started inside an open mesh).
//   A false boundary is crossed straight and untinted (it still counts as an interface).
//   At a true boundary n1 is the IOR on the ray's side, n2 the other:
//   entering: n1 = current medium (before the push), n2 = ior(m);
//   leaving: n1 = ior(m), n2 = current medium (after the removal).
//   ior(m) = max(1, m.ior + iorOffset + iorScale * r) where m has an IOR texture (glTF
//   extension SNELL_materials_ior_texture), r its red channel at the hit read as
//   byte / 255 (no sRGB decode), else m.ior;
//   for the medium being left or entered at this hit; a medium not at the hit
//   (the other side) uses its base IOR. With dispersion D > 0 (KHR_materials_dispersion,
//   D = 20 / Abbe number) the channels see ior - h, ior, ior + h (red, green,
//   blue) with h = 0.025 D (ior - 1), the extension's own spread: the pixel is
//   traced again once per channel from the camera, each keeping its channel.
//   n = entering ? Ns : -Ns; eta = n1 / n2;
//   c = -dot(d, n); if c <= 0 the shading normal faces away: n = entering ? Ng : -Ng, c = -dot(d, n);
//   k = 1 - eta^2 (1 - c^2);
//   k < 0: total internal reflection, d' = d + 2 c n, R = 1;
//   else d' = eta d + (eta c - sqrt(k)) n, and with Fresnel on (kOpticsFresnel)
//     R = (Rs + Rp) / 2, Rs = ((eta c - ct) / (eta c + ct))^2, Rp = ((eta ct - c) / (eta ct + c))^2, ct = sqrt(k),
//     the unpolarised dielectric reflectance; T = 1 - R (off: R = 0, T = 1).
//   d' = normalize(d'); a refracted ray's throughput *= T, total internal
//   reflection keeps it; then throughput *= base colour (factor times texture,
//   linear) at every true boundary. The (n2/n1)^2 radiance factor is not
//   applied: it cancels on leaving a closed medium.
//   The first `reflections` true boundaries of a path that refract (k >= 0)
//   also add, where R > 0 and before this boundary's factors: throughput * (R * reflected + highlight):
//     reflected: one ray along r = d + 2 c n from the hit; an opaque face it meets
//       is shaded as below, otherwise (a miss or a refractive face) it sees the environment;
//     highlight: sum over lights (as below) with nl = dot(n, l) > 0 of
//       E * D(nh) * F(dot(v, h)) / (4 max(dot(n, v), 1e-4)), v = -d, h = normalize(l + v), nh = dot(n, h),
//       skipped where nh <= 0 or dot(v, h) <= 0; D the GGX distribution, a = max(roughness^2, kMinAlpha):
//       D = a^2 / (pi (nh^2 (a^2 - 1) + 1)^2); F the R above (with eta) at cosine dot(v, h).
//     The catch light of an eye is this highlight on the cornea.
//   Past maxBends the ray crosses straight (no Fresnel, no reflection).
//   Volume (KHR_materials_volume, thickness > 0 and a finite attenuation
//   distance): a segment of length t inside a current medium with one
//   multiplies the throughput by attenuationColor^(t / attenuationDistance)
//   (Beer-Lambert); the last segment of a ray leaving the scene is not
//   attenuated. Thin-walled materials (thickness 0) have no volume.
//   A ray crosses at most maxInterfaces true boundaries (refraction and
//   internal reflection alike; default kDefaultMaxInterfaces): the one after
//   that ends it as a miss (outcome kOutcomeInterfaceLimit).
// The environment a reflected ray sees: the equirectangular map (kOpticsEnvironmentMap),
//   u = 0.5 + atan(d.x, -d.z) / (2 pi), v = acos(clamp(d.y, -1, 1)) / pi (world +Y up,
//   -Z at the centre), bilinear, repeating in u and clamped in v, texel centres at
//   (i + 0.5) / W; or the studio gradient: y = d.y, y >= 0: mix(kStudioHorizon,
//   kStudioZenith, y); y < 0: mix(kStudioHorizon, kStudioGround, min(1, -4 y)).
// Opaque faces: colour = throughput * (emissive + kAmbient * base
//                 + sum over lights E * max(dot(N, L), 0) * (base / pi + kSpecular * max(dot(N, H), 0)^kShininess))
//   with N = Ns turned towards the viewer (flipped when dot(Ns, -d) < 0), V = -d,
//   H = normalize(L + V), base = baseColorFactor.rgb * texture.rgb, emissive the same way.
//   Lights (glTF KHR_lights_punctual; a light shines down its node's -Z):
//     directional: L = -direction, E = colour * intensity;
//     point: L towards the light, E = colour * intensity / distance^2 * window,
//            window = clamp(1 - (distance / range)^4, 0, 1)^2 with a finite range, else 1;
//     spot: as point times s^2, s = clamp((dot(direction, -L) - cos outer) / max(1e-4, cos inner - cos outer), 0, 1).
//   No lights in the scene: one directional headlight along the camera's forward
//   axis with E = (kHeadlight, kHeadlight, kHeadlight). No shadows.
// Misses: colour = throughput * background (primary and transmitted rays; only
// reflected rays see the environment). Alpha is 1 everywhere.
//
// Textures. uv' = (T * vec3(uv, 1)).xy with T the KHR_texture_transform matrix;
// at mip level l (W_l = max(1, W >> l), H_l likewise; shared/scene.h lays the
// levels out, each the 2x2 mean of the one above in linear light),
// x = u' W_l - 0.5, y = v' H_l - 0.5 (row 0 is the image's first row); texels
// are decoded from sRGB to linear, then filtered bilinearly within a level and
// linearly between the two levels around the level of detail (trilinear).
// A sampler that says nearest reads the nearest texel of level 0, floor(u' W).
// Wrap per axis: repeat, mirrored repeat or clamp to edge, applied to the
// integer texel index.
// Level of detail: ray cones (Akenine-Möller et al., Ray Tracing Gems, ch. 20).
//   Each ray carries a cone, width w at its origin and spread angle a:
//   perspective primary rays w = 0, a = atan(2 tanHalfFovY / H); orthographic
//   w = 2 halfHeight / H, a = 0; listed rays w = 0, a = 0 (level 0). At a hit
//   at distance t the cone is w' = w + a t wide, and a texture is read at
//     lod = 0.5 log2(W H |det T2|) + 0.5 log2(A_uv / A_world) + log2|w'| - log2|dot(d, Ng)|,
//   T2 the transform's 2x2 part, A_uv = |cross2(uv1 - uv0, uv2 - uv0)| of the
//   texture's UV set and A_world = |cross(v1 - v0, v2 - v0)| (world space);
//   clamped to [0, levels - 1], and 0 where it is not a number.
//   The cone goes on from the hit w' wide. At a boundary that bends, with
//   k = the triangle's signed curvature as the ray meets it: the mean over its
//   edges (v_i, v_j) with |v_j - v_i| > 0 of dot(n_j - n_i, v_j - v_i) / |v_j - v_i|^2,
//   n the unit world vertex normals, all negated where dot(n_0 + n_1 + n_2, Ng) < 0,
//   and the sum negated again where the ray leaves (dot(d, Ng) > 0), so k > 0
//   where the surface bulges towards the ray (0 without normals or edges):
//   a refracted ray's a' = eta a - (1 - eta) k w' (the paraxial refraction of
//   the cone's edge rays: a surface that converges light narrows the cone, a
//   magnifier's footprint shrinks); a reflected ray and total internal
//   reflection a' = a + 2 k w'. A straight crossing keeps a. Past a focus w
//   is negative: textures read at |w|, lod's log2(w') is log2|w'|. The raster
//   pass reads opaque fragments with the primary ray's cone, so it and the
//   trace agree.
//   The environment map has no mips: reflected rays read it at full size.
//   With kOpticsTextureLod off, traced rays read every texture at level 0.
// With kOpticsDispersion off no material disperses (D = 0 everywhere); with
// kOpticsVolume off no material attenuates (as if every one were thin-walled).
#ifndef SNELL_TRACE_H
#define SNELL_TRACE_H
#include "scene.h"

SNELL_GPU_BEGIN

#ifdef __cplusplus
inline constexpr float kAmbient = 0.03f;
inline constexpr float kSpecular = 0.04f;
inline constexpr float kShininess = 64.0f;
inline constexpr float kHeadlight = 3.14159265f;
#else
const float kAmbient = 0.03;
const float kSpecular = 0.04;
const float kShininess = 64.0;
const float kHeadlight = 3.14159265;
#endif
// The smallest GGX width a highlight gets (roughness 0 would make a light a
// point no pixel catches), and the default studio gradient's colours.
#ifdef __cplusplus
inline constexpr float kMinAlpha = 0.002f;
inline constexpr float kStudioGround[3] = {0.02f, 0.02f, 0.02f};
inline constexpr float kStudioHorizon[3] = {0.30f, 0.29f, 0.27f};
inline constexpr float kStudioZenith[3] = {0.70f, 0.75f, 0.85f};
#else
const float kMinAlpha = 0.002;
const vec3 kStudioGround = vec3(0.02, 0.02, 0.02);
const vec3 kStudioHorizon = vec3(0.30, 0.29, 0.27);
const vec3 kStudioZenith = vec3(0.70, 0.75, 0.85);
#endif
SNELL_CONST kDefaultMaxInterfaces = 8;
SNELL_CONST kMaxMedia = 4;  // media one ray can be inside at once
SNELL_CONST kDefaultReflections = 1;  // true boundaries per path that send a reflected ray

// TracePush::optics bits.
SNELL_CONST kOpticsFresnel = 1u;         // R and T at every boundary, reflections, highlights
SNELL_CONST kOpticsEnvironmentMap = 2u;  // reflected rays read kTraceBindingEnvironment, not the studio gradient
SNELL_CONST kOpticsTextureLod = 4u;      // textures at the ray cone's level of detail (off: level 0)
SNELL_CONST kOpticsDispersion = 8u;      // dispersive materials split the colours (off: every channel at the base IOR)
SNELL_CONST kOpticsVolume = 16u;         // volumes attenuate (off: every material thin-walled)

// What a traced pixel ended on (TraceAov::outcome).
SNELL_CONST kOutcomeMiss = 0;
SNELL_CONST kOutcomeOpaque = 1;
SNELL_CONST kOutcomeInterfaceLimit = 2;  // more refractive faces than maxInterfaces


// Per-pixel outputs for tests and tools, written when TracePush::flags has kTraceFlagAov.
// 112 bytes
struct TraceAov {
  float distance;   // 4: to the first hit along the unit primary ray; -1 on a miss
  uint instance;    // 4: draw item of the first hit, kNoHit on a miss
  uint primitive;   // 4: triangle within that item's shape, kNoHit on a miss
  uint interfaces;  // 4: refractive faces crossed
  uint outcome;     // 4: kOutcome*
  uint nodeVisits;  // 4: BVH nodes visited over the whole path (the cost heat map)
  float landingU;   // 4: where a path that crossed glass ended on an opaque face with a base
  float landingV;   // 4: colour texture, that texture's UV (transformed); NaN otherwise (refraction maps)
  // A path that crossed glass, split the way a baked refraction map redraws
  // it: colour = shine + weight * (landingMaterial's base colour texture at
  // landing UV and level of detail landingLod), or shine + weight where it
  // ended on an untextured opaque face, or shine alone where it ended
  // elsewhere (weight 0). Zero where the path crossed no glass.
  uint landingMaterial;  // 4: the opaque face's material; kNoHit where it met none
  float landingLod;      // 4: the level of detail its base colour texture was read at
  float shineR;     // 4: reflections, highlights and emissive light
  float shineG;     // 4
  float shineB;     // 4
  float weightR;    // 4: light times the glass's transmittance times the base colour factor
  float weightG;    // 4
  float weightB;    // 4
  // What the path cost (bench cost): closest-hit queries (segments, reflected
  // rays included), child boxes tested and triangles tested, over the whole
  // path; the driver's pipeline counts only segments.
  uint segments;        // 4
  uint boxTests;        // 4
  uint triangleTests;   // 4
  // How busy the subgroup's lanes were (trace.comp; 0 from the driver's
  // pipeline, and no passes from the several-lanes walk): passes of the traversal loops this
  // pixel's lane made, passes its subgroup made that this lane led (the
  // lowest lane still walking counts them), the most node visits of any
  // pixel of its subgroup, and the subgroup's size. sum(walkSteps) /
  // sum(subgroupSteps x subgroupSize) is the loops' lane utilisation.
  uint walkSteps;       // 4
  uint subgroupSteps;   // 4
  uint subgroupVisits;  // 4
  uint subgroupSize;    // 4
  // The shortest segment a ray of the path ran after leaving a surface, kInf
  // where none did: a ray that hit the surface it left (a self-hit) ran one
  // of rounding's length.
  float shortestSegment;  // 4
  // Where the walk spends visits that find nothing (bench cost; 0 from the
  // driver's pipeline): node visits that enter no child, of those the ones
  // whose children the ray does meet, but beyond the nearest hit (a walk
  // that knew each entry's distance, or found the hit sooner, would skip
  // them), and leaves reached, whose triangles make triangleTests.
  uint deadVisits;    // 4
  uint culledVisits;  // 4
  uint leafVisits;  // 4
  // Passes of the leaf loops (their triangle tests) that this lane led for
  // its subgroup, as subgroupSteps does for the traversal loops:
  // sum(leafVisits) / sum(leafSteps x subgroupSize) is the share of a
  // subgroup's lanes at work while any of them tests a leaf.
  uint leafSteps;   // 4
};

SNELL_CONST kNoHit = 0xffffffffu;
SNELL_CONST kAllBends = 0xffffffffu;  // TracePush::maxBends: refraction at every interface (physics)
SNELL_CONST kTraceFlagAov = 1u;
SNELL_CONST kTraceFlagOrthographic = 2u;
SNELL_CONST kTraceFlagRayList = 4u;  // primary rays from kTraceBindingRays, not the camera
SNELL_CONST kTraceFlagPixelList = 8u;  // only the pixels kTraceBindingPixels lists (the masked trace)
// The hit-replay ablation (bench cost): record writes each segment's closest
// hit to kTraceBindingHits; replay reads them back instead of traversing, so
// its time is the path's work without the traversal. Benchmarks only.
SNELL_CONST kTraceFlagRecordHits = 16u;
SNELL_CONST kTraceFlagReplayHits = 32u;
SNELL_CONST kTraceReplaySegments = 8;  // segments a pixel records; later ones are traced in both runs
SNELL_CONST kTraceTile = 8;  // pixels per side of one workgroup's tile
// Specialisation constants of the trace: the kOptics* and kTraceFlag* bits a
// pipeline is made for. A bit off compiles its code out; TracePush's optics
// and flags still say what a dispatch draws (a pipeline made without them,
// the driver-rt peer's, follows the push constant alone).
SNELL_CONST kTraceSpecOptics = 0;
SNELL_CONST kTraceSpecFlags = 1;
// Lanes that trace one listed pixel together (the masked trace only): 1, or
// a power of two no larger than the subgroup (trace.comp's traverseLanes).
SNELL_CONST kTraceSpecLanes = 2;
// What the scene's materials use (kTraceSpecSurface): a pipeline made without
// a bit compiles that work out of every hit. No push constant repeats them:
// they are the scene's, fixed when it is uploaded (SceneGpu::surface), and a
// scene without them draws the same pixels with them compiled in.
SNELL_CONST kTraceSpecSurface = 3;
// 1: the trees keep each node's children's exact boxes (shared/bvh.h:
// kBvhFlagChildBoxes) and the walk reads those; 0: it decodes the nodes' own.
SNELL_CONST kTraceSpecChildBoxes = 4;
// 1: the bottom level also keeps 4-wide records (shared/bvh.h: BvhWideEntry)
// and its walk reads those; 0: it walks the binary nodes.
SNELL_CONST kTraceSpecWideWalk = 5;
SNELL_CONST kSurfaceTextures = 1u;      // some material reads a texture (any slot)
SNELL_CONST kSurfaceEmissiveMaps = 2u;  // some material has an emissive texture
SNELL_CONST kSurfaceIorMaps = 4u;       // some material has an IOR texture
SNELL_CONST kSurfaceNormalMaps = 8u;    // some material has a normal map
SNELL_CONST kSurfaceAlpha = 16u;        // some material masks or blends by alpha
SNELL_CONST kSurfaceSingleSided = 32u;  // some opaque material is single-sided: its back faces are culled
SNELL_CONST kSurfaceAll = 63u;
// Nodes one ray segment may visit before it gives up: a corrupted tree ends here.
SNELL_CONST kTraceMaxVisits = 1u << 20;
// Entries of a walk's stack, both levels together. The binary walk pushes at
// most one a level of a tree, and so does the 4-wide walk once the stack
// runs short (three every other level before that), so a bottom-level tree
// of depth d needs d entries above the top level's (tests/bvh_test.cpp: the
// builder's trees of a million triangles reach 57).
SNELL_CONST kTraceStackSize = 64u;

// The trace's own binding slots, after the scene binding set (shared/scene.h).
SNELL_CONST kTraceBindingTlasNodes = kSceneBindingCount + 0;
SNELL_CONST kTraceBindingTlasGroups = kSceneBindingCount + 1;
SNELL_CONST kTraceBindingBlasNodes = kSceneBindingCount + 2;
SNELL_CONST kTraceBindingBlasGroups = kSceneBindingCount + 3;
SNELL_CONST kTraceBindingImage = kSceneBindingCount + 4;          // rgba16f storage image
SNELL_CONST kTraceBindingAov = kSceneBindingCount + 5;            // TraceAov[width * height]
SNELL_CONST kTraceBindingRays = kSceneBindingCount + 6;           // GpuRay[width * height], with kTraceFlagRayList
SNELL_CONST kTraceBindingPixels = kSceneBindingCount + 7;         // TracePixelList, with kTraceFlagPixelList
SNELL_CONST kTraceBindingMask = kSceneBindingCount + 8;           // r32ui image: non-zero where a transmissive face is visible (compaction)
SNELL_CONST kTraceBindingGeometryFirst = kSceneBindingCount + 9;  // uint[geometryCount]: first triangle (driver-rt pipeline only)
SNELL_CONST kTraceBindingEnvironment = kSceneBindingCount + 10;   // vec4[]: (width, height, 0, 0), then width * height linear RGB texels, row 0 at +Y
SNELL_CONST kTraceBindingHits = kSceneBindingCount + 11;          // TraceHitRecord[width * height * kTraceReplaySegments], record/replay only
SNELL_CONST kTraceBindingTlasChildBoxes = kSceneBindingCount + 12;  // vec4[3 * nodes] (kTraceSpecChildBoxes)
SNELL_CONST kTraceBindingBlasChildBoxes = kSceneBindingCount + 13;
SNELL_CONST kTraceBindingBlasWideRecords = kSceneBindingCount + 14;  // BvhWideEntry[4 * nodes] (kTraceSpecWideWalk)

// A primary ray from a list, relative to the frame origin like everything the trace sees.
// 32 bytes, total: 32 bytes
struct GpuRay {
  vec4 origin;     // 16: xyz; w unused
  vec4 direction;  // 16: xyz, unit length; w unused
};

// One recorded closest hit (kTraceFlagRecordHits).
// 32 bytes, total: 32 bytes
struct TraceHitRecord {
  float t;          // 4
  uint instance;    // 4: kNoHit on a miss
  uint primitive;   // 4
  float pad0;       // 4
  vec4 bary;        // 16: xyz
};

// The scene is rebased to a frame origin near the cameras (Renderer);
// `eye` is the camera relative to it.
// 128 bytes, total: 128 bytes
struct TracePush {
  vec4 right;       // 16: xyz; w: half width of the view at unit distance (or of the ortho view)
  vec4 up;          // 16: xyz; w: half height
  vec4 forward;     // 16: xyz; w unused
  vec4 background;  // 16: rgb; w unused
  vec4 eye;         // 16: xyz; w unused
  uint width;       // 4
  uint height;      // 4
  uint maxInterfaces;  // 4
  uint lightCount;  // 4: 0: the headlight
  uint flags;       // 4: kTraceFlag*
  uint tilesX;      // 4: tiles per row
  float shiftX;     // 4: the film back's offset (View::shift)
  float shiftY;     // 4
  uint pad0;        // 4
  uint maxBends;    // 4: interfaces that refract; later ones are crossed straight (kAllBends: every one)
  uint optics;      // 4: kOptics* bits
  uint reflections; // 4: true boundaries per path that send a reflected ray
};

// The masked trace's pixel list (shaders/comp/trace_compact.comp writes it,
// the trace reads it): a header, then one packed pixel (x | y << 16) per entry.
// The header's dispatch fields are a VkDispatchIndirectCommand for the trace,
// one invocation per listed pixel: kTraceListGroupsX workgroups a row, as many
// rows as the list needs (the compaction raises dispatchY), so even a list of
// every pixel of a large image stays within the device's workgroup limits.
// The host writes the header (count 0, dispatch kTraceListGroupsX x 0 x 1) before compacting.
// 32 bytes, total: 32 bytes
struct TracePixelListHeader {
  uint count;      // 4: pixels listed
  uint pad0;       // 4
  uint dispatchX;  // 4: kTraceListGroupsX
  uint dispatchY;  // 4: rows of workgroups (atomicMax as pixels are listed)
  uint dispatchZ;  // 4: 1
  uint pad1;       // 4
  uint pad2;       // 4
  uint pad3;       // 4
};
SNELL_CONST kTracePixelListDispatchOffset = 8;  // bytes into the list: the indirect arguments
SNELL_CONST kTraceListGroupsX = 256;  // the masked trace's workgroups per dispatch row
// Tiles of kTraceTile x kTraceTile pixels each compaction workgroup lists, one after another.
SNELL_CONST kTraceCompactTiles = 16;

// 16 bytes, total: 16 bytes
struct TraceCompactPush {
  uint width;           // 4
  uint height;          // 4
  uint tilesX;          // 4: kTraceTile-wide tiles per row
  uint lanesPerPixel;   // 4: the trace's invocations per listed pixel (kTraceSpecLanes)
};

SNELL_GPU_END
#endif
