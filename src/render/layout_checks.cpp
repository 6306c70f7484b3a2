// Every struct in shaders/shared/ that the render layer shares with GLSL is
// read with std430 rules; these checks fail the build if the C++ view of a
// layout drifts from the budget its header states (the viewer checks its own
// present.h in viewer/display.cpp).
#include "shared/bvh.h"
#include "shared/deform.h"
#include "shared/prefix_sum.h"
#include "shared/radix_sort.h"
#include "shared/raster.h"
#include "shared/scene.h"
#include "shared/trace.h"

#include <cstddef>

namespace snell::gpu {

static_assert(sizeof(ScanPush) == 16);
static_assert(offsetof(ScanPush, count) == 0);
static_assert(offsetof(ScanPush, blockCount) == 4);
static_assert(offsetof(ScanPush, addPartials) == 8);

static_assert(sizeof(SortPush) == 16);
static_assert(offsetof(SortPush, count) == 0);
static_assert(offsetof(SortPush, blockCount) == 4);
static_assert(offsetof(SortPush, shift) == 8);
static_assert(kSortRadix == 1u << kSortRadixBits);

static_assert(sizeof(DeformPush) == 16 && offsetof(DeformPush, jobCount) == 4);
static_assert(sizeof(DeformJob) == 48 && offsetof(DeformJob, outputFirst) == 12 && offsetof(DeformJob, skinFirst) == 28 &&
              offsetof(DeformJob, jointCount) == 36);
// deform.comp reads these as std430 uvec4[], vec4[] and mat4[].
static_assert(sizeof(glm::uvec4) == 16 && sizeof(glm::vec4) == 16 && sizeof(glm::mat4) == 64);

// The exact child boxes: three vec4s a node (bvh_quantise, bvh_refit and trace.comp index them so).
static_assert(kBvhChildBoxBytes == 3 * sizeof(glm::vec4));
static_assert(sizeof(BvhNode) == 40 && offsetof(BvhNode, scale) == 12 && offsetof(BvhNode, quant) == 16 &&
              offsetof(BvhNode, child) == 28 && offsetof(BvhNode, parent) == 36);
static_assert(sizeof(BvhWideEntry) == 32 && offsetof(BvhWideEntry, ref) == 12 && offsetof(BvhWideEntry, hi) == 16 &&
              offsetof(BvhWideEntry, parent) == 28);
static_assert(sizeof(BvhGroup) == 64 && offsetof(BvhGroup, boxHi) == 12 && offsetof(BvhGroup, root) == 24 &&
              offsetof(BvhGroup, first) == 28 && offsetof(BvhGroup, count) == 32 && offsetof(BvhGroup, buildArea) == 36);
static_assert(sizeof(BvhBuildEntry) == 48 && offsetof(BvhBuildEntry, base) == 12 &&
              offsetof(BvhBuildEntry, centroidLo) == 16 && offsetof(BvhBuildEntry, centroidHi) == 28);
static_assert(sizeof(BvhCluster) == 32 && offsetof(BvhCluster, lo) == 8 && offsetof(BvhCluster, hi) == 20);
static_assert(sizeof(BvhRefitEntry) == 16 && offsetof(BvhRefitEntry, threadBase) == 12);
static_assert(sizeof(BvhPush) == 16 && offsetof(BvhPush, total) == 12);
static_assert(sizeof(GpuInstance) == 112 && offsetof(GpuInstance, worldToObject) == 48 &&
              offsetof(GpuInstance, geometry) == 96 && offsetof(GpuInstance, material) == 100);

static_assert(sizeof(GpuTextureSlot) == 48 && offsetof(GpuTextureSlot, texture) == 32 &&
              offsetof(GpuTextureSlot, lodOffset) == 40);
static_assert(sizeof(GpuMaterial) == 288 && offsetof(GpuMaterial, transmission) == 48 &&
              offsetof(GpuMaterial, attenuationDistance) == 76 && offsetof(GpuMaterial, base) == 80 &&
              offsetof(GpuMaterial, emissive) == 128 && offsetof(GpuMaterial, iorMap) == 176 &&
              offsetof(GpuMaterial, normal) == 224 && offsetof(GpuMaterial, normalScale) == 272 &&
              offsetof(GpuMaterial, alphaMode) == 280);
static_assert(sizeof(GpuTexture) == 16 && offsetof(GpuTexture, flags) == 12);
static_assert(sizeof(TextureMipPush) == 32 && offsetof(TextureMipPush, srgb) == 24);
static_assert(sizeof(GpuLight) == 64 && offsetof(GpuLight, cone) == 48);
static_assert(sizeof(TraceAov) == 112 && offsetof(TraceAov, deadVisits) == 96 && offsetof(TraceAov, leafVisits) == 104 && offsetof(TraceAov, leafSteps) == 108 && offsetof(TraceAov, walkSteps) == 76 && offsetof(TraceAov, subgroupVisits) == 84 &&
              offsetof(TraceAov, segments) == 64 && offsetof(TraceAov, triangleTests) == 72 && offsetof(TraceAov, nodeVisits) == 20 && offsetof(TraceAov, landingV) == 28 &&
              offsetof(TraceAov, landingMaterial) == 32 && offsetof(TraceAov, shineR) == 40 && offsetof(TraceAov, weightB) == 60);
static_assert(sizeof(TraceHitRecord) == 32 && offsetof(TraceHitRecord, bary) == 16);
static_assert(sizeof(GpuRay) == 32 && offsetof(GpuRay, direction) == 16);
static_assert(sizeof(TracePixelListHeader) == 32 && offsetof(TracePixelListHeader, dispatchX) == kTracePixelListDispatchOffset);
static_assert(sizeof(TraceCompactPush) == 16 && offsetof(TraceCompactPush, lanesPerPixel) == 12);
static_assert(sizeof(RasterPush) == 112 && offsetof(RasterPush, offsetStrength) == 96 && offsetof(RasterPush, flags) == 80 && offsetof(RasterPush, lightCount) == 84);
static_assert(sizeof(RasterPush) == 112 && offsetof(RasterPush, mapWidth) == 100);
static_assert(sizeof(RefractionTexel) == 48 && offsetof(RefractionTexel, weight) == 16 && offsetof(RefractionTexel, material) == 40);
static_assert(sizeof(TracePush) == 128 && offsetof(TracePush, eye) == 64 && offsetof(TracePush, width) == 80 &&
              offsetof(TracePush, tilesX) == 100 && offsetof(TracePush, pad0) == 112 &&
              offsetof(TracePush, optics) == 120);

}  // namespace snell::gpu
