// The frame: what changed since the GPU last saw the scene, the passes that
// follow from it, and the readbacks, recorded into one submission per frame.
#include "render/renderer.h"

#include "render/pass_names.h"
#include "vk/error.h"

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace snell::render {

namespace {

constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

void rows(const glm::dmat4& m, glm::vec4 out[3]) {
  for (int r = 0; r < 3; ++r) out[r] = glm::vec4(glm::dvec4(m[0][r], m[1][r], m[2][r], m[3][r]));
}

std::vector<glm::vec4> unpackHalves(const std::byte* data, size_t pixels) {
  std::vector<glm::vec4> rgba(pixels);
  const auto* halves = reinterpret_cast<const uint16_t*>(data);
  for (size_t i = 0; i < pixels; ++i) {
    for (int c = 0; c < 4; ++c) rgba[i][c] = glm::unpackHalf1x16(halves[4 * i + size_t(c)]);
  }
  return rgba;
}

}  // namespace

// One frame in flight: its commands, the host data it uploads, what it reads back.
struct Renderer::Slot {
  Slot(vk::Context& context, size_t index)
      : commands(context, "frame " + std::to_string(index)), arena(context, "frame uploads " + std::to_string(index)) {}
  vk::Commands commands;
  vk::UploadArena arena;
  vk::Buffer readback;  ///< SAH statistics of both levels, dropped triangles, pixels traced per view
  VkDeviceSize topStatsAt = 0, droppedAt = 0, pixelCountsAt = 0;
  uint64_t frame = 0;
  bool pending = false;
  FrameResult result;
  std::vector<uint32_t> refitGroups, builtGroups;  ///< bottom-level groups to read the SAH of
  bool topRefit = false, topBuilt = false;
  struct ViewReadback {
    size_t view = 0;
    uint32_t width = 0, height = 0;
    bool trace = true, composite = false, aov = false, half = false;
    vk::Buffer pixels;  ///< trace image (when asked for), then composite, then AOV
  };
  std::vector<ViewReadback> readbacks;
  /// Readback buffers of earlier frames, reused: a fresh mapped allocation each frame costs the host more than the copy.
  std::vector<vk::Buffer> spareReadbacks;
  std::vector<size_t> maskedViews;  ///< views whose pixel count the GPU counted (index into the frame's views)
};

// What the renderer keeps per view index: its images and what it last drew.
struct Renderer::View {
  ViewImages images;
  vk::Buffer rays;
  bool fresh = false;  ///< images just made: UNDEFINED to GENERAL before use
  bool rendered = false;
  uint64_t version = 0;
  ViewRequest last;
};

// The host's plan for a frame's update.
struct Renderer::Update {
  bool work = false;  ///< any view: the frame's scene work runs
  bool trees = false;
  bool driver = false;  ///< some view traces through the driver's ray tracing
  std::vector<uint32_t> deform;  ///< DeformPass outputs
  bool instancesChanged = false, lightsChanged = false;
  std::vector<gpu::GpuInstance> instances;
  std::vector<gpu::GpuLight> lights;
  std::vector<uint32_t> build, refit;  ///< bottom-level groups (refit lists the built ones too, for their SAH)
  bool buildTop = false, refitTop = false;
};

Renderer::Renderer(vk::Context& context, const scene::Scene& scene, const scene::Pose& pose, RendererOptions options)
    : context_(context), sceneModel_(scene), options_(options),
      scene_(uploadScene(context, scene, pose, options.host.positions ? &options.host : nullptr)), bounds_(scene),
      rebuilds_(scene_.geometries.size(), options.rebuildGrowth) {
  if (options_.framesInFlight == 0) throw std::invalid_argument("renderer: framesInFlight must be at least 1");
  deform_ = std::make_unique<DeformPass>(context, scene, pose, [&](int item) {
    for (const GeometryRange& g : scene_.geometries) {
      if (g.item == item) return DeformSlot{&scene_.positions, &scene_.normals, g.firstVertex};
    }
    throw std::logic_error("deforming item without a geometry");
  });
  raster_ = std::make_unique<RasterPass>(context);
  trace_ = std::make_unique<TracePass>(context, scene, scene_);
  std::string name = scene.source.empty() ? std::string("scene") : scene.source;
  size_t lightNodes = 0;
  for (const scene::Node& node : scene.nodes) lightNodes += node.light >= 0 ? 1 : 0;
  instances_ = vk::Buffer(context, {std::max<size_t>(pose.items.size(), 1) * sizeof(gpu::GpuInstance),
                                    kStorage | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT, vk::MemoryDomain::Device,
                                    name + " instances"});
  lights_ = vk::Buffer(context, {std::max<size_t>(lightNodes, 1) * sizeof(gpu::GpuLight), kStorage,
                                 vk::MemoryDomain::Device, name + " lights"});
  for (char r : scene_.itemSeeThrough) seeThrough_ = seeThrough_ || r;

  items_.resize(pose.items.size());
  itemDeformOutput_.assign(pose.items.size(), ~0u);
  for (size_t o = 0; o < deform_->outputs().size(); ++o) {
    itemDeformOutput_[size_t(deform_->outputs()[o].item)] = static_cast<uint32_t>(o);
  }
  geometryDirty_.assign(scene_.geometries.size(), 1);
  for (uint32_t i = 0; i < options_.framesInFlight; ++i) slots_.push_back(std::make_unique<Slot>(context, i));
}

Renderer::~Renderer() {
  try {
    finish();
  } catch (...) {
    // A lost device is reported by the frame that met it; nothing more to do here.
  }
}

const ViewImages& Renderer::viewImages(size_t index) const { return views_.at(index).images; }

void Renderer::invalidateViews() {
  for (View& v : views_) v.rendered = false;
}

RefractionBake Renderer::bakeRefractionMap(const scene::Pose& pose, const FrameSettings& settings, size_t view) {
  RefractionBake bake = bakeRefraction(*this, pose, settings);
  RefractionMapBuffer map = uploadRefractionMap(context_, bake);
  finish();  // no frame in flight reads the old map when it goes
  if (maps_.size() <= view) maps_.resize(view + 1);
  maps_[view] = std::move(map);
  invalidateViews();  // a view that reads a kept map sees a new one through the same pointer
  return bake;
}

const RefractionMapBuffer& Renderer::refractionMap(size_t view) const {
  static const RefractionMapBuffer none;
  return view < maps_.size() ? maps_[view] : none;
}

void Renderer::markDirty(int shape) {
  if (shape < 0 || size_t(shape) >= sceneModel_.shapes.size()) {
    throw std::invalid_argument("renderer: no shape " + std::to_string(shape) + " to mark dirty");
  }
  for (size_t g = 0; g < scene_.geometries.size(); ++g) {
    if (scene_.geometries[g].shape != shape) continue;
    geometryDirty_[g] = 1;
    trace_->noteGeometryMoved(uint32_t(g));
  }
  ++sceneVersion_;
}

void Renderer::setShapeBounds(int shape, const glm::dvec3& lo, const glm::dvec3& hi) {
  if (shape < 0 || size_t(shape) >= sceneModel_.shapes.size() || !sceneModel_.shapes[size_t(shape)].host) {
    throw std::invalid_argument("renderer: no host shape " + std::to_string(shape) + " to bound");
  }
  bounds_.setShapeBox(shape, lo, hi);
}

void Renderer::invalidateTrees() {
  treesBuilt_ = false;
  topBuilt_ = false;
}

void Renderer::prepareTrees() {
  if (builder_) return;
  builder_ = std::make_unique<BvhBuilder>(context_);
  std::vector<uint32_t> counts;
  for (const GeometryRange& g : scene_.geometries) counts.push_back(g.triangleCount);
  std::string name = sceneModel_.source.empty() ? std::string("scene") : sceneModel_.source;
  blas_ = std::make_unique<Bvh>(builder_->makeBvh(counts, BvhLeaves::Triangles, name + " bottom level"));
  tlas_ = std::make_unique<Bvh>(builder_->makeBvh({static_cast<uint32_t>(scene_.itemGeometry.size())},
                                                  BvhLeaves::Instances, name + " top level"));
}

uint64_t Renderer::memoryBytes() const {
  uint64_t bytes = scene_.bytes + deform_->bytes() + instances_.size() + lights_.size();
  if (blas_) {
    bytes += blas_->treeBytes() + tlas_->treeBytes() + blas_->workBytes() + tlas_->workBytes() + builder_->scratchBytes();
  }
  bytes += trace_->bytes();
  return bytes;
}

std::vector<std::string> Renderer::pipelineStatistics() const { return trace_->statistics(); }

double Renderer::treeBytesPerTriangle() const {
  if (!blas_ || scene_.triangleCount == 0) return 0.0;
  return double(blas_->treeBytes() + tlas_->treeBytes()) / scene_.triangleCount;
}

bool Renderer::viewNeedsTrees(const ViewRequest& request) const {
  if (request.output == ViewOutput::Trace) return !request.driverTrace;
  return request.raster.refraction && request.raster.screenSpace == ScreenSpace::Off && seeThrough_ &&
         transmissiveInView(request.settings);
}

bool Renderer::transmissiveInView(const FrameSettings& settings) const {
  return bounds_.anyInView(settings, scene_.itemSeeThrough);
}

Renderer::Update Renderer::planUpdate(const scene::Pose& pose, const std::vector<ViewRequest>& views,
                                      FrameStats& stats) {
  Update u;
  u.work = !views.empty();
  if (!u.work) return u;

  // Where every item is (bounding spheres), for culling and the origin.
  bounds_.place(pose);
  if (options_.independentFrames) origin_ = FrameOrigin();
  stats.rebased = origin_.follow(views.front().settings.view.eye, bounds_);
  const glm::dvec3 origin = origin_.origin();

  // Deform what changed.
  for (size_t i = 0; i < pose.items.size(); ++i) {
    if (itemDeformOutput_[i] == ~0u) continue;
    const scene::DrawItem& item = pose.items[i];
    ItemState& state = items_[i];
    if (state.deformed && state.weights == item.weights && state.joints == item.jointMatrices) {
      ++stats.itemsDeformSkipped;
      continue;
    }
    state.deformed = true;
    state.weights = item.weights;
    state.joints = item.jointMatrices;
    u.deform.push_back(itemDeformOutput_[i]);
    ++stats.itemsDeformed;
    for (size_t g = 0; g < scene_.geometries.size(); ++g) {
      if (scene_.geometries[g].item != int(i)) continue;
      geometryDirty_[g] = 1;
      trace_->noteGeometryMoved(uint32_t(g));
    }
  }

  // Instances and lights, relative to the origin in double, so float data near
  // the camera keeps its precision however far the scene is from the world's origin.
  u.instances.resize(pose.items.size());
  for (size_t i = 0; i < pose.items.size(); ++i) {
    const scene::DrawItem& item = pose.items[i];
    // Skinned positions come out of the deform pass relative to the item's anchor.
    glm::dmat4 toWorld = item.world;
    if (item.skinned) toWorld = glm::dmat4(1.0), toWorld[3] = glm::dvec4(DeformPass::anchorOf(item), 1.0);
    toWorld[3] -= glm::dvec4(origin, 0.0);
    gpu::GpuInstance inst{};
    rows(toWorld, inst.objectToWorld);
    rows(glm::inverse(toWorld), inst.worldToObject);
    inst.geometry = scene_.itemGeometry[i];
    inst.material = scene_.itemMaterial[i];
    u.instances[i] = inst;
  }
  u.instancesChanged = uploadedInstances_.size() != u.instances.size() ||
                       std::memcmp(uploadedInstances_.data(), u.instances.data(),
                                   u.instances.size() * sizeof(gpu::GpuInstance)) != 0;
  for (size_t n = 0; n < sceneModel_.nodes.size() && n < pose.world.size(); ++n) {
    int index = sceneModel_.nodes[n].light;
    if (index < 0 || size_t(index) >= sceneModel_.lights.size()) continue;
    const scene::Light& light = sceneModel_.lights[size_t(index)];
    glm::dmat4 world(pose.world[n]);
    gpu::GpuLight g{};
    uint32_t type = light.type == scene::LightType::Directional ? gpu::kLightDirectional
                    : light.type == scene::LightType::Point     ? gpu::kLightPoint
                                                                : gpu::kLightSpot;
    g.positionType = glm::vec4(glm::vec3(glm::dvec3(world[3]) - origin), float(type));
    glm::dvec3 direction = -glm::normalize(glm::dvec3(world[2]));
    g.direction = glm::vec4(glm::vec3(direction), std::isfinite(light.range) ? light.range : 0.0f);
    g.radiance = glm::vec4(light.color * light.intensity, 0.0f);
    g.cone = glm::vec4(std::cos(light.innerConeAngle), std::cos(light.outerConeAngle), 0.0f, 0.0f);
    u.lights.push_back(g);
  }
  u.lightsChanged = uploadedLights_.size() != u.lights.size() ||
                    std::memcmp(uploadedLights_.data(), u.lights.data(), u.lights.size() * sizeof(gpu::GpuLight)) != 0;
  if (!u.deform.empty() || u.instancesChanged || u.lightsChanged) ++sceneVersion_;

  // Trees, only when some view traces.
  for (const ViewRequest& v : views) u.trees = u.trees || viewNeedsTrees(v);
  for (const ViewRequest& v : views) u.driver = u.driver || (v.output == ViewOutput::Trace && v.driverTrace);
  if (!u.trees) return u;
  prepareTrees();
  if (options_.independentFrames) treesBuilt_ = topBuilt_ = false;
  bool bottomChanged = false;
  if (!treesBuilt_) {
    for (uint32_t g = 0; g < scene_.geometries.size(); ++g) u.build.push_back(g);
    rebuilds_.clear();
  } else {
    // Rebuilds the SAH asked for, within the budget (at least one a frame).
    std::vector<uint32_t> triangles;
    for (const GeometryRange& g : scene_.geometries) triangles.push_back(g.triangleCount);
    u.build = rebuilds_.take(options_.rebuildBudget, triangles);
  }
  for (uint32_t g : u.build) geometryDirty_[g] = 0;
  u.refit = u.build;  // a refit right after a build measures the new tree's SAH
  for (uint32_t g = 0; g < scene_.geometries.size(); ++g) {
    if (!geometryDirty_[g]) continue;
    geometryDirty_[g] = 0;
    u.refit.push_back(g);
  }
  bottomChanged = !u.refit.empty();
  stats.treesBuilt = static_cast<uint32_t>(u.build.size());
  stats.treesRefit = static_cast<uint32_t>(u.refit.size() - u.build.size());
  stats.treesSkipped = static_cast<uint32_t>(scene_.geometries.size() - u.refit.size());
  for (uint32_t g : u.build) stats.trianglesBuilt += scene_.geometries[g].triangleCount;
  for (size_t k = u.build.size(); k < u.refit.size(); ++k) stats.trianglesRefit += scene_.geometries[u.refit[k]].triangleCount;
  treesBuilt_ = true;

  if (rebuilds_.takeTopRebuild() || !topBuilt_) {
    u.buildTop = u.refitTop = true;
    topBuilt_ = true;
    topDirty_ = false;
  } else if (topDirty_ || u.instancesChanged || bottomChanged) {
    u.refitTop = true;
    topDirty_ = false;
  }
  stats.topLevelBuilt = u.buildTop ? 1 : 0;
  stats.topLevelRefit = u.refitTop && !u.buildTop ? 1 : 0;
  stats.topLevelSkipped = u.refitTop ? 0 : 1;
  return u;
}

void Renderer::recordUpdate(vk::Commands& commands, Slot& slot, const scene::Pose& pose, const Update& u) {
  if (u.instancesChanged) {
    slot.arena.copy(commands, u.instances, instances_);
    uploadedInstances_ = u.instances;
    topDirty_ = topDirty_ || !u.trees;  // trees skipped this frame: the top level catches up later
  }
  if (u.lightsChanged) {
    slot.arena.copy(commands, u.lights, lights_);
    uploadedLights_ = u.lights;
  }
  lightCount_ = static_cast<uint32_t>(u.lights.size());
  commands.barrier(VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                   VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_VERTEX_SHADER_BIT |
                       VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT);
  if (!u.deform.empty()) {
    commands.beginPass(pass::kDeform);
    deform_->record(commands, pose, slot.arena, u.deform);
    commands.endPass();
  }
  if (u.driver) {
    trace_->recordDriverUpdate(commands, slot.arena, scene_, u.instances, u.instancesChanged);
  } else if (u.instancesChanged) {
    trace_->noteInstancesMoved();
  }
  if (!u.trees) return;
  BvhInputs triangles{&scene_.positions, &scene_.indices, nullptr, nullptr};
  if (!u.build.empty()) {
    commands.beginPass(pass::kBlasBuild);
    builder_->recordBuild(commands, *blas_, triangles, u.build, slot.arena);
    commands.endPass();
  }
  if (!u.refit.empty()) {
    // Counts the triangles the refit finds non-finite (it covers every tree built this frame too).
    commands.fillBuffer(blas_->dropped, 0);
    commands.transferToCompute();
    commands.beginPass(pass::kBlasRefit);
    builder_->recordRefit(commands, *blas_, triangles, u.refit, slot.arena);
    commands.endPass();
  }
  slot.refitGroups = u.refit;
  slot.builtGroups = u.build;
  if (u.refitTop) {
    commands.beginPass(pass::kTlas);
    BvhInputs top{nullptr, nullptr, &instances_, blas_.get()};
    if (u.buildTop) builder_->recordBuild(commands, *tlas_, top, {}, slot.arena);
    builder_->recordRefit(commands, *tlas_, top, {}, slot.arena);
    commands.endPass();
  }
  slot.topRefit = u.refitTop;
  slot.topBuilt = u.buildTop;
}

void Renderer::recordTrace(vk::Commands& commands, const ViewRequest& request, View& view, bool masked,
                           FrameStats& stats) {
  TraceInputs in{&scene_, &instances_, &lights_, lightCount_, origin_.origin(), blas_.get(), tlas_.get()};
  TraceTarget target{&view.images.trace, request.aov ? &view.images.aov : nullptr,
                     request.settings.rays.empty() ? nullptr : &view.rays, &view.images.mask, &view.images.pixels};
  if (request.output == ViewOutput::Trace && request.driverTrace) {
    stats.pixelsTraced += trace_->recordDriver(commands, in, request.settings, target);
  } else {
    stats.pixelsTraced += trace_->record(commands, in, request.settings, target, masked);
  }
  ++stats.traceDispatches;
}

void Renderer::recordView(vk::Commands& commands, Slot& slot, size_t index, const ViewRequest& request,
                          FrameStats& stats) {
  View& view = views_[index];
  const FrameSettings& settings = request.settings;
  bool unchanged = view.rendered && view.version == sceneVersion_ && request == view.last;
  if (unchanged) {
    ++stats.viewsSkipped;
  } else {
    ++stats.viewsRendered;
    if (!settings.rays.empty()) slot.arena.copy(commands, [&] {
        std::vector<gpu::GpuRay> rays(settings.rays.size());
        for (size_t i = 0; i < rays.size(); ++i) {
          // Relative to the origin in double, like the instances, before the cast to float.
          rays[i].origin = glm::vec4(glm::vec3(settings.rays[i].origin - origin_.origin()), 1.0f);
          rays[i].direction = glm::vec4(glm::vec3(glm::normalize(settings.rays[i].direction)), 0.0f);
        }
        return rays;
      }(), view.rays);
    if (!settings.rays.empty()) commands.transferToCompute();
    RasterScene scene{&scene_, &sceneModel_, &instances_, &lights_, lightCount_, origin_.origin()};
    if (request.output == ViewOutput::Trace) {
      recordTrace(commands, request, view, false, stats);
    } else {
      RasterOptions raster = request.raster;
      if (!raster.refractionMap && refractionMap(index).width > 0) raster.refractionMap = &maps_[index];
      if (!raster.depth) {
        // Near and far planes around the items' spheres at this pose: loose
        // enough for any deformation, and reverse Z keeps the precision.
        glm::dvec3 lo, hi;
        bounds_.box(lo, hi);
        raster.depth = fitDepthRange(settings.view, lo, hi);
      }
      bool glass = raster.refraction && seeThrough_ && transmissiveInView(settings);
      bool traces = glass && raster.screenSpace == ScreenSpace::Off;
      bool masked = traces && request.masked;
      // A screen-space method draws what lies behind the glass first, into the trace image.
      if (glass && !traces && raster.screenSpace != ScreenSpace::RefractionMap) {
        raster_->recordBehind(commands, scene, settings, raster, view.images.depth, view.images.mask, view.images.trace);
      }
      raster_->recordDepth(commands, scene, settings, raster, view.images.depth, masked ? &view.images.mask : nullptr,
                           view.images.composite);
      if (traces) {
        recordTrace(commands, request, view, masked, stats);
        if (masked) slot.maskedViews.push_back(index);
      }
      raster_->recordShading(commands, scene, settings, raster, view.images.trace, view.images.composite,
                             view.images.depth, view.images.mask, traces);
    }
    view.rendered = true;
    view.version = sceneVersion_;
    view.last = request;
    view.last.settings.rays.clear();
    if (!settings.rays.empty()) view.rendered = false;  // a ray list is never assumed the same
  }
  if (!request.readback.enabled) return;
  Slot::ViewReadback rb;
  rb.view = index;
  rb.width = settings.width;
  rb.height = settings.height;
  rb.composite = request.output == ViewOutput::Composite;
  rb.trace = !rb.composite || request.readback.trace;
  rb.aov = request.aov;
  rb.half = request.readback.half;
  VkDeviceSize pixels = VkDeviceSize(settings.width) * settings.height;
  VkDeviceSize images = pixels * 8 * ((rb.trace ? 1 : 0) + (rb.composite ? 1 : 0));
  VkDeviceSize bytes = images + (rb.aov ? pixels * sizeof(gpu::TraceAov) : 0);
  auto spare = std::find_if(slot.spareReadbacks.begin(), slot.spareReadbacks.end(),
                            [&](const vk::Buffer& b) { return b.size() >= bytes; });
  if (spare != slot.spareReadbacks.end()) {
    rb.pixels = std::move(*spare);
    slot.spareReadbacks.erase(spare);
  } else {
    rb.pixels = vk::Buffer(context_, {bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryDomain::Readback,
                                      "view " + std::to_string(index) + " readback"});
  }
  commands.barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                   VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_TRANSFER_READ_BIT);
  if (rb.trace) commands.copyImageToBuffer(view.images.trace, rb.pixels, 0);
  if (rb.composite) commands.copyImageToBuffer(view.images.composite, rb.pixels, rb.trace ? pixels * 8 : 0);
  if (rb.aov) commands.copyBuffer(view.images.aov, rb.pixels, pixels * sizeof(gpu::TraceAov), 0, images);
  slot.readbacks.push_back(std::move(rb));
}

uint64_t Renderer::submit(const FrameRequest& request) {
  if (!request.pose) throw std::invalid_argument("renderer: a frame needs a pose");
  const scene::Pose& pose = *request.pose;
  if (pose.items.size() != scene_.itemGeometry.size()) {
    throw std::invalid_argument("renderer: the pose has " + std::to_string(pose.items.size()) +
                                " draw items; it was built for " + std::to_string(scene_.itemGeometry.size()));
  }
  for (const ViewRequest& v : request.views) {
    checkImageSize(context_, v.settings.width, v.settings.height);
    if (!v.settings.rays.empty() && v.settings.rays.size() != size_t(v.settings.width) * v.settings.height) {
      throw std::invalid_argument("renderer: " + std::to_string(v.settings.rays.size()) + " rays for " +
                                  std::to_string(size_t(v.settings.width) * v.settings.height) + " pixels");
    }
    if (!v.settings.rays.empty() && v.output != ViewOutput::Trace) {
      throw std::invalid_argument("renderer: ray lists have no raster image");
    }
  }
  // The pipelines the views will trace with start compiling now, beside the update's.
  for (const ViewRequest& v : request.views) {
    trace_->prepare(v.settings);
    bool traces = v.output == ViewOutput::Trace ? !v.driverTrace
                                                : v.raster.refraction && v.raster.screenSpace == ScreenSpace::Off && seeThrough_;
    if (traces) trace_->prefetch(v.settings, v.aov, v.output == ViewOutput::Composite && v.masked);
  }
  uint64_t frame = ++submitted_;
  Slot& slot = *slots_[frame % slots_.size()];
  if (slot.pending) collect(slot);
  slot.frame = frame;
  slot.result = FrameResult{};
  slot.readbacks.clear();
  slot.maskedViews.clear();
  slot.refitGroups.clear();
  slot.builtGroups.clear();
  slot.topRefit = slot.topBuilt = false;
  slot.arena.reset();
  FrameStats& stats = slot.result.stats;
  stats.frame = frame;

  // Every view's images, at its size.
  if (views_.size() < request.views.size()) views_.resize(request.views.size());
  for (size_t i = 0; i < request.views.size(); ++i) {
    const ViewRequest& r = request.views[i];
    View& v = views_[i];
    ViewImages& im = v.images;
    bool composite = r.output == ViewOutput::Composite;
    bool resized = im.width != r.settings.width || im.height != r.settings.height;
    if (resized) v = View{};
    uint32_t w = r.settings.width, h = r.settings.height;
    std::string name = "view " + std::to_string(i);
    uint64_t pixels = uint64_t(w) * h;
    // Refused whole, before any of it is allocated, where the device cannot hold it.
    uint64_t needed = (im.trace.handle() ? 0 : pixels * 8) +
                      (composite && !im.composite.handle() ? pixels * (8 + 4 + 4 + 4) : 0) +
                      (r.aov && !im.aov.handle() ? pixels * sizeof(gpu::TraceAov) : 0) +
                      (!r.settings.rays.empty() && !v.rays.handle() ? pixels * sizeof(gpu::GpuRay) : 0);
    if (needed) context_.checkFits(needed, name + " at " + std::to_string(w) + "x" + std::to_string(h));
    im.width = w;
    im.height = h;
    if (!im.trace.handle()) {
      // A colour attachment too: the screen-space methods draw what lies behind the glass into it.
      im.trace = vk::Image(context_, {w, h, VK_FORMAT_R16G16B16A16_SFLOAT,
                                      VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                                          VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT,
                                      name + " trace"});
      v.fresh = true;
    }
    if (composite && !im.composite.handle()) {
      im.composite = vk::Image(context_, {w, h, kCompositeFormat,
                                          VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                              VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                          name + " composite"});
      im.depth = vk::Image(context_, {w, h, kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, name + " depth"});
      im.mask = vk::Image(context_, {w, h, kMaskFormat,
                                     VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
                                         VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                                     name + " transmissive mask"});
      im.pixels = vk::Buffer(context_, {sizeof(gpu::TracePixelListHeader) + pixels * 4,
                                        kStorage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, vk::MemoryDomain::Device,
                                        name + " pixels to trace"});
      v.fresh = true;
    }
    if (r.aov && !im.aov.handle()) {
      im.aov = vk::Buffer(context_, {pixels * sizeof(gpu::TraceAov), kStorage, vk::MemoryDomain::Device, name + " AOV"});
      v.rendered = false;
    }
    if (!r.settings.rays.empty() && !v.rays.handle()) {
      v.rays = vk::Buffer(context_, {pixels * sizeof(gpu::GpuRay), kStorage, vk::MemoryDomain::Device, name + " rays"});
    }
  }

  Update update = planUpdate(pose, request.views, stats);
  vk::Commands& commands = slot.commands;
  commands.setTimed(options_.passTimes);
  commands.begin();
  if (request.prologue) request.prologue(commands);
  // Frames in flight share the scene's GPU data: what this frame rewrites,
  // the one before may still be reading.
  commands.fullBarrier();
  for (size_t i = 0; i < request.views.size(); ++i) {
    View& v = views_[i];
    if (!v.fresh) continue;
    for (const vk::Image* image : {&v.images.trace, &v.images.composite, &v.images.depth, &v.images.mask}) {
      if (image->handle()) commands.imageLayout(*image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
    }
    v.fresh = false;
  }
  if (update.work) recordUpdate(commands, slot, pose, update);
  for (size_t i = 0; i < request.views.size(); ++i) recordView(commands, slot, i, request.views[i], stats);

  // What the host reads back of this frame: tree statistics, pixel counts.
  uint32_t groups = blas_ ? blas_->groupCount() : 0;
  slot.topStatsAt = uint64_t(groups) * 16;
  slot.droppedAt = slot.topStatsAt + 16;
  slot.pixelCountsAt = slot.droppedAt + 16;
  VkDeviceSize readbackBytes = slot.pixelCountsAt + 4 * std::max<size_t>(request.views.size(), 1);
  if (slot.readback.size() < readbackBytes) {
    slot.readback = vk::Buffer(context_, {readbackBytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryDomain::Readback,
                                          "frame statistics"});
  }
  commands.computeToTransfer();
  if (!slot.refitGroups.empty()) {
    commands.copyBuffer(blas_->stats, slot.readback, uint64_t(groups) * 16);
    commands.copyBuffer(blas_->dropped, slot.readback, 4, 0, slot.droppedAt);
  }
  if (slot.topRefit) commands.copyBuffer(tlas_->stats, slot.readback, 16, 0, slot.topStatsAt);
  for (size_t k = 0; k < slot.maskedViews.size(); ++k) {
    commands.copyBuffer(views_[slot.maskedViews[k]].images.pixels, slot.readback, 4, 0, slot.pixelCountsAt + 4 * k);
  }
  commands.transferToHost();
  if (request.record) request.record(commands);
  stats.dispatches = commands.dispatches();
  stats.draws = commands.draws();
  commands.submit(request.waitSemaphore, request.waitStage, request.signalSemaphore);
  slot.pending = true;
  return frame;
}

void Renderer::collect(Slot& slot) {
  slot.commands.wait();
  slot.pending = false;
  FrameResult& result = slot.result;
  result.passes = slot.commands.passTimes();
  const std::byte* data = slot.readback.mapped().data();
  auto word = [&](VkDeviceSize at) {
    uint32_t w;
    std::memcpy(&w, data + at, 4);
    return w;
  };
  auto sahAt = [&](VkDeviceSize at) {
    glm::uvec4 s;
    std::memcpy(&s, data + at, 16);
    return BvhBuilder::sahCost(s);
  };
  if (!slot.refitGroups.empty()) {
    result.stats.droppedTriangles = word(slot.droppedAt);
    std::vector<char> built(scene_.geometries.size(), 0);
    for (uint32_t g : slot.builtGroups) built[g] = 1;
    for (uint32_t g : slot.refitGroups) {
      double growth = rebuilds_.noteBottom(g, sahAt(uint64_t(g) * 16), built[g]);
      result.stats.sahGrowth = std::max(result.stats.sahGrowth, growth);
    }
  }
  if (slot.topRefit) rebuilds_.noteTop(sahAt(slot.topStatsAt), slot.topBuilt);
  for (size_t k = 0; k < slot.maskedViews.size(); ++k) result.stats.pixelsTraced += word(slot.pixelCountsAt + 4 * k);
  result.views.clear();
  for (Slot::ViewReadback& rb : slot.readbacks) {
    ViewPixels v;
    v.width = rb.width;
    v.height = rb.height;
    size_t pixels = size_t(rb.width) * rb.height;
    const std::byte* bytes = rb.pixels.mapped().data();
    const std::byte* composite = bytes + (rb.trace ? pixels * 8 : 0);
    if (rb.half) {
      const auto* halves = reinterpret_cast<const uint16_t*>(bytes);
      if (rb.trace) v.traceHalf.assign(halves, halves + 4 * pixels);
      const auto* compositeHalves = reinterpret_cast<const uint16_t*>(composite);
      if (rb.composite) v.compositeHalf.assign(compositeHalves, compositeHalves + 4 * pixels);
    } else {
      if (rb.trace) v.trace = unpackHalves(bytes, pixels);
      if (rb.composite) v.composite = unpackHalves(composite, pixels);
    }
    if (rb.aov) {
      v.aov.resize(pixels);
      std::memcpy(v.aov.data(), composite + (rb.composite ? pixels * 8 : 0), pixels * sizeof(gpu::TraceAov));
    }
    result.views.push_back(std::move(v));
    slot.spareReadbacks.push_back(std::move(rb.pixels));
  }
  // Views that changed size leave buffers nothing reuses: keep the latest few.
  constexpr size_t kSpareReadbacks = 4;
  if (slot.spareReadbacks.size() > kSpareReadbacks) {
    slot.spareReadbacks.erase(slot.spareReadbacks.begin(), slot.spareReadbacks.end() - kSpareReadbacks);
  }
  slot.readbacks.clear();
}

const FrameResult& Renderer::wait(uint64_t frame) {
  Slot& slot = *slots_[frame % slots_.size()];
  if (slot.frame != frame) {
    throw std::logic_error("renderer: frame " + std::to_string(frame) + " is no longer held (" +
                           std::to_string(slots_.size()) + " frames in flight)");
  }
  if (slot.pending) collect(slot);
  return slot.result;
}

void Renderer::finish() {
  for (auto& slot : slots_) {
    if (slot->pending) collect(*slot);
  }
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

namespace {

// One view, read back: what the two convenience calls below share.
RenderedFrame renderOneView(Renderer& renderer, const scene::Pose& pose, const ViewRequest& view,
                            std::vector<glm::vec4>* composite) {
  FrameRequest request;
  request.pose = &pose;
  request.views.push_back(view);
  request.views.back().readback.enabled = true;
  const FrameResult& result = renderer.wait(renderer.submit(request));
  RenderedFrame frame;
  frame.width = view.settings.width;
  frame.height = view.settings.height;
  frame.rgba = result.views.at(0).trace;
  frame.aov = result.views.at(0).aov;
  frame.droppedTriangles = result.stats.droppedTriangles;
  frame.passes = result.passes;
  frame.stats = result.stats;
  if (composite) *composite = result.views.at(0).composite;
  return frame;
}

}  // namespace

RenderedFrame renderFrame(Renderer& renderer, const scene::Pose& pose, const FrameSettings& settings, bool withAov) {
  ViewRequest view;
  view.settings = settings;
  view.aov = withAov;
  return renderOneView(renderer, pose, view, nullptr);
}

CompositeFrame renderComposite(Renderer& renderer, const scene::Pose& pose, const FrameSettings& settings,
                               const RasterOptions& options, bool withAov, bool masked) {
  ViewRequest view;
  view.settings = settings;
  view.output = ViewOutput::Composite;
  view.raster = options;
  view.masked = masked;
  view.aov = withAov;
  CompositeFrame frame;
  frame.trace = renderOneView(renderer, pose, view, &frame.rgba);
  return frame;
}

RefractionBake bakeRefraction(Renderer& renderer, const scene::Pose& pose, const FrameSettings& settings) {
  RenderedFrame frame = renderFrame(renderer, pose, settings, true);
  return bakeFromAov(frame.width, frame.height, frame.aov, renderer.scene());
}

}  // namespace snell::render
