// The raster pass: one draw per draw item over the trace's own buffers.
#include "render/raster_pass.h"

#include "shared/raster.h"
#include "vk/error.h"

#include "raster_depth.spv.h"
#include "raster_fragment.spv.h"
#include "raster_vertex.spv.h"

#include <algorithm>
#include <cmath>

namespace snell::render {

void fitDepthRange(const scene::View& view, const glm::dvec3& lo, const glm::dvec3& hi, RasterOptions& options) {
  if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) return;  // nothing drawn: any range will do
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
    options.nearPlane = nearest - 0.01 * size;
    options.farPlane = farthest + 0.01 * size;
  } else {
    // Reverse Z in float keeps depth precision however small the near plane:
    // a millionth of the scene clips nothing the trace would show.
    options.nearPlane = std::max(nearest, 1e-6 * size);
    options.nearPlane = std::min(options.nearPlane, 1e-3 * std::max(farthest, size));
    options.farPlane = farthest;
  }
}

RasterPass::RasterPass(vk::Context& context) : context_(context) {
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
  depth_ = std::make_unique<vk::GraphicsProgram>(context, depthOnly);
  desc.depthCompare = VK_COMPARE_OP_EQUAL;  // only the fragment the pre-pass kept
  desc.depthWrite = false;
  fill_ = std::make_unique<vk::GraphicsProgram>(context, desc);
  if (context.caps().fillModeNonSolid) {
    desc.name = "raster wireframe";
    desc.polygonMode = VK_POLYGON_MODE_LINE;
    desc.depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL;
    desc.depthWrite = false;
    desc.depthBias = 4.0f;  // reverse Z: towards the camera, over the face's own depth
    desc.blend = true;
    wire_ = std::make_unique<vk::GraphicsProgram>(context, desc);
  }
}

RasterPass::~RasterPass() = default;

void RasterPass::record(vk::Commands& commands, const Renderer& renderer, const FrameSettings& settings,
                        const vk::Image& traceImage, const vk::Image& target, const vk::Image& depth,
                        const RasterOptions& options) const {
  for (const vk::Image* image : {&traceImage, &target, &depth}) {
    if (image->width() != settings.width || image->height() != settings.height) {
      throw vk::VulkanError("raster pass: image '" + image->name() + "' is not the frame's size");
    }
  }
  if (options.wireframe && !wire_) {
    throw vk::VulkanError("raster pass: this device cannot draw wireframes (no fillModeNonSolid)");
  }
  const scene::View& v = settings.view;
  double aspect = double(settings.width) / double(settings.height);
  gpu::RasterPush push{};
  push.right = glm::vec4(glm::vec3(v.right), float(1.0 / (v.halfHeight * aspect)));
  push.up = glm::vec4(glm::vec3(v.up), float(1.0 / v.halfHeight));
  push.forward = glm::vec4(glm::vec3(v.forward), float(options.nearPlane));
  push.eye = glm::vec4(glm::vec3(v.eye - renderer.origin()), float(options.farPlane));
  push.wireColor = options.wireColor;
  push.flags = v.orthographic ? gpu::kRasterFlagOrthographic : 0u;
  push.lightCount = renderer.lightCount();
  push.shiftX = float(v.shift.x);
  push.shiftY = float(v.shift.y);

  // The one barrier: deformed vertices and the trace image, written by
  // compute, become visible to the vertex and fragment shaders.
  commands.computeToGraphics();
  commands.beginPass("raster");
  VkRect2D area{{0, 0}, {settings.width, settings.height}};
  float clear[4] = {settings.background.r, settings.background.g, settings.background.b, 1.0f};
  {
    vk::RenderingScope scope(commands, target, &depth, area, clear);
    const SceneGpu& scene = renderer.sceneGpu();
    const scene::Scene& model = renderer.scene();
    auto refractive = [&](int shape) {
      int material = shape >= 0 ? model.shapes[size_t(shape)].material : -1;
      return material >= 0 && model.materials[size_t(material)].refractive();
    };
    // Vertex-stage bindings first (slots 0 to kRasterBindingIndices): the depth pre-pass binds only those.
    constexpr size_t kVertexBindings = gpu::kRasterBindingIndices + 1;
    static_assert(gpu::kRasterBindingInstances == 0 && gpu::kRasterBindingMaterials == kVertexBindings);
    const vk::BufferBinding resources[] = {{gpu::kRasterBindingInstances, &renderer.instances()},
                                           {gpu::kRasterBindingPositions, &scene.positions},
                                           {gpu::kRasterBindingNormals, &scene.normals},
                                           {gpu::kRasterBindingTexcoords, &scene.texcoords},
                                           {gpu::kRasterBindingIndices, &scene.indices},
                                           {gpu::kRasterBindingMaterials, &scene.materials},
                                           {gpu::kRasterBindingTextures, &scene.textures},
                                           {gpu::kRasterBindingTexels, &scene.texels},
                                           {gpu::kRasterBindingLights, &renderer.lights()},
                                           {gpu::kRasterBindingTraceImage, nullptr, &traceImage}};
    auto drawItems = [&](const vk::GraphicsProgram& program, const gpu::RasterPush& p) {
      bool depthOnly = &program == depth_.get();
      program.bind(commands, std::span(resources).first(depthOnly ? kVertexBindings : std::size(resources)), area);
      for (size_t item = 0; item < scene.itemGeometry.size(); ++item) {
        const GeometryRange& g = scene.geometries[scene.itemGeometry[item]];
        // Without refraction glass is left out and seen straight through, as IOR 1 would show it.
        if (!options.refraction && refractive(g.shape)) continue;
        program.draw(commands, p, 3 * g.triangleCount, 3 * g.firstTriangle, static_cast<uint32_t>(item));
      }
    };
    drawItems(*depth_, push);
    drawItems(*fill_, push);
    if (options.wireframe) {
      gpu::RasterPush wirePush = push;
      wirePush.flags |= gpu::kRasterFlagWireframe;
      drawItems(*wire_, wirePush);
    }
  }
  commands.endPass();
}

CompositeFrame renderComposite(vk::Context& context, Renderer& renderer, const scene::Pose& pose,
                               const FrameSettings& settings, const RasterOptions& options, bool withAov) {
  if (!settings.rays.empty()) throw std::invalid_argument("renderComposite: ray lists have no raster image");
  RasterPass raster(context);
  FrameTargets targets = makeFrameTargets(context, settings, withAov);
  vk::Image composite(context, {settings.width, settings.height, kCompositeFormat,
                                VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "composite"});
  vk::Image depth(context, {settings.width, settings.height, kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                            "composite depth"});
  vk::Commands commands(context, "composite frame");
  commands.begin();
  for (const vk::Image* image : {&targets.image, &composite, &depth}) {
    commands.imageLayout(*image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
  }
  renderer.update(commands, pose, settings.view.eye);
  renderer.trace(commands, settings, targets.image, withAov ? &targets.aov : nullptr);
  raster.record(commands, renderer, settings, targets.image, composite, depth, options);
  commands.computeToTransfer();
  commands.graphicsToTransfer();
  commands.submitAndWait();
  CompositeFrame frame;
  frame.trace = readFrame(context, renderer, targets, commands);
  frame.rgba = downloadRgba16f(context, composite);
  return frame;
}

}  // namespace snell::render
