// The frame's passes, recorded in order.
#include "render/renderer.h"

#include "vk/error.h"

#include "trace.spv.h"

#include <glm/gtc/packing.hpp>

#include <cstring>
#include <stdexcept>

namespace snell::render {

namespace {

std::vector<uint32_t> triangleCounts(const SceneGpu& scene) {
  std::vector<uint32_t> counts;
  for (const GeometryRange& g : scene.geometries) counts.push_back(g.triangleCount);
  return counts;
}

void rows(const glm::dmat4& m, glm::vec4 out[3]) {
  for (int r = 0; r < 3; ++r) out[r] = glm::vec4(glm::dvec4(m[0][r], m[1][r], m[2][r], m[3][r]));
}

}  // namespace

Renderer::Renderer(vk::Context& context, const scene::Scene& scene, const scene::Pose& layout)
    : context_(context),
      sceneModel_(scene),
      scene_(uploadScene(context, scene, layout)),
      builder_(context),
      arena_(context, "frame uploads") {
  deform_ = std::make_unique<DeformPass>(context, scene, layout, [&](int item) {
    for (const GeometryRange& g : scene_.geometries) {
      if (g.item == item) return DeformSlot{&scene_.positions, &scene_.normals, g.firstVertex};
    }
    throw std::logic_error("deforming item without a geometry");
  });
  std::string name = scene.source.empty() ? std::string("scene") : scene.source;
  blas_ = builder_.makeBvh(triangleCounts(scene_), BvhLeaves::Triangles, name + " bottom level");
  tlas_ = builder_.makeBvh({static_cast<uint32_t>(layout.items.size())}, BvhLeaves::Instances, name + " top level");
  instances_ = vk::Buffer(context, {std::max<size_t>(layout.items.size(), 1) * sizeof(gpu::GpuInstance),
                                    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryDomain::Upload, name + " instances"});
  size_t lightNodes = 0;
  for (const scene::Node& node : scene.nodes) lightNodes += node.light >= 0 ? 1 : 0;
  lights_ = vk::Buffer(context, {std::max<size_t>(lightNodes, 1) * sizeof(gpu::GpuLight), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                 vk::MemoryDomain::Upload, name + " lights"});
  static_assert(sizeof(gpu::TraceAov) == sizeof(gpu::GpuRay));
  placeholder_ = vk::Buffer(context, {sizeof(gpu::TraceAov), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                      vk::MemoryDomain::Device, "no AOV or ray list"});
  trace_ = std::make_unique<vk::ComputeProgram>(context, vk::ComputeProgramDesc{"trace", kSpvTrace, {}, false});
}

Renderer::~Renderer() = default;

uint64_t Renderer::memoryBytes() const {
  return scene_.bytes + instances_.size() + lights_.size() + blas_.treeBytes() + tlas_.treeBytes() +
         builder_.scratchBytes();
}

void Renderer::record(vk::Commands& commands, const scene::Pose& pose, const FrameSettings& settings,
                      const vk::Image& target, const vk::Buffer* aov, const vk::Buffer* rays) {
  update(commands, pose, settings.view.eye);
  trace(commands, settings, target, aov, rays);
}

void Renderer::update(vk::Commands& commands, const scene::Pose& pose, const glm::dvec3& origin) {
  if (pose.items.size() != scene_.itemGeometry.size()) {
    throw vk::VulkanError("renderer: the pose has " + std::to_string(pose.items.size()) + " draw items; it was built for " +
                          std::to_string(scene_.itemGeometry.size()));
  }
  const glm::dvec3 eye = origin;
  origin_ = origin;

  // Instances and lights, camera-relative: subtracted in double so the float
  // data near the camera keeps its precision however far it is from the origin.
  auto* instances = reinterpret_cast<gpu::GpuInstance*>(instances_.mapped().data());
  glm::dmat4 rebase = glm::dmat4(1.0);
  rebase[3] = glm::dvec4(-eye, 1.0);
  for (size_t i = 0; i < pose.items.size(); ++i) {
    // Skinned positions come out of the deform pass camera-relative already.
    glm::dmat4 toWorld = pose.items[i].skinned ? glm::dmat4(1.0) : rebase * pose.items[i].world;
    gpu::GpuInstance inst{};
    rows(toWorld, inst.objectToWorld);
    rows(glm::inverse(toWorld), inst.worldToObject);
    inst.geometry = scene_.itemGeometry[i];
    inst.material = scene_.itemMaterial[i];
    instances[i] = inst;
  }
  auto* lights = reinterpret_cast<gpu::GpuLight*>(lights_.mapped().data());
  uint32_t lightCount = 0;
  for (size_t n = 0; n < sceneModel_.nodes.size() && n < pose.world.size(); ++n) {
    int index = sceneModel_.nodes[n].light;
    if (index < 0 || size_t(index) >= sceneModel_.lights.size()) continue;
    const scene::Light& light = sceneModel_.lights[size_t(index)];
    glm::dmat4 world(pose.world[n]);
    gpu::GpuLight g{};
    uint32_t type = light.type == scene::LightType::Directional ? gpu::kLightDirectional
                    : light.type == scene::LightType::Point     ? gpu::kLightPoint
                                                                : gpu::kLightSpot;
    g.positionType = glm::vec4(glm::vec3(glm::dvec3(world[3]) - eye), float(type));
    glm::dvec3 direction = -glm::normalize(glm::dvec3(world[2]));
    g.direction = glm::vec4(glm::vec3(direction), std::isfinite(light.range) ? light.range : 0.0f);
    g.radiance = glm::vec4(light.color * light.intensity, 0.0f);
    g.cone = glm::vec4(std::cos(light.innerConeAngle), std::cos(light.outerConeAngle), 0.0f, 0.0f);
    lights[lightCount++] = g;
  }
  lightCount_ = lightCount;

  arena_.reset();
  // Counts the triangles this frame's box pass finds non-finite (RenderedFrame::droppedTriangles).
  commands.fillBuffer(blas_.dropped, 0);
  commands.transferToCompute();

  commands.beginPass("deform");
  deform_->record(commands, pose, eye);
  commands.endPass();

  BvhInputs triangles{&scene_.positions, &scene_.indices, nullptr, nullptr};
  if (!blasBuilt_) {
    commands.beginPass("blas build");
    builder_.recordBuild(commands, blas_, triangles, {}, arena_);
    commands.endPass();
    blasBuilt_ = true;
  } else {
    std::vector<uint32_t> deforming;
    for (size_t g = 0; g < scene_.geometries.size(); ++g) {
      if (scene_.geometries[g].item >= 0) deforming.push_back(static_cast<uint32_t>(g));
    }
    if (!deforming.empty()) {
      commands.beginPass("blas refit");
      builder_.recordRefit(commands, blas_, triangles, deforming, arena_);
      commands.endPass();
    }
  }

  commands.beginPass("tlas");
  builder_.recordBuild(commands, tlas_, {nullptr, nullptr, &instances_, &blas_}, {}, arena_);
  commands.endPass();
  updated_ = true;
}

void Renderer::trace(vk::Commands& commands, const FrameSettings& settings, const vk::Image& target,
                     const vk::Buffer* aov, const vk::Buffer* rays) {
  if (!updated_) throw vk::VulkanError("renderer: trace() before any update()");
  if (target.width() != settings.width || target.height() != settings.height) {
    throw vk::VulkanError("renderer: the target image is not the frame's size");
  }
  // After the top level; and between two views' traces, which both bind the
  // placeholder in the AOV slot the shader declares writable.
  commands.computeToCompute();
  commands.beginPass("trace");
  const scene::View& v = settings.view;
  double aspect = double(settings.width) / double(settings.height);
  gpu::TracePush push{};
  push.right = glm::vec4(glm::vec3(v.right), float(v.halfHeight * aspect));
  push.up = glm::vec4(glm::vec3(v.up), float(v.halfHeight));
  push.forward = glm::vec4(glm::vec3(v.forward), 0.0f);
  push.background = glm::vec4(settings.background, 1.0f);
  push.eye = glm::vec4(glm::vec3(v.eye - origin_), 0.0f);
  push.width = settings.width;
  push.height = settings.height;
  push.maxInterfaces = settings.maxInterfaces;
  push.lightCount = lightCount_;
  push.flags = (aov ? gpu::kTraceFlagAov : 0u) | (v.orthographic ? gpu::kTraceFlagOrthographic : 0u) |
               (rays ? gpu::kTraceFlagRayList : 0u);
  push.tilesX = (settings.width + gpu::kTraceTile - 1) / gpu::kTraceTile;
  push.shiftX = float(v.shift.x);
  push.shiftY = float(v.shift.y);
  uint32_t tilesY = (settings.height + gpu::kTraceTile - 1) / gpu::kTraceTile;
  trace_->dispatchGroups(commands,
                         {{gpu::kTraceBindingTlasNodes, &tlas_.nodes},
                          {gpu::kTraceBindingTlasGroups, &tlas_.groups},
                          {gpu::kTraceBindingInstances, &instances_},
                          {gpu::kTraceBindingBlasNodes, &blas_.nodes},
                          {gpu::kTraceBindingBlasGroups, &blas_.groups},
                          {gpu::kTraceBindingPositions, &scene_.positions},
                          {gpu::kTraceBindingNormals, &scene_.normals},
                          {gpu::kTraceBindingTexcoords, &scene_.texcoords},
                          {gpu::kTraceBindingIndices, &scene_.indices},
                          {gpu::kTraceBindingMaterials, &scene_.materials},
                          {gpu::kTraceBindingTextures, &scene_.textures},
                          {gpu::kTraceBindingTexels, &scene_.texels},
                          {gpu::kTraceBindingLights, &lights_},
                          {gpu::kTraceBindingImage, nullptr, &target},
                          {gpu::kTraceBindingAov, aov ? aov : &placeholder_},
                          {gpu::kTraceBindingRays, rays ? rays : &placeholder_}},
                         push, uint64_t(push.tilesX) * tilesY);
  commands.endPass();
}

void checkImageSize(const vk::Context& context, uint32_t width, uint32_t height) {
  if (width == 0 || height == 0) throw std::invalid_argument("the image size must be at least 1x1");
  uint32_t limit = 16384;  // maxImageDimension2D every Vulkan 1.3 device offers at least 4096; snell caps here
  VkPhysicalDeviceProperties properties;
  vkGetPhysicalDeviceProperties(context.physicalDevice(), &properties);
  limit = std::min(limit, properties.limits.maxImageDimension2D);
  if (width > limit || height > limit) {
    throw std::invalid_argument("the image size " + std::to_string(width) + "x" + std::to_string(height) +
                                " exceeds this device's limit of " + std::to_string(limit) + " pixels a side");
  }
}

FrameTargets makeFrameTargets(vk::Context& context, const FrameSettings& settings, bool withAov) {
  checkImageSize(context, settings.width, settings.height);
  FrameTargets t;
  t.image = vk::Image(context, {settings.width, settings.height, VK_FORMAT_R16G16B16A16_SFLOAT,
                                VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, "trace image"});
  size_t pixels = size_t(settings.width) * settings.height;
  if (withAov) {
    t.aov = vk::Buffer(context, {pixels * sizeof(gpu::TraceAov),
                                 VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                 vk::MemoryDomain::Device, "trace AOV"});
  }
  if (!settings.rays.empty()) {
    if (settings.rays.size() != pixels) {
      throw std::invalid_argument("renderFrame: " + std::to_string(settings.rays.size()) + " rays for " +
                                  std::to_string(pixels) + " pixels");
    }
    t.rays = vk::Buffer(context, {pixels * sizeof(gpu::GpuRay), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                  vk::MemoryDomain::Upload, "ray list"});
    auto* out = reinterpret_cast<gpu::GpuRay*>(t.rays.mapped().data());
    for (size_t i = 0; i < pixels; ++i) {
      // Camera-relative in double, like the instances, before the cast to float.
      out[i].origin = glm::vec4(glm::vec3(settings.rays[i].origin - settings.view.eye), 1.0f);
      out[i].direction = glm::vec4(glm::vec3(glm::normalize(settings.rays[i].direction)), 0.0f);
    }
  }
  return t;
}

std::vector<glm::vec4> downloadRgba16f(vk::Context& context, const vk::Image& image) {
  size_t pixels = size_t(image.width()) * image.height();
  std::vector<uint16_t> halves(pixels * 4);
  vk::downloadImage(context, image, halves.data());
  std::vector<glm::vec4> rgba(pixels);
  for (size_t i = 0; i < pixels; ++i) {
    for (int c = 0; c < 4; ++c) rgba[i][c] = glm::unpackHalf1x16(halves[4 * i + size_t(c)]);
  }
  return rgba;
}

RenderedFrame readFrame(vk::Context& context, const Renderer& renderer, const FrameTargets& targets,
                        const vk::Commands& commands) {
  RenderedFrame frame;
  frame.width = targets.image.width();
  frame.height = targets.image.height();
  frame.passes = commands.passTimes();
  frame.rgba = downloadRgba16f(context, targets.image);
  vk::download(context, renderer.blas().dropped, &frame.droppedTriangles, 4);
  if (targets.aov.handle()) {
    frame.aov.resize(frame.rgba.size());
    vk::download(context, targets.aov, frame.aov.data(), frame.aov.size() * sizeof(gpu::TraceAov));
  }
  return frame;
}

RenderedFrame renderFrame(vk::Context& context, Renderer& renderer, const scene::Pose& pose,
                          const FrameSettings& settings, bool withAov) {
  FrameTargets targets = makeFrameTargets(context, settings, withAov);
  vk::Commands commands(context, "frame");
  commands.begin();
  commands.imageLayout(targets.image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
  renderer.record(commands, pose, settings, targets.image, withAov ? &targets.aov : nullptr,
                  settings.rays.empty() ? nullptr : &targets.rays);
  commands.computeToTransfer();
  commands.submitAndWait();
  return readFrame(context, renderer, targets, commands);
}

}  // namespace snell::render
