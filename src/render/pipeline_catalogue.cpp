// The pipelines each pass can make, gathered for `snell bench pipelines`.
#include "render/pipeline_catalogue.h"

#include "peer/driver_tracer.h"
#include "render/bvh.h"
#include "render/deform_pass.h"
#include "render/prefix_sum.h"
#include "render/radix_sort.h"
#include "render/raster_pass.h"
#include "render/refine_pass.h"
#include "render/scene_gpu.h"
#include "render/trace_pass.h"
#include "shared/trace.h"

#include <algorithm>
#include <cstdio>

namespace snell::render {

namespace {

std::string hex(uint32_t bits) {
  char text[16];
  std::snprintf(text, sizeof text, "0x%02x", bits);
  return text;
}

// The benchmarks' scenes (the spheres over their backdrop, the eye): base
// colour textures and single-sided faces.
constexpr uint32_t kBenchSurface = gpu::kSurfaceTextures | gpu::kSurfaceSingleSided;

CataloguedPipeline computeEntry(std::string pass, std::string variant, vk::ComputeProgramDesc desc) {
  CataloguedPipeline p;
  p.pass = std::move(pass);
  p.variant = std::move(variant);
  p.compute = std::move(desc);
  return p;
}

}  // namespace

std::vector<CataloguedPipeline> traceCatalogue(const vk::Context& context) {
  // What a view of a textured glass scene traces with by default (Fresnel,
  // textures at the ray cone's level of detail), and everything.
  const uint32_t viewOptics = gpu::kOpticsFresnel | gpu::kOpticsTextureLod;
  const uint32_t allOptics = gpu::kOpticsFresnel | gpu::kOpticsEnvironmentMap | gpu::kOpticsTextureLod |
                             gpu::kOpticsDispersion | gpu::kOpticsVolume;
  std::vector<CataloguedPipeline> entries;
  auto add = [&](std::string variant, uint32_t optics, uint32_t flags, uint32_t lanes, uint32_t surface) {
    CataloguedPipeline p = computeEntry("trace", variant + ", surface " + hex(surface),
                                        TracePass::programDesc(context.facts(), optics, flags, lanes, surface));
    p.optics = optics, p.flags = flags, p.lanes = lanes, p.surface = surface;
    entries.push_back(std::move(p));
  };
  // Surface features come from the scene's materials: every map is a texture.
  const uint32_t surfaces[] = {0u,
                               gpu::kSurfaceTextures,
                               gpu::kSurfaceTextures | gpu::kSurfaceEmissiveMaps,
                               gpu::kSurfaceTextures | gpu::kSurfaceIorMaps,
                               gpu::kSurfaceTextures | gpu::kSurfaceNormalMaps,
                               gpu::kSurfaceAlpha,
                               gpu::kSurfaceSingleSided,
                               kBenchSurface,
                               gpu::kSurfaceAll};
  for (uint32_t surface : surfaces) add("full frame", viewOptics, 0u, 1u, surface);
  add("full frame, AOVs", viewOptics, gpu::kTraceFlagAov, 1u, kBenchSurface);
  add("ray list (stress grid)", viewOptics, gpu::kTraceFlagRayList | gpu::kTraceFlagAov, 1u, kBenchSurface);
  // The masked viewport's lanes a pixel: at most 8, and within the smallest subgroup.
  const uint32_t widest = std::min(8u, context.facts().minSubgroupSize);
  for (uint32_t lanes = 1; lanes <= widest; lanes *= 2) {
    add("masked, " + std::to_string(lanes) + (lanes == 1 ? " lane" : " lanes") + " a pixel", viewOptics,
        gpu::kTraceFlagPixelList, lanes, kBenchSurface);
  }
  add("full frame, every optics feature", allOptics, 0u, 1u, gpu::kSurfaceAll);
  return entries;
}

std::vector<CataloguedPipeline> pipelineCatalogue(const vk::Context& context) {
  std::vector<CataloguedPipeline> entries = traceCatalogue(context);
  entries.push_back(computeEntry("trace", "compaction of the masked trace's pixels", TracePass::compactDesc()));
  for (const vk::ComputeProgramDesc& d : BvhBuilder::programDescs(context)) entries.push_back(computeEntry("bvh", d.name, d));
  for (KeyWidth width : {KeyWidth::Bits32, KeyWidth::Bits64}) {
    const char* keys = width == KeyWidth::Bits32 ? ", 32-bit keys" : ", 64-bit keys";
    for (const vk::ComputeProgramDesc& d : RadixSort::programDescs(context, width)) {
      entries.push_back(computeEntry("sort", d.name + keys, d));
    }
  }
  for (const vk::ComputeProgramDesc& d : PrefixSum::programDescs(context)) entries.push_back(computeEntry("scan", d.name, d));
  entries.push_back(computeEntry("deform", "morphs and skins", DeformPass::programDesc()));
  for (const vk::ComputeProgramDesc& d : RefinePass::programDescs()) entries.push_back(computeEntry("refine", d.name, d));
  entries.push_back(computeEntry("mips", "texture mip levels", textureMipsDesc()));
  for (const vk::GraphicsProgramDesc& d : RasterPass::programDescs(context)) {
    CataloguedPipeline p;
    p.pass = "raster";
    p.variant = d.name;
    p.graphics = d;
    entries.push_back(std::move(p));
  }
  if (context.caps().driverRayTracing) {
    CataloguedPipeline p;
    p.pass = "driver-rt";
    p.variant = "the driver's ray tracing pipeline, surface " + hex(kBenchSurface);
    p.rayTracing = peer::DriverTracer::programDesc(kBenchSurface);
    entries.push_back(std::move(p));
  }
  return entries;
}

}  // namespace snell::render
