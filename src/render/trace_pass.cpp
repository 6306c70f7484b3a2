#include "render/trace_pass.h"
#include "render/pass_names.h"

#include "trace.spv.h"
#include "trace_compact.spv.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace snell::render {

namespace {

// Which optics a scene's materials can show at all: a view that asks for
// more traces exactly the same image with the rest compiled out.
uint32_t opticsOfScene(const scene::Scene& scene) {
  uint32_t optics = gpu::kOpticsEnvironmentMap;  // the view brings the environment
  for (const scene::Material& m : scene.materials) {
    if (m.refractive()) optics |= gpu::kOpticsFresnel;
    if (m.refractive() && m.dispersion > 0.0f) optics |= gpu::kOpticsDispersion;
    if (m.refractive() && m.attenuates()) optics |= gpu::kOpticsVolume;
  }
  if (!scene.textures.empty()) optics |= gpu::kOpticsTextureLod;
  return optics;
}

}  // namespace

TracePass::TracePass(vk::Context& context, const scene::Scene& scene, const SceneGpu& gpu, BvhChildBoxes childBoxes,
                     bool wideWalk)
    : context_(context), sceneOptics_(opticsOfScene(scene)), sceneSurface_(gpu.surface), childBoxes_(childBoxes),
      wideWalk_(wideWalk) {
  compact_ = std::make_unique<vk::ComputeProgram>(context, compactDesc());
  placeholder_ = vk::Buffer(context, {sizeof(gpu::TracePixelListHeader), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                      vk::MemoryDomain::Device, "placeholder"});
  driverMoved_.assign(gpu.geometries.size(), 0);
}

TracePass::~TracePass() = default;

uint32_t TracePass::opticsFor(const FrameSettings& settings) const {
  const scene::Optics& o = settings.optics;
  uint32_t asked = (o.fresnel ? gpu::kOpticsFresnel : 0u) | (o.environment ? gpu::kOpticsEnvironmentMap : 0u) |
                   (o.textureLod ? gpu::kOpticsTextureLod : 0u) | (o.dispersion ? gpu::kOpticsDispersion : 0u) |
                   (o.volume ? gpu::kOpticsVolume : 0u);
  return asked & sceneOptics_;
}

uint32_t TracePass::replayFlags(const FrameSettings& settings) {
  return settings.hitReplay == HitReplay::Record ? gpu::kTraceFlagRecordHits
         : settings.hitReplay == HitReplay::Replay ? gpu::kTraceFlagReplayHits
                                                   : 0u;
}

const vk::Buffer& TracePass::hitRecords(const FrameSettings& settings) {
  if (settings.hitReplay == HitReplay::Off) return placeholder_;
  VkDeviceSize bytes = VkDeviceSize(settings.width) * settings.height * gpu::kTraceReplaySegments *
                       sizeof(gpu::TraceHitRecord);
  if (hitRecords_.size() < bytes) {
    if (settings.hitReplay == HitReplay::Replay) throw std::logic_error("trace: a hit replay before its record");
    hitRecords_ = vk::Buffer(context_, {bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryDomain::Device,
                                        "trace hit records"});
  }
  return hitRecords_;
}

bool TracePass::manyLanesNeedWave32(const vk::DeviceFacts& device) {
  // RDNA1 and RDNA2 (gfx10), which RADV names by chip; RDNA3 is "GFX11xx", GCN "VEGA..".
  if (device.driverId != VK_DRIVER_ID_MESA_RADV) return false;
  for (const char* chip : {"NAVI1", "NAVI2", "VANGOGH", "REMBRANDT", "MENDOCINO", "CYAN_SKILLFISH", "GFX103"}) {
    if (device.name.find(chip) != std::string::npos) return true;
  }
  return false;
}

vk::ComputeProgramDesc TracePass::programDesc(const vk::DeviceFacts& device, uint32_t optics, uint32_t flags,
                                              uint32_t lanes, uint32_t surface, BvhChildBoxes childBoxes,
                                              bool wideWalk) {
  // Several lanes a pixel must share a subgroup: full subgroups keep them together.
  vk::ComputeProgramDesc desc{"trace",
                              kSpvTrace,
                              {{gpu::kTraceSpecOptics, optics},
                               {gpu::kTraceSpecFlags, flags},
                               {gpu::kTraceSpecLanes, lanes},
                               {gpu::kTraceSpecSurface, surface},
                               {gpu::kTraceSpecChildBoxes, childBoxes == BvhChildBoxes::Exact ? 1u : 0u},
                               {gpu::kTraceSpecWideWalk, wideWalk && childBoxes == BvhChildBoxes::Exact ? 1u : 0u}},
                              lanes > 1};
  if (lanes > 1 && manyLanesNeedWave32(device)) desc.requiredSubgroupSize = 32;
  return desc;
}

vk::ComputeProgramDesc TracePass::compactDesc() { return {"trace compact", kSpvTraceCompact, {}, false}; }

const vk::ComputeProgram& TracePass::program(uint32_t optics, uint32_t flags, uint32_t lanes) {
  uint64_t key = uint64_t(optics) << 32 | uint64_t(lanes) << 16 | flags;
  auto found = programs_.find(key);
  if (found != programs_.end()) return *found->second;
  vk::ComputeProgramDesc desc = programDesc(context_.facts(), optics, flags, lanes, sceneSurface_, childBoxes_, wideWalk_);
  return *programs_.emplace(key, std::make_unique<vk::ComputeProgram>(context_, desc)).first->second;
}

uint32_t TracePass::flagsFor(const FrameSettings& settings, bool aov, bool masked) const {
  return (aov ? gpu::kTraceFlagAov : 0u) | (settings.view.orthographic ? gpu::kTraceFlagOrthographic : 0u) |
         (settings.rays.empty() ? 0u : gpu::kTraceFlagRayList) | (masked ? gpu::kTraceFlagPixelList : 0u) |
         replayFlags(settings);
}

void TracePass::prefetch(const FrameSettings& settings, bool aov, bool masked) {
  program(opticsFor(settings), flagsFor(settings, aov, masked), 1);
}

uint32_t TracePass::maskedLanes(const FrameSettings& settings, bool aov, uint64_t listedBefore, uint32_t forced) {
  // Lanes of a pixel share a subgroup; the shader's masks hold at most 32 of them.
  const uint32_t widest = std::min(8u, context_.facts().minSubgroupSize);
  uint32_t lanes = 1;
  if (forced) {
    while (lanes * 2 <= std::min(forced, widest)) lanes *= 2;
    return lanes;
  }
  if (listedBefore == 0) return 1;
  while (lanes * 2 <= widest && listedBefore * lanes * 2 <= kMaskedLaneInvocations) lanes *= 2;
  if (lanes > 1 && !program(opticsFor(settings), flagsFor(settings, aov, true), lanes).ready()) return 1;
  return lanes;
}

void TracePass::prepare(const FrameSettings& settings) {
  const std::shared_ptr<const scene::Environment>& env = settings.optics.environment;
  if (!env || environments_.count(env.get())) return;
  if (env->width == 0 || env->height == 0 || env->texels.size() != size_t(env->width) * env->height) {
    throw std::invalid_argument("renderer: environment " + env->source + " has no texels");
  }
  // Header (width, height), then the texels; kept while the environment is alive.
  std::vector<glm::vec4> data;
  data.reserve(env->texels.size() + 1);
  data.emplace_back(float(env->width), float(env->height), 0.0f, 0.0f);
  for (const glm::vec3& t : env->texels) data.emplace_back(t, 0.0f);
  VkDeviceSize bytes = data.size() * sizeof(glm::vec4);
  if (bytes > context_.caps().maxStorageBufferRange) {
    throw std::runtime_error(env->source + ": the environment needs " + std::to_string(bytes >> 20) +
                             " MiB; the device binds at most " +
                             std::to_string(context_.caps().maxStorageBufferRange >> 20) + " MiB in one buffer");
  }
  vk::Buffer buffer(context_, {bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                               vk::MemoryDomain::Device, "environment " + env->source});
  vk::upload(context_, buffer, data.data(), bytes);
  environments_.emplace(env.get(), Environment{env, std::move(buffer)});
}

const vk::Buffer& TracePass::environmentBuffer(const scene::Optics& optics) const {
  if (!optics.environment) return placeholder_;
  auto found = environments_.find(optics.environment.get());
  if (found == environments_.end()) {
    throw std::logic_error("trace: an environment reached a trace before prepare() uploaded it");
  }
  return found->second.buffer;
}

gpu::TracePush TracePass::push(const TraceInputs& in, const FrameSettings& settings, const TraceTarget& target,
                               bool masked) const {
  const scene::View& v = settings.view;
  double aspect = double(settings.width) / double(settings.height);
  gpu::TracePush push{};
  push.right = glm::vec4(glm::vec3(v.right), float(v.halfHeight * aspect));
  push.up = glm::vec4(glm::vec3(v.up), float(v.halfHeight));
  push.forward = glm::vec4(glm::vec3(v.forward), 0.0f);
  push.background = glm::vec4(settings.background, 1.0f);
  push.eye = glm::vec4(glm::vec3(v.eye - in.origin), 0.0f);
  push.width = settings.width;
  push.height = settings.height;
  push.maxInterfaces = settings.maxInterfaces;
  push.maxBends = settings.maxBends;
  push.lightCount = in.lightCount;
  push.flags = flagsFor(settings, target.aov != nullptr, masked);  // the pipeline's flags: prefetch() made it
  push.tilesX = (settings.width + gpu::kTraceTile - 1) / gpu::kTraceTile;
  push.shiftX = float(v.shift.x);
  push.shiftY = float(v.shift.y);
  push.optics = opticsFor(settings);
  push.reflections = settings.optics.reflections;
  return push;
}

std::vector<vk::BufferBinding> TracePass::pathBindings(const TraceInputs& in, const FrameSettings& settings,
                                                       const TraceTarget& target) const {
  std::vector<vk::BufferBinding> bindings = {
      {gpu::kTraceBindingEnvironment, &environmentBuffer(settings.optics)},
      {gpu::kTraceBindingImage, nullptr, target.image},
      {gpu::kTraceBindingAov, target.aov ? target.aov : &placeholder_},
      {gpu::kTraceBindingRays, target.rays ? target.rays : &placeholder_}};
  in.scene->appendBindings(bindings, *in.instances, *in.lights);
  return bindings;
}

uint64_t TracePass::record(vk::Commands& commands, const TraceInputs& in, const FrameSettings& settings,
                           const TraceTarget& target, bool masked, uint32_t lanes) {
  // The pipelines are specialised to what the trees keep: trees of the other
  // kind would be walked through a 16-byte placeholder.
  if (in.tlas->childBoxes != childBoxes_ || in.blas->childBoxes != childBoxes_ || in.blas->hasWideRecords() != wideWalk_) {
    throw std::logic_error("trace: trees whose child boxes or 4-wide records are not the kind its pipelines were made for");
  }
  gpu::TracePush p = push(in, settings, target, masked);
  if (!masked) lanes = 1;
  uint32_t tilesY = (settings.height + gpu::kTraceTile - 1) / gpu::kTraceTile;
  uint64_t traced = 0;
  if (masked) {
    // The pre-pass's mask becomes the list of pixels to trace, and the
    // trace's workgroup rows (trace.h: TracePixelListHeader).
    commands.graphicsToCompute();
    const gpu::TracePixelListHeader header{0, 0, gpu::kTraceListGroupsX, 0, 1, 0, 0, 0};
    commands.updateBuffer(*target.pixels, &header, sizeof(header));
    commands.transferToCompute();
    gpu::TraceCompactPush compact{settings.width, settings.height, p.tilesX, lanes};
    uint64_t tiles = uint64_t(p.tilesX) * tilesY;
    commands.beginPass(pass::kTraceList);
    compact_->dispatchGroups(commands,
                             {{gpu::kTraceBindingMask, nullptr, target.mask}, {gpu::kTraceBindingPixels, target.pixels}},
                             compact, (tiles + gpu::kTraceCompactTiles - 1) / gpu::kTraceCompactTiles);
    commands.endPass();
    commands.computeToIndirect();
  } else {
    commands.computeToCompute();
    traced = uint64_t(settings.width) * settings.height;
  }
  const vk::ComputeProgram& trace = program(p.optics, p.flags, lanes);
  commands.beginPass(pass::kTrace);
  std::vector<vk::BufferBinding> bindings = pathBindings(in, settings, target);
  bindings.insert(bindings.end(), {{gpu::kTraceBindingTlasNodes, &in.tlas->nodes},
                                   {gpu::kTraceBindingTlasGroups, &in.tlas->groups},
                                   {gpu::kTraceBindingBlasNodes, &in.blas->nodes},
                                   {gpu::kTraceBindingBlasGroups, &in.blas->groups},
                                   {gpu::kTraceBindingTlasChildBoxes, &in.tlas->exactChildBoxes},
                                   {gpu::kTraceBindingBlasChildBoxes, &in.blas->exactChildBoxes},
                                   {gpu::kTraceBindingBlasWideRecords, &in.blas->wideRecords},
                                   {gpu::kTraceBindingPixels, masked ? target.pixels : &placeholder_},
                                   {gpu::kTraceBindingHits, &hitRecords(settings)}});
  if (masked) {
    trace.dispatchIndirect(commands, bindings, p, *target.pixels, gpu::kTracePixelListDispatchOffset);
  } else {
    trace.dispatchGroups(commands, bindings, p, uint64_t(p.tilesX) * tilesY);
  }
  commands.endPass();
  return traced;
}

void TracePass::recordDriverUpdate(vk::Commands& commands, vk::UploadArena& arena, const SceneGpu& gpu,
                                   const std::vector<gpu::GpuInstance>& instances, bool instancesChanged) {
  if (!driver_) {
    std::vector<peer::DriverGeometry> geometries;
    for (const GeometryRange& g : gpu.geometries) geometries.push_back({g.firstTriangle, g.triangleCount});
    driver_ = std::make_unique<peer::DriverTracer>(context_, gpu.positions, gpu.vertexCount, gpu.indices, geometries,
                                                   static_cast<uint32_t>(instances.size()), sceneSurface_);
    std::fill(driverMoved_.begin(), driverMoved_.end(), 0);  // the first build sees them as they are
  }
  std::vector<uint32_t> moved;
  for (uint32_t g = 0; g < driverMoved_.size(); ++g) {
    if (driverMoved_[g]) moved.push_back(g);
    driverMoved_[g] = 0;
  }
  driver_->recordUpdate(commands, arena, instances, instancesChanged || driverInstancesStale_, moved);
  driverInstancesStale_ = false;
}

uint64_t TracePass::recordDriver(vk::Commands& commands, const TraceInputs& in, const FrameSettings& settings,
                                 const TraceTarget& target) {
  if (!driver_) throw std::logic_error("trace: a driver-rt view before its structures were updated");
  commands.computeToCompute();
  std::vector<vk::BufferBinding> bindings = pathBindings(in, settings, target);
  bindings.push_back({gpu::kTraceBindingGeometryFirst, &driver_->geometryFirst()});
  driver_->recordTrace(commands, bindings, push(in, settings, target, false));
  return uint64_t(settings.width) * settings.height;
}

std::vector<std::string> TracePass::statistics() const {
  std::vector<std::string> lines;
  for (const auto& [key, program] : programs_) {
    char variant[96];
    std::snprintf(variant, sizeof variant, "trace (optics 0x%x, flags 0x%x, surface 0x%x, %u lanes a pixel): ",
                  unsigned(key >> 32), unsigned(key & 0xffffu), unsigned(sceneSurface_), unsigned(key >> 16 & 0xffffu));
    for (const std::string& line : program->statistics()) lines.push_back(variant + line);
  }
  return lines;
}

void TracePass::finishCompiles() const {
  for (const auto& entry : programs_) entry.second->finishCompile();
}

uint64_t TracePass::bytes() const { return driver_ ? driver_->bytes() : 0; }

}  // namespace snell::render
