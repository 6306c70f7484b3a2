// The raster pass: one draw per draw item over the trace's own buffers.
#include "render/raster_pass.h"

#include "render/pass_names.h"
#include "vk/error.h"

#include "raster_depth.spv.h"
#include "raster_fragment.spv.h"
#include "raster_mask.spv.h"
#include "raster_vertex.spv.h"

#include <algorithm>
#include <cmath>

namespace snell::render {

DepthRange fitDepthRange(const scene::View& view, const glm::dvec3& lo, const glm::dvec3& hi) {
  DepthRange range;
  if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) return range;  // nothing drawn: any range will do
  double nearest = std::numeric_limits<double>::infinity(), farthest = -nearest;
  for (int corner = 0; corner < 8; ++corner) {
    glm::dvec3 p((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y, (corner & 4) ? hi.z : lo.z);
    double z = glm::dot(p - view.eye, view.forward);
    nearest = std::min(nearest, z);
    farthest = std::max(farthest, z);
  }
  double size = std::max(glm::length(hi - lo), 1e-30);
  if (view.orthographic) {
    // The trace sees everything along the ray, in front of the eye or not.
    range.nearPlane = nearest - 0.01 * size;
    range.farPlane = farthest + 0.01 * size;
  } else {
    // Reverse Z in float keeps depth precision however small the near plane:
    // a millionth of the scene clips nothing the trace would show.
    range.nearPlane = std::max(nearest, 1e-6 * size);
    range.nearPlane = std::min(range.nearPlane, 1e-3 * std::max(farthest, size));
    range.farPlane = farthest;
  }
  return range;
}

std::vector<vk::GraphicsProgramDesc> RasterPass::programDescs(const vk::Context& context) {
  vk::GraphicsProgramDesc desc;
  desc.name = "raster";
  desc.vertexSpirv = kSpvRasterVertex;
  desc.fragmentSpirv = kSpvRasterFragment;
  desc.colorFormat = kCompositeFormat;
  desc.depthFormat = kDepthFormat;
  vk::GraphicsProgramDesc depthOnly = desc;
  depthOnly.name = "raster depth";
  depthOnly.fragmentSpirv = kSpvRasterDepth;
  depthOnly.colorWrite = false;
  vk::GraphicsProgramDesc mask = desc;
  mask.name = "raster depth and mask";
  mask.fragmentSpirv = kSpvRasterMask;
  mask.colorFormat = kMaskFormat;
  desc.depthCompare = VK_COMPARE_OP_EQUAL;  // only the fragment the pre-pass kept
  desc.depthWrite = false;
  std::vector<vk::GraphicsProgramDesc> descs = {depthOnly, mask, desc};
  if (context.caps().fillModeNonSolid) {
    desc.name = "raster wireframe";
    desc.polygonMode = VK_POLYGON_MODE_LINE;
    desc.depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL;
    desc.depthWrite = false;
    desc.depthBias = 4.0f;  // reverse Z: towards the camera, over the face's own depth
    desc.blend = true;
    descs.push_back(desc);
  }
  return descs;
}

RasterPass::RasterPass(vk::Context& context)
    : context_(context),
      noMap_(context, {sizeof(gpu::RefractionTexel), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryDomain::Device,
                       "no refraction map"}) {
  std::vector<vk::GraphicsProgramDesc> descs = programDescs(context);
  depth_ = std::make_unique<vk::GraphicsProgram>(context, descs[0]);
  mask_ = std::make_unique<vk::GraphicsProgram>(context, descs[1]);
  fill_ = std::make_unique<vk::GraphicsProgram>(context, descs[2]);
  if (descs.size() > 3) wire_ = std::make_unique<vk::GraphicsProgram>(context, descs[3]);
}

RasterPass::~RasterPass() = default;

gpu::RasterPush RasterPass::push(const RasterScene& scene, const FrameSettings& settings,
                                 const RasterOptions& options) const {
  const scene::View& v = settings.view;
  double aspect = double(settings.width) / double(settings.height);
  gpu::RasterPush push{};
  push.right = glm::vec4(glm::vec3(v.right), float(1.0 / (v.halfHeight * aspect)));
  push.up = glm::vec4(glm::vec3(v.up), float(1.0 / v.halfHeight));
  const DepthRange depth = options.depth.value_or(DepthRange{});
  push.forward = glm::vec4(glm::vec3(v.forward), float(depth.nearPlane));
  push.eye = glm::vec4(glm::vec3(v.eye - scene.origin), float(depth.farPlane));
  push.wireColor = options.wireColor;
  push.flags = v.orthographic ? gpu::kRasterFlagOrthographic : 0u;
  push.lightCount = scene.lightCount;
  push.shiftX = float(v.shift.x);
  push.shiftY = float(v.shift.y);
  if (options.refraction) push.flags |= uint32_t(options.screenSpace);
  if (options.refraction && options.screenSpace == ScreenSpace::RefractionMap) {
    if (!options.refractionMap || options.refractionMap->width == 0 || options.refractionMap->height == 0) {
      throw vk::VulkanError("raster pass: the refraction-map method needs a baked map (Renderer::bakeRefractionMap)");
    }
    push.mapWidth = options.refractionMap->width;
    push.mapHeight = options.refractionMap->height;
  }
  push.offsetStrength = options.offsetStrength;
  return push;
}

void RasterPass::drawItems(vk::Commands& commands, const vk::GraphicsProgram& program, const RasterScene& scene,
                           const RasterOptions& options, const gpu::RasterPush& push,
                           std::span<const vk::BufferBinding> resources, VkRect2D area) const {
  program.bind(commands, resources, area);
  const SceneGpu& gpuScene = *scene.scene;
  for (size_t item = 0; item < gpuScene.itemGeometry.size(); ++item) {
    const GeometryRange& g = gpuScene.geometries[gpuScene.itemGeometry[item]];
    // Without refraction glass is left out and seen straight through, as IOR 1 would show it.
    if (!options.refraction && gpuScene.itemRefractive[item]) continue;
    program.draw(commands, push, 3 * g.triangleCount, 3 * g.firstTriangle, static_cast<uint32_t>(item));
  }
}

void RasterPass::recordDepth(vk::Commands& commands, const RasterScene& scene, const FrameSettings& settings,
                             const RasterOptions& options, const vk::Image& depth, const vk::Image* mask,
                             const vk::Image& colorTarget) const {
  recordDepthPass(commands, scene, settings, options, depth, mask, colorTarget, 0u, pass::kRasterDepth);
}

void RasterPass::recordDepthPass(vk::Commands& commands, const RasterScene& scene, const FrameSettings& settings,
                                 const RasterOptions& options, const vk::Image& depth, const vk::Image* mask,
                                 const vk::Image& colorTarget, uint32_t extraFlags, const char* passName) const {
  for (const vk::Image* image : {&depth, mask, &colorTarget}) {
    if (image && (image->width() != settings.width || image->height() != settings.height)) {
      throw vk::VulkanError("raster pass: image '" + image->name() + "' is not the frame's size");
    }
  }
  commands.beginPass(passName);
  VkRect2D area{{0, 0}, {settings.width, settings.height}};
  const float clearMask[4] = {0.0f, 0.0f, 0.0f, 0.0f};  // the uint attachment clears to 0
  {
    vk::RenderingScope scope(commands, mask ? *mask : colorTarget, &depth, area, mask ? clearMask : nullptr, true);
    std::vector<vk::BufferBinding> resources;
    scene.scene->appendBindings(resources, *scene.instances, *scene.lights);
    gpu::RasterPush p = push(scene, settings, options);
    p.flags |= extraFlags;
    drawItems(commands, mask ? *mask_ : *depth_, scene, options, p, resources, area);
  }
  commands.endPass();
}

void RasterPass::recordShading(vk::Commands& commands, const RasterScene& scene, const FrameSettings& settings,
                               const RasterOptions& options, const vk::Image& traceImage, const vk::Image& target,
                               const vk::Image& depth, const vk::Image& behindDepth, bool traced) const {
  recordShadingPass(commands, scene, settings, options, traceImage, target, depth, behindDepth,
                    traced ? gpu::kRasterFlagTraced : 0u, pass::kRasterShading);
}

void RasterPass::recordShadingPass(vk::Commands& commands, const RasterScene& scene, const FrameSettings& settings,
                                   const RasterOptions& options, const vk::Image& traceImage, const vk::Image& target,
                                   const vk::Image& depth, const vk::Image& behindDepth, uint32_t extraFlags,
                                   const char* passName) const {
  for (const vk::Image* image : {&traceImage, &target, &depth, &behindDepth}) {
    if (image->width() != settings.width || image->height() != settings.height) {
      throw vk::VulkanError("raster pass: image '" + image->name() + "' is not the frame's size");
    }
  }
  if (options.wireframe && !wire_) {
    throw vk::VulkanError("raster pass: this device cannot draw wireframes (no fillModeNonSolid)");
  }
  // The trace image (and deformed vertices), written by compute, become
  // visible to the fragment shaders; the pre-pass's depth to the depth test.
  commands.computeToGraphics();
  commands.barrier(VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                   VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT);
  commands.beginPass(passName);
  VkRect2D area{{0, 0}, {settings.width, settings.height}};
  float clear[4] = {settings.background.r, settings.background.g, settings.background.b, settings.backgroundAlpha};
  {
    vk::RenderingScope scope(commands, target, &depth, area, clear, false);
    const vk::Buffer& map = options.refractionMap && options.screenSpace == ScreenSpace::RefractionMap
                                ? options.refractionMap->texels
                                : noMap_;
    std::vector<vk::BufferBinding> resources = {{gpu::kRasterBindingTraceImage, nullptr, &traceImage},
                                                {gpu::kRasterBindingBehindDepth, nullptr, &behindDepth},
                                                {gpu::kRasterBindingRefractionMap, &map, nullptr}};
    scene.scene->appendBindings(resources, *scene.instances, *scene.lights);
    gpu::RasterPush p = push(scene, settings, options);
    p.flags |= extraFlags;
    drawItems(commands, *fill_, scene, options, p, resources, area);
    if (options.wireframe) {
      p.flags |= gpu::kRasterFlagWireframe;
      drawItems(commands, *wire_, scene, options, p, resources, area);
    }
  }
  commands.endPass();
}

void RasterPass::recordBehind(vk::Commands& commands, const RasterScene& scene, const FrameSettings& settings,
                              const RasterOptions& options, const vk::Image& depth, const vk::Image& behindDepth,
                              const vk::Image& behind) const {
  RasterOptions opaque = options;
  opaque.refraction = false;  // glass left out: what lies behind it
  opaque.wireframe = false;
  recordDepthPass(commands, scene, settings, opaque, depth, &behindDepth, behind, gpu::kRasterFlagBehindDepth,
                  "behind depth");
  recordShadingPass(commands, scene, settings, opaque, behind, behind, depth, behindDepth, 0u, "behind shading");
  // The picture and its depth become what the shading pass's fragments read;
  // the depth attachment is cleared again by the next pre-pass.
  commands.barrier(VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT,
                   VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                   VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT,
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                       VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
}

}  // namespace snell::render
