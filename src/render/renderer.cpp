// The frame: what changed since the GPU last saw the scene, the passes that
// follow from it, and the readbacks, recorded into one submission per frame.
// submit() reads top to bottom as the frame; the steps follow it in order.
#include "render/renderer.h"

#include "render/one_view.h"
#include "render/pass_names.h"
#include "vk/error.h"

#include <algorithm>
#include <utility>
#include <cstring>
#include <stdexcept>

namespace snell::render {

namespace {

constexpr VkBufferUsageFlags kStorage =
    VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

// Whether two tables hold the same bytes (empty ones included: memcmp may not see null pointers).
template <typename T>
bool sameBytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

BvhChildBoxes childBoxesOf(const RendererOptions& o) {
  return o.compactTrees ? BvhChildBoxes::Quantised : BvhChildBoxes::Exact;
}

}  // namespace

// What one view does this frame, decided once from its request and where the glass is.
struct Renderer::ViewPlan {
  bool traces = false;  ///< the view runs a trace
  bool driver = false;  ///< ... through the driver's ray tracing (trace output only)
  bool masked = false;  ///< ... of only the pixels whose visible face is see-through (composite)
  bool behind = false;  ///< a screen-space method first draws what lies behind the glass
  bool needsTrees() const { return traces && !driver; }
};

// What the renderer keeps per view index to skip a view nothing changed for.
struct Renderer::ViewState {
  bool rendered = false;
  uint64_t version = 0;
  ViewRequest last;
  uint64_t listed = 0;  ///< glass pixels its last collected masked trace listed
};

// The host's plan for a frame's update of the scene.
struct Renderer::Update {
  bool trees = false;   ///< some view traces through snell's trees
  bool driver = false;  ///< some view traces through the driver's ray tracing
  std::vector<uint32_t> deform;  ///< DeformPass outputs
  bool instancesChanged = false, lightsChanged = false;
  std::vector<gpu::GpuInstance> instances;
  std::vector<gpu::GpuLight> lights;
  SceneTrees::Work treeWork;
};

// One frame in flight: its commands, the host data it uploads, what it reads back.
struct Renderer::Slot {
  Slot(vk::Context& context, size_t index)
      : commands(context, "frame " + std::to_string(index)), arena(context, "frame uploads " + std::to_string(index)) {}
  vk::Commands commands;
  vk::UploadArena arena;
  uint64_t frame = 0;
  bool pending = false;
  FrameResult result;

  /// What the host reads back of every frame: the trees' statistics, then
  /// the pixels traced per masked view (counted on the GPU).
  vk::Buffer statistics;
  SceneTrees::Work trees;
  std::vector<size_t> maskedViews;
  VkDeviceSize pixelCountsAt = 0;
  std::vector<PendingReadback> readbacks;

  void reset(uint64_t number) {
    frame = number;
    result = FrameResult{};
    result.stats.frame = number;
    trees = SceneTrees::Work{};
    maskedViews.clear();
    readbacks.clear();
    arena.reset();
  }
};

Renderer::Renderer(vk::Context& context, const scene::Scene& scene, const scene::Pose& pose, RendererOptions options)
    : context_(context), sceneModel_(scene), options_(options),
      scene_(uploadScene(context, scene, pose, options.host.positions ? &options.host : nullptr)),
      trees_(context, scene_, scene.source.empty() ? std::string("scene") : scene.source, options.rebuildGrowth,
             options.rebuildBudget, childBoxesOf(options)),
      targets_(context), bounds_(scene) {
  if (options_.framesInFlight == 0) throw std::invalid_argument("renderer: framesInFlight must be at least 1");
  if (options_.traceLanes & (options_.traceLanes - 1) || options_.traceLanes > 8) {
    throw std::invalid_argument("renderer: traceLanes must be 0 (chosen per frame), 1, 2, 4 or 8, not " +
                                std::to_string(options_.traceLanes));
  }
  deform_ = std::make_unique<DeformPass>(context, scene, pose, [&](int item) {
    for (const GeometryRange& g : scene_.geometries) {
      if (g.item == item) return DeformSlot{&scene_.positions, &scene_.normals, g.firstVertex};
    }
    throw std::logic_error("deforming item without a geometry");
  });
  raster_ = std::make_unique<RasterPass>(context);
  trace_ = std::make_unique<TracePass>(
      context, scene, scene_, childBoxesOf(options),
      keepsWideRecords(context, BvhLeaves::Triangles, childBoxesOf(options), scene_.triangleCount));
  std::string name = scene.source.empty() ? std::string("scene") : scene.source;
  feed_ = std::make_unique<VertexFeed>(context, scene, scene_, options_.keepVertices, name);
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
  for (uint32_t i = 0; i < options_.framesInFlight; ++i) slots_.push_back(std::make_unique<Slot>(context, i));
}

Renderer::~Renderer() {
  try {
    finish();
  } catch (...) {
    // A lost device is reported by the frame that met it; nothing more to do here.
  }
}

// ---------------------------------------------------------------- the frame

uint64_t Renderer::submit(const FrameRequest& request) {
  request.check(context_, scene_.itemGeometry.size());
  const scene::Pose& pose = *request.pose;

  // Where every item is (bounding spheres), then what each view does: both
  // decide which views trace, and the pipelines those need start compiling
  // now, beside the update's work.
  bounds_.place(pose);
  std::vector<ViewPlan> plans;
  for (const ViewRequest& v : request.views) plans.push_back(plan(v));
  for (size_t i = 0; i < request.views.size(); ++i) {
    const ViewRequest& v = request.views[i];
    trace_->prepare(v.settings);
    if (plans[i].needsTrees()) trace_->prefetch(v.settings, v.aov, plans[i].masked);
  }

  const uint64_t frame = ++submitted_;
  Slot& slot = *slots_[frame % slots_.size()];
  if (slot.pending) collect(slot);
  slot.reset(frame);
  FrameStats& stats = slot.result.stats;

  std::vector<bool> lost = targets_.prepare(request.views);
  if (views_.size() < request.views.size()) views_.resize(request.views.size());
  for (size_t i = 0; i < lost.size(); ++i) views_[i].rendered = views_[i].rendered && !lost[i];
  Update update = planUpdate(pose, request, plans, slot);

  vk::Commands& commands = slot.commands;
  commands.setTimed(options_.passTimes);
  commands.begin();
  // Frames in flight share the scene's GPU data: what this frame rewrites,
  // the one before may still be reading.
  commands.fullBarrier();
  const FeedCounts fed = feed_->record(commands, slot.arena, *deform_);
  stats.shapesCopied = fed.shapesCopied;
  stats.shapesRefined = fed.shapesRefined;
  stats.verticesRefined = fed.verticesRefined;
  for (const vk::Image* image : targets_.takeNewImages()) {
    commands.imageLayout(*image, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
  }
  if (!request.views.empty()) recordUpdate(commands, slot, pose, update);
  for (size_t i = 0; i < request.views.size(); ++i) recordView(commands, slot, i, request.views[i], plans[i]);
  recordReadbacks(commands, slot, request);
  recordStatistics(commands, slot, request.views.size());
  if (request.record) request.record(commands);
  stats.dispatches = commands.dispatches();
  stats.draws = commands.draws();
  commands.submit(request.waitSemaphore, request.waitStage, request.signalSemaphore);
  slot.pending = true;
  return frame;
}

Renderer::ViewPlan Renderer::plan(const ViewRequest& request) const {
  ViewPlan p;
  if (request.output == ViewOutput::Trace) {
    p.traces = true;
    p.driver = request.driverTrace;
    return p;
  }
  const RasterOptions& raster = request.raster;
  const bool glass = raster.refraction && seeThrough_ && bounds_.anyInView(request.settings, scene_.itemSeeThrough);
  p.traces = glass && raster.screenSpace == ScreenSpace::Off;
  p.masked = p.traces && request.masked;
  p.behind = glass && !p.traces && raster.screenSpace != ScreenSpace::RefractionMap;
  return p;
}

Renderer::Update Renderer::planUpdate(const scene::Pose& pose, const FrameRequest& request,
                                      const std::vector<ViewPlan>& plans, Slot& slot) {
  Update u;
  if (request.views.empty()) return u;
  FrameStats& stats = slot.result.stats;
  if (options_.independentFrames) origin_ = FrameOrigin();
  stats.rebased = origin_.follow(request.views.front().settings.view.eye, bounds_);
  planDeform(pose, u, stats);
  u.instances = scene_.packInstances(pose, origin_.origin());
  u.lights = SceneGpu::packLights(sceneModel_, pose, origin_.origin());
  u.instancesChanged = !sameBytes(uploadedInstances_, u.instances);
  u.lightsChanged = !sameBytes(uploadedLights_, u.lights);
  if (!u.deform.empty() || u.instancesChanged || u.lightsChanged) ++sceneVersion_;
  for (const ViewPlan& p : plans) {
    u.trees = u.trees || p.needsTrees();
    u.driver = u.driver || p.driver;
  }
  if (u.trees) u.treeWork = trees_.plan(u.instancesChanged, options_.independentFrames, stats);
  return u;
}

// The deforming items whose weights or joints changed since the GPU deformed them.
void Renderer::planDeform(const scene::Pose& pose, Update& u, FrameStats& stats) {
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
    for (uint32_t g = 0; g < scene_.geometries.size(); ++g) {
      if (scene_.geometries[g].item == int(i)) noteMoved(g);
    }
  }
}

void Renderer::recordUpdate(vk::Commands& commands, Slot& slot, const scene::Pose& pose, const Update& u) {
  if (u.instancesChanged) {
    slot.arena.copy(commands, u.instances, instances_);
    uploadedInstances_ = u.instances;
    if (!u.trees) trees_.noteTopStale();  // the top level catches up in the next frame with trees
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
  if (u.trees) trees_.record(commands, u.treeWork, instances_, slot.arena);
  slot.trees = u.treeWork;
}

void Renderer::recordView(vk::Commands& commands, Slot& slot, size_t index, const ViewRequest& request,
                          const ViewPlan& plan) {
  ViewState& state = views_[index];
  FrameStats& stats = slot.result.stats;
  if (state.rendered && state.version == sceneVersion_ && request == state.last) {
    ++stats.viewsSkipped;
    return;
  }
  ++stats.viewsRendered;
  const FrameSettings& settings = request.settings;
  const ViewImages& images = targets_.images(index);
  if (!settings.rays.empty()) {
    std::vector<gpu::GpuRay> rays(settings.rays.size());
    for (size_t i = 0; i < rays.size(); ++i) {
      // Relative to the origin in double, like the instances, before the cast to float.
      rays[i].origin = glm::vec4(glm::vec3(settings.rays[i].origin - origin_.origin()), 1.0f);
      rays[i].direction = glm::vec4(glm::vec3(glm::normalize(settings.rays[i].direction)), 0.0f);
    }
    slot.arena.copy(commands, rays, targets_.rays(index));
    commands.transferToCompute();
  }
  if (request.output == ViewOutput::Trace) {
    recordTrace(commands, index, request, plan, stats);
  } else {
    RasterScene scene{&scene_, &sceneModel_, &instances_, &lights_, lightCount_, origin_.origin()};
    RasterOptions raster = request.raster;
    if (!raster.refractionMap && refractionMap(index).width > 0) raster.refractionMap = &maps_[index];
    if (!raster.depth) {
      // Near and far planes around the items' spheres at this pose: loose
      // enough for any deformation, and reverse Z keeps the precision.
      glm::dvec3 lo, hi;
      bounds_.box(lo, hi);
      raster.depth = fitDepthRange(settings.view, lo, hi);
    }
    // A screen-space method draws what lies behind the glass first, into the trace image.
    if (plan.behind) raster_->recordBehind(commands, scene, settings, raster, images.depth, images.mask, images.trace);
    raster_->recordDepth(commands, scene, settings, raster, images.depth, plan.masked ? &images.mask : nullptr,
                         images.composite);
    if (plan.traces) {
      recordTrace(commands, index, request, plan, stats);
      if (plan.masked) slot.maskedViews.push_back(index);
    }
    raster_->recordShading(commands, scene, settings, raster, images.trace, images.composite, images.depth,
                           images.mask, plan.traces);
  }
  state.rendered = settings.rays.empty();  // a ray list is never assumed the same
  state.version = sceneVersion_;
  state.last = request;
  state.last.settings.rays.clear();
}

void Renderer::recordTrace(vk::Commands& commands, size_t index, const ViewRequest& request, const ViewPlan& plan,
                           FrameStats& stats) {
  const ViewImages& images = targets_.images(index);
  TraceInputs in{&scene_, &instances_, &lights_, lightCount_, origin_.origin(), trees_.blas(), trees_.tlas()};
  TraceTarget target{&images.trace, request.aov ? &images.aov : nullptr,
                     request.settings.rays.empty() ? nullptr : &targets_.rays(index), &images.mask, &images.pixels};
  if (plan.driver) {
    stats.pixelsTraced += trace_->recordDriver(commands, in, request.settings, target);
  } else {
    uint32_t lanes = 1;
    if (plan.masked) {
      uint64_t listed = options_.independentFrames ? 0 : views_[index].listed;
      lanes = trace_->maskedLanes(request.settings, request.aov, listed, options_.traceLanes);
      stats.traceLanes = std::max(stats.traceLanes, lanes);
    }
    stats.pixelsTraced += trace_->record(commands, in, request.settings, target, plan.masked, lanes);
  }
  ++stats.traceDispatches;
}

// The views' images (and AOV) the caller asked for, into host buffers.
void Renderer::recordReadbacks(vk::Commands& commands, Slot& slot, const FrameRequest& request) {
  if (request.readbacks.empty()) return;
  commands.barrier(VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT,
                   VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_TRANSFER_READ_BIT);
  for (const ReadbackRequest& r : request.readbacks) {
    slot.readbacks.push_back(targets_.recordReadback(commands, r.view, request.views[r.view], r));
  }
}

// What the host reads back of every frame: the trees' statistics, pixel counts.
void Renderer::recordStatistics(vk::Commands& commands, Slot& slot, size_t views) {
  slot.pixelCountsAt = trees_.statisticsBytes(slot.trees);
  const VkDeviceSize bytes = slot.pixelCountsAt + 4 * std::max<size_t>(views, 1);
  if (slot.statistics.size() < bytes) {
    slot.statistics = vk::Buffer(context_, {bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, vk::MemoryDomain::Readback,
                                            "frame statistics"});
  }
  commands.computeToTransfer();
  trees_.recordStatistics(commands, slot.trees, slot.statistics, 0);
  for (size_t k = 0; k < slot.maskedViews.size(); ++k) {
    commands.copyBuffer(targets_.images(slot.maskedViews[k]).pixels, slot.statistics, 4, 0,
                        slot.pixelCountsAt + 4 * k);
  }
  commands.transferToHost();
}

// ---------------------------------------------------------------- the frame's results

void Renderer::collect(Slot& slot) {
  slot.commands.wait();
  slot.pending = false;
  FrameResult& result = slot.result;
  result.passes = slot.commands.passTimes();
  const std::byte* data = slot.statistics.mapped().data();
  for (const ShapeBox& box : trees_.collect(slot.trees, data, result.stats)) bounds_.setShapeBox(box.shape, box.lo, box.hi);
  for (size_t k = 0; k < slot.maskedViews.size(); ++k) {
    uint32_t count;
    std::memcpy(&count, data + slot.pixelCountsAt + 4 * k, 4);
    result.stats.pixelsTraced += count;
    if (slot.maskedViews[k] < views_.size()) views_[slot.maskedViews[k]].listed = count;
  }
  result.views.clear();
  for (PendingReadback& r : slot.readbacks) result.views.push_back(targets_.finishReadback(std::move(r)));
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

// ---------------------------------------------------------------- between frames

KeptVertices Renderer::keptVertices(int shape) {
  if (!feed_->keeps()) throw std::invalid_argument("renderer: made without kept vertices");
  finish();
  return feed_->kept(shape);
}

void Renderer::markDirty(int shape) {
  if (shape < 0 || size_t(shape) >= sceneModel_.shapes.size()) {
    throw std::invalid_argument("renderer: no shape " + std::to_string(shape) + " to mark dirty");
  }
  feed_->markDirty(shape);
  // The shape's vertices are also those of its parts (Shape::vertexSource).
  for (size_t s = 0; s < sceneModel_.shapes.size(); ++s) {
    if (int(s) != shape && sceneModel_.shapes[s].vertexSource != shape) continue;
    for (uint32_t g = 0; g < scene_.geometries.size(); ++g) {
      if (scene_.geometries[g].shape == int(s)) noteMoved(g);
    }
    // A host's promised box still holds; any other is unknown until a refit measures it.
    if (!sceneModel_.shapes[s].host) {
      bounds_.setShapeBox(int(s), glm::dvec3(INFINITY), glm::dvec3(-INFINITY));
      trees_.measure(int(s));
    }
  }
  ++sceneVersion_;
}

void Renderer::invalidateViews() {
  for (ViewState& v : views_) v.rendered = false;
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

std::optional<RefractionBake> Renderer::keepRefractionMap(const scene::Pose& pose, const FrameSettings& settings,
                                                          size_t view) {
  const RefractionMapBuffer& kept = refractionMap(view);
  if (kept.width == settings.width && kept.height == settings.height) return std::nullopt;
  return bakeRefractionMap(pose, settings, view);
}

const RefractionMapBuffer& Renderer::refractionMap(size_t view) const {
  static const RefractionMapBuffer none;
  return view < maps_.size() ? maps_[view] : none;
}

void Renderer::noteMoved(uint32_t geometry) {
  trees_.noteMoved(geometry);
  trace_->noteGeometryMoved(geometry);
}

uint64_t Renderer::memoryBytes() const {
  return scene_.bytes + deform_->bytes() + feed_->bytes() + instances_.size() + lights_.size() +
         trees_.bytes() + trace_->bytes();
}

std::vector<std::string> Renderer::pipelineStatistics() const { return trace_->statistics(); }

void Renderer::finishCompiles() const {
  if (trace_) trace_->finishCompiles();
}

}  // namespace snell::render
