// The public API (include/snell/snell.h) over the layers below: a Device is a
// vk::Context, a Scene a scene::Scene (a host's data turned into one), a
// Renderer a render::Renderer with the pose it draws. Every exception from
// below leaves as snell::Error.
#include "snell/snell.h"

#include "bake/refraction_bake.h"
#include "io/environment.h"
#include "render/method.h"
#include "render/pixel_aovs.h"
#include "render/raster_pass.h"
#include "render/renderer.h"
#include "render/shot.h"
#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/optics.h"
#include "scene/subdivision.h"
#include "scene/view.h"
#include "vk/commands.h"
#include "vk/context.h"
#include "vk/error.h"

#include <glm/gtc/packing.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cstring>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <utility>

namespace snell {

namespace {

// Runs `body`, turning whatever it throws into snell::Error.
template <typename Body>
auto guarded(Body&& body) -> decltype(body()) {
  try {
    return body();
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(e.what());
  }
}

glm::dmat4 toMatrix(const Mat4& m) { return glm::dmat4(glm::make_mat4(m.data())); }
glm::vec3 toVec(const Vec3& v) { return {v[0], v[1], v[2]}; }

// Every IEEE half's float: a table lookup converts a frame's pixels several times faster than bit arithmetic.
const std::array<float, 65536>& halfTable() {
  static const std::array<float, 65536> table = [] {
    std::array<float, 65536> t{};
    for (uint32_t h = 0; h < t.size(); ++h) t[h] = glm::unpackHalf1x16(uint16_t(h));
    return t;
  }();
  return table;
}

// A Vulkan entry point of the device's extensions; throws when the driver has none.
template <typename Function>
Function deviceFunction(VkDevice device, const char* name) {
  auto f = reinterpret_cast<Function>(vkGetDeviceProcAddr(device, name));
  if (!f) throw Error(std::string(name) + " is missing: make the Device with DeviceOptions::interop");
  return f;
}

}  // namespace

const char* version() { return SNELL_VERSION; }

std::vector<MethodDescription> methods() {
  std::vector<MethodDescription> all;
  for (const render::MethodInfo& m : render::methods()) all.push_back({m.name, m.summary});
  return all;
}

// ---------------------------------------------------------------- Device

struct Device::Impl {
  std::unique_ptr<vk::Context> context;
  // Renderers on several threads share the context (its queue, its deferred
  // destruction, its memory count): their GPU calls take turns here.
  std::recursive_mutex mutex;
};

Device::Device(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Device::~Device() = default;
Device::Device(Device&&) noexcept = default;
Device& Device::operator=(Device&&) noexcept = default;

namespace {

vk::ContextDesc contextDesc(const DeviceOptions& options) {
  vk::ContextDesc desc;
  desc.applicationName = "snell (embedded)";
  desc.deviceOverride = options.device;
  desc.environment = io::deviceEnvironment();  // SNELL_DEVICE, or the GPUs a launcher gave the process
  desc.validation = options.validation;
  desc.synchronizationValidation = options.synchronizationValidation;
  desc.robustBufferAccess = options.validation;
  desc.driverRayTracing = options.driverRayTracing;
  if (options.interop) {
    desc.deviceExtensions = {VK_KHR_EXTERNAL_MEMORY_FD_EXTENSION_NAME};
    desc.optionalDeviceExtensions = {VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME};  // lavapipe lacks it
  }
  return desc;
}

}  // namespace

Device Device::create(const DeviceOptions& options) {
  return guarded([&] {
    auto impl = std::make_unique<Impl>();
    impl->context = vk::Context::create(contextDesc(options));
    return Device(std::move(impl));
  });
}

Device Device::adopt(const HostDevice& host) {
  return guarded([&] {
    vk::AdoptedDevice adopted;
    adopted.instance = host.instance;
    adopted.physicalDevice = host.physicalDevice;
    adopted.device = host.device;
    adopted.queueFamily = host.queueFamily;
    adopted.queue = host.queue;
    adopted.enabled13 = host.enabled13;
    adopted.enabled13.pNext = nullptr;
    auto impl = std::make_unique<Impl>();
    impl->context = vk::Context::adopt(adopted);
    return Device(std::move(impl));
  });
}

VkInstance Device::instance() const { return impl_->context->instance(); }
VkPhysicalDevice Device::physicalDevice() const { return impl_->context->physicalDevice(); }
VkDevice Device::device() const { return impl_->context->device(); }
VkQueue Device::queue() const { return impl_->context->queue(); }
uint32_t Device::queueFamily() const { return impl_->context->queueFamily(); }
std::string Device::name() const { return impl_->context->facts().name; }
uint64_t Device::validationMessages() const { return impl_->context->validationMessageCount(); }

bool Device::exportsSemaphores() const {
  // Enabled only when DeviceOptions::interop asked for it and the device has it.
  if (!impl_->context->enabled(VK_KHR_EXTERNAL_SEMAPHORE_FD_EXTENSION_NAME)) return false;
  VkPhysicalDeviceExternalSemaphoreInfo info{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_EXTERNAL_SEMAPHORE_INFO};
  info.handleType = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
  VkExternalSemaphoreProperties properties{VK_STRUCTURE_TYPE_EXTERNAL_SEMAPHORE_PROPERTIES};
  vkGetPhysicalDeviceExternalSemaphoreProperties(physicalDevice(), &info, &properties);
  return (properties.externalSemaphoreFeatures & VK_EXTERNAL_SEMAPHORE_FEATURE_EXPORTABLE_BIT) != 0;
}

void Device::waitIdle() {
  guarded([&] { VK_CHECK(vkDeviceWaitIdle(device())); });
}

// ---------------------------------------------------------------- Scene

struct Scene::Impl {
  scene::Scene scene;
  render::HostBuffers host;  ///< null handles for a glTF scene or kept vertices
  /// The shapes carry the host's first vertices (HostScene::vertices), and
  /// each Renderer keeps a copy for the host to rewrite.
  bool keep = false;
};

Scene::Scene(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

Scene Scene::load(const std::string& path) {
  return guarded([&] {
    auto impl = std::make_unique<Impl>();
    impl->scene = scene::loadGltf(path);
    return Scene(std::move(impl));
  });
}

namespace {

// One of a material's texture slots: its index checked against the scene's textures.
scene::TextureRef toTextureRef(int texture, const TextureTransform& t, size_t textures, const std::string& where) {
  if (texture < -1 || texture >= int(textures)) {
    throw Error(where + " " + std::to_string(texture) + " of " + std::to_string(textures) + " textures");
  }
  for (float f : {t.offset[0], t.offset[1], t.rotation, t.scale[0], t.scale[1]}) {
    if (!std::isfinite(f)) throw Error(where + "'s transform is not finite");
  }
  scene::TextureRef ref;
  ref.texture = texture;
  ref.transform = scene::uvTransform({t.offset[0], t.offset[1]}, t.rotation, {t.scale[0], t.scale[1]});
  return ref;
}

scene::Material toMaterial(const Material& m, size_t textures, const std::string& where) {
  if (!(m.ior >= 1.0f) || !(m.transmission >= 0.0f && m.transmission <= 1.0f)) {
    throw Error(where + ": ior must be at least 1 and transmission within [0, 1]");
  }
  if (!(m.dispersion >= 0.0f) || !std::isfinite(m.dispersion)) throw Error(where + ": dispersion must be 0 or more");
  if (!(m.alphaCutoff >= 0.0f) || !std::isfinite(m.alphaCutoff)) throw Error(where + ": alphaCutoff must be 0 or more");
  if (!std::isfinite(m.normalScale)) throw Error(where + ": normalScale is not finite");
  scene::Material out;
  out.name = m.name;
  out.emissiveFactor = toVec(m.emissive);
  out.dispersion = m.dispersion;
  out.baseColorFactor = glm::make_vec4(m.baseColor.data());
  out.baseColorTexture = toTextureRef(m.baseColorTexture, m.baseColorTransform, textures, where + ": baseColorTexture");
  out.emissiveTexture = toTextureRef(m.emissiveTexture, m.emissiveTransform, textures, where + ": emissiveTexture");
  out.normalTexture = toTextureRef(m.normalTexture, m.normalTransform, textures, where + ": normalTexture");
  out.normalScale = m.normalScale;
  out.alphaMode = m.alphaMode == Material::Alpha::Mask    ? scene::AlphaMode::Mask
                  : m.alphaMode == Material::Alpha::Blend ? scene::AlphaMode::Blend
                                                          : scene::AlphaMode::Opaque;
  out.alphaCutoff = m.alphaCutoff;
  out.transmission = m.transmission;
  out.ior = m.ior;
  out.roughness = m.roughness;
  out.thickness = m.thickness;
  out.attenuationColor = toVec(m.attenuationColor);
  out.attenuationDistance = m.attenuationDistance;
  out.doubleSided = m.doubleSided;
  return out;
}

scene::Shape toShape(const Mesh& m, int index, size_t materials, const std::string& where) {
  const bool cage = m.subdivision.scheme != Subdivision::Scheme::None;
  if (!cage && (m.indices.empty() || m.indices.size() % 3 != 0)) {
    throw Error(where + ": needs a whole number of triangles (" + std::to_string(m.indices.size()) + " indices)");
  }
  if (!cage && !m.subdivision.uvIndices.empty()) throw Error(where + ": face-varying texcoords are for subdivision surfaces");
  const bool faceVarying = !m.subdivision.uvIndices.empty();
  if (faceVarying ? m.texcoords.size() % 2 != 0 : !m.texcoords.empty() && m.texcoords.size() != size_t(m.vertexCount) * 2) {
    throw Error(where + ": " + std::to_string(m.texcoords.size()) + " texcoord floats for " +
                std::to_string(m.vertexCount) + " vertices");
  }
  if (m.material >= int(materials)) {
    throw Error(where + ": material " + std::to_string(m.material) + " of " + std::to_string(materials));
  }
  scene::Shape shape;
  shape.name = m.name;
  shape.mesh = index;
  shape.material = m.material;
  shape.indices = m.indices;
  for (size_t v = 0; v + 1 < m.texcoords.size(); v += 2) shape.texcoords0.emplace_back(m.texcoords[v], m.texcoords[v + 1]);
  shape.host = scene::HostVertices{m.firstVertex, m.vertexCount, toVec(m.boundsLo), toVec(m.boundsHi)};
  return shape;
}

// A subdivision surface's cage, at rest at `positions` (3 floats a vertex;
// null for a mesh in the host's buffers, which snell never sees at rest).
scene::SubdivisionCage toCage(const Mesh& m, const float* positions) {
  const Subdivision& d = m.subdivision;
  scene::SubdivisionCage cage;
  cage.scheme = d.scheme == Subdivision::Scheme::Loop       ? scene::SubdivisionScheme::Loop
                : d.scheme == Subdivision::Scheme::Bilinear ? scene::SubdivisionScheme::Bilinear
                                                            : scene::SubdivisionScheme::CatmullClark;
  cage.level = d.level;
  cage.limitSurface = d.limitSurface;
  cage.normals = d.normals == Subdivision::Normals::Limit && positions ? scene::SubdivisionNormals::Limit
                                                                       : scene::SubdivisionNormals::Mesh;
  cage.positions.assign(m.vertexCount, glm::vec3(0.0f));
  if (positions) std::memcpy(cage.positions.data(), positions, size_t(m.vertexCount) * 12);
  cage.faceVertexCounts = d.faceVertexCounts;
  cage.faceVertexIndices = m.indices;
  cage.leftHanded = d.leftHanded;
  cage.holeIndices = d.holeIndices;
  cage.creaseIndices = d.creaseIndices;
  cage.creaseLengths = d.creaseLengths;
  cage.creaseSharpnesses = d.creaseSharpnesses;
  cage.cornerIndices = d.cornerIndices;
  cage.cornerSharpnesses = d.cornerSharpnesses;
  cage.boundary = scene::BoundaryInterpolation(int(d.interpolateBoundary));
  cage.faceVarying = scene::FaceVaryingInterpolation(int(d.faceVarying));
  cage.smoothTriangles = d.smoothTriangles;
  for (size_t i = 0; i + 1 < m.texcoords.size(); i += 2) cage.uvs.emplace_back(m.texcoords[i], m.texcoords[i + 1]);
  cage.uvIndices = d.uvIndices;
  return cage;
}

// Refines mesh `m`'s cage into `shape` (its warnings into the scene's); SceneError becomes Error.
void refineCage(const Mesh& m, const float* positions, scene::Shape& shape, scene::Scene& s, const std::string& where) {
  try {
    std::optional<scene::HostVertices> host = shape.host;
    scene::subdivide(toCage(m, positions), shape, where, s.warnings);
    if (host) {  // its vertices are the host's: only the refined triangles and texcoords are snell's
      shape.host = host;
      shape.positions.clear();
      shape.normals.clear();
    }
  } catch (const scene::SceneError& e) {
    throw Error(e.what());
  }
}

// Gives each mesh its vertices from HostScene::vertices: the scene's shapes
// are then snell's own, with a rest pose each Renderer keeps a copy of.
void keepVertices(const HostScene& host, Scene::Impl& impl) {
  if (host.vertices.size() != host.meshes.size()) {
    throw Error(host.name + ": " + std::to_string(host.vertices.size()) + " vertex lists for " +
                std::to_string(host.meshes.size()) + " meshes (without host buffers, each mesh needs its vertices)");
  }
  uint64_t total = 0;
  for (const Mesh& m : host.meshes) total += m.vertexCount;
  if (total > (1u << 31) / 3) throw Error(host.name + ": " + std::to_string(total) + " vertices are too many for one scene");
  for (size_t i = 0; i < host.meshes.size(); ++i) {
    const Mesh& m = host.meshes[i];
    const MeshVertices& v = host.vertices[i];
    std::string where = host.name + ": mesh " + std::to_string(i) + (m.name.empty() ? "" : " ('" + m.name + "')");
    if (m.vertexCount == 0) throw Error(where + " has no vertices");
    const bool cage = m.subdivision.scheme != Subdivision::Scheme::None;
    if (v.positions.size() != size_t(m.vertexCount) * 3 ||
        (v.normals.size() != size_t(m.vertexCount) * 3 && !(cage && v.normals.empty()))) {
      throw Error(where + ": " + std::to_string(v.positions.size()) + " position and " + std::to_string(v.normals.size()) +
                  " normal floats for " + std::to_string(m.vertexCount) + " vertices (3 each)");
    }
    scene::Shape& shape = impl.scene.shapes[i];
    shape.host.reset();
    if (m.subdivision.scheme != Subdivision::Scheme::None) {
      refineCage(m, v.positions.data(), shape, impl.scene, where);
      continue;
    }
    shape.positions.resize(m.vertexCount);
    shape.normals.resize(m.vertexCount);
    std::memcpy(shape.positions.data(), v.positions.data(), v.positions.size() * sizeof(float));
    std::memcpy(shape.normals.data(), v.normals.data(), v.normals.size() * sizeof(float));
  }
  impl.keep = true;
}

// A light's node: it shines down its -Z axis from `position`.
glm::mat4 lightMatrix(const Light& light) {
  glm::vec3 back = -glm::normalize(toVec(light.direction));
  glm::vec3 helper = std::abs(back.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  glm::vec3 x = glm::normalize(glm::cross(helper, back));
  glm::vec3 y = glm::cross(back, x);
  return glm::mat4(glm::vec4(x, 0), glm::vec4(y, 0), glm::vec4(back, 0), glm::vec4(toVec(light.position), 1));
}

}  // namespace

Scene Scene::fromHost(const HostScene& host) {
  return guarded([&] {
    auto impl = std::make_unique<Impl>();
    scene::Scene& s = impl->scene;
    s.source = host.name;
    bool keep = !host.positions && !host.normals;
    if (!keep && (!host.positions || !host.normals)) {
      throw Error(host.name + ": give both the positions and normals buffers, or neither (snell keeps the vertices)");
    }
    if (!keep && !host.vertices.empty()) throw Error(host.name + ": vertex lists are for scenes without host buffers");
    for (size_t i = 0; i < host.textures.size(); ++i) {
      const Texture& t = host.textures[i];
      if (t.width == 0 || t.height == 0 || t.rgba.size() != size_t(t.width) * t.height * 4) {
        throw Error(host.name + ": texture " + std::to_string(i) + " ('" + t.name + "') has " +
                    std::to_string(t.rgba.size()) + " bytes for " + std::to_string(t.width) + "x" +
                    std::to_string(t.height) + " RGBA8 pixels");
      }
      scene::Texture& texture = s.textures.emplace_back(scene::Texture{t.name, t.width, t.height, t.rgba});
      texture.repeatS = t.wrapS != Texture::Wrap::Clamp;
      texture.repeatT = t.wrapT != Texture::Wrap::Clamp;
      texture.mirrorS = t.wrapS == Texture::Wrap::Mirror;
      texture.mirrorT = t.wrapT == Texture::Wrap::Mirror;
      texture.linearFilter = !t.nearest;
    }
    for (size_t i = 0; i < host.materials.size(); ++i) {
      s.materials.push_back(toMaterial(host.materials[i], s.textures.size(),
                                       host.name + ": material " + std::to_string(i)));
    }
    for (size_t i = 0; i < host.meshes.size(); ++i) {
      s.shapes.push_back(toShape(host.meshes[i], int(i), s.materials.size(), host.name + ": mesh " + std::to_string(i)));
      s.meshes.push_back(scene::Mesh{host.meshes[i].name, {int(i)}, {}});
    }
    for (size_t i = 0; i < host.instances.size(); ++i) {
      const Instance& instance = host.instances[i];
      if (instance.mesh < 0 || size_t(instance.mesh) >= s.meshes.size()) {
        throw Error(host.name + ": instance " + std::to_string(i) + " places mesh " + std::to_string(instance.mesh) +
                    " of " + std::to_string(s.meshes.size()));
      }
      scene::Node node;
      node.name = "instance " + std::to_string(i);
      node.mesh = instance.mesh;
      node.matrix = glm::make_mat4(instance.transform.data());
      s.roots.push_back(int(s.nodes.size()));
      s.nodes.push_back(node);
    }
    for (size_t i = 0; i < host.lights.size(); ++i) {
      const Light& l = host.lights[i];
      scene::Light light;
      light.type = l.type == Light::Type::Directional ? scene::LightType::Directional
                   : l.type == Light::Type::Point     ? scene::LightType::Point
                                                      : scene::LightType::Spot;
      light.color = toVec(l.color);
      light.intensity = l.intensity;
      light.innerConeAngle = l.innerConeAngle;
      light.outerConeAngle = l.outerConeAngle;
      scene::Node node;
      node.name = "light " + std::to_string(i);
      node.light = int(s.lights.size());
      node.matrix = lightMatrix(l);
      s.lights.push_back(light);
      s.roots.push_back(int(s.nodes.size()));
      s.nodes.push_back(node);
    }
    for (size_t i = 0; i < host.cameras.size(); ++i) {
      const SceneCamera& c = host.cameras[i];
      std::string where = host.name + ": camera " + std::to_string(i);
      if (c.orthographic ? !(c.ymag > 0.0f) : !(c.yfov > 0.0f && c.yfov < 3.14159f)) {
        throw Error(where + (c.orthographic ? ": ymag must be positive" : ": yfov must be within (0, pi) radians"));
      }
      for (float f : c.transform) {
        if (!std::isfinite(f)) throw Error(where + "'s transform is not finite");
      }
      scene::Camera camera;
      camera.name = c.name;
      camera.orthographic = c.orthographic;
      camera.yfov = c.yfov;
      camera.xmag = camera.ymag = c.ymag;
      scene::Node node;
      node.name = c.name.empty() ? "camera " + std::to_string(i) : c.name;
      node.camera = int(s.cameras.size());
      node.matrix = glm::make_mat4(c.transform.data());
      s.cameras.push_back(camera);
      s.roots.push_back(int(s.nodes.size()));
      s.nodes.push_back(node);
    }
    if (keep) {
      keepVertices(host, *impl);
    } else {
      impl->host = {host.positions, host.normals, host.vertexCapacity};
      for (size_t i = 0; i < host.meshes.size(); ++i) {
        if (host.meshes[i].subdivision.scheme == Subdivision::Scheme::None) continue;
        refineCage(host.meshes[i], nullptr, s.shapes[i], s, host.name + ": mesh " + std::to_string(i));
      }
    }
    return Scene(std::move(impl));
  });
}

std::string Scene::name() const { return impl_->scene.source; }
size_t Scene::meshCount() const { return impl_->scene.shapes.size(); }
size_t Scene::cameraCount() const { return impl_->scene.cameras.size(); }
uint32_t Scene::vertexCount(int mesh) const {
  if (mesh < 0 || size_t(mesh) >= impl_->scene.shapes.size()) {
    throw Error("vertexCount: no mesh " + std::to_string(mesh) + " of " + std::to_string(impl_->scene.shapes.size()));
  }
  return uint32_t(impl_->scene.shapes[size_t(mesh)].writtenVertexCount());
}
uint32_t Scene::drawnVertexCount(int mesh) const {
  vertexCount(mesh);  // the same check
  return uint32_t(impl_->scene.shapes[size_t(mesh)].vertexCount());
}
uint32_t Scene::drawnTriangleCount(int mesh) const {
  vertexCount(mesh);
  return uint32_t(impl_->scene.shapes[size_t(mesh)].triangleCount());
}
std::vector<std::string> Scene::warnings() const { return impl_->scene.warnings; }
bool Scene::keepsVertices() const { return impl_->keep; }
double Scene::duration() const { return scene::animationDuration(impl_->scene); }

// ---------------------------------------------------------------- Environment

// The core's environment itself: the trace keys its upload by this object, so
// every View that holds the same Environment shares one buffer.
struct Environment::Impl : scene::Environment {};

Environment::Environment(std::shared_ptr<const Impl> impl) : impl_(std::move(impl)) {}

Environment Environment::fromPixels(uint32_t width, uint32_t height, const float* rgb, const std::string& name) {
  return guarded([&] {
    if (width == 0 || height == 0 || !rgb) {
      throw Error(name + ": an environment of " + std::to_string(width) + "x" + std::to_string(height) +
                  " texels has nothing to show");
    }
    auto impl = std::make_shared<Impl>();
    impl->source = name;
    impl->width = width;
    impl->height = height;
    impl->texels.resize(size_t(width) * height);
    for (size_t i = 0; i < impl->texels.size(); ++i) impl->texels[i] = glm::vec3(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]);
    scene::fitEnvironment(*impl);
    return Environment(std::move(impl));
  });
}

uint32_t Environment::width() const { return impl_->width; }
uint32_t Environment::height() const { return impl_->height; }
std::string Environment::name() const { return impl_->source; }

// ---------------------------------------------------------------- Renderer

namespace {

// A camera frame from a host's view and projection matrices (OpenGL's
// conventions). The trace's ray through a pixel (shared/trace.h) has slopes
// sx = ndc.x * halfHeight * aspect + shift.x, sy = ndc.y * halfHeight + shift.y;
// an off-centre projection is exactly such a window of slopes (perspective)
// or of offsets (orthographic).
scene::View viewFromMatrices(const CameraMatrices& m, uint32_t width, uint32_t height) {
  for (size_t i = 0; i < 16; ++i) {
    if (!std::isfinite(m.view[i]) || !std::isfinite(m.projection[i])) throw Error("view: the camera matrices are not finite");
  }
  glm::dmat4 toWorld = glm::inverse(toMatrix(m.view));
  glm::dmat4 p = toMatrix(m.projection);  // p[column][row]
  scene::View v;
  v.description = "the host's camera matrices";
  v.right = glm::dvec3(toWorld[0]);
  v.up = glm::dvec3(toWorld[1]);
  v.forward = -glm::dvec3(toWorld[2]);
  v.eye = glm::dvec3(toWorld[3]);
  double lr = glm::length(v.right), lu = glm::length(v.up), lf = glm::length(v.forward);
  if (!(lr > 0.0 && lu > 0.0 && lf > 0.0) || !std::isfinite(lr * lu * lf)) throw Error("view: the view matrix is singular");
  v.right /= lr, v.up /= lu, v.forward /= lf;
  if (std::abs(glm::dot(v.right, v.up)) > 1e-4 || std::abs(glm::dot(v.right, v.forward)) > 1e-4 ||
      std::abs(glm::dot(v.up, v.forward)) > 1e-4) {
    throw Error("view: the view matrix shears (its axes are not at right angles)");
  }
  if (p[0][3] != 0.0 || p[1][3] != 0.0 || p[0][1] != 0.0 || p[1][0] != 0.0) {
    throw Error("view: the projection is not a perspective or orthographic one (it mixes x and y, or x and y into w)");
  }
  bool perspective = p[2][3] < 0.0 && p[3][3] == 0.0;
  v.orthographic = p[2][3] == 0.0 && p[3][3] != 0.0;
  if (!perspective && !v.orthographic) throw Error("view: the projection is neither perspective (w = -z) nor orthographic (w = 1)");
  if (!(p[0][0] > 0.0 && p[1][1] > 0.0)) throw Error("view: the projection flips or collapses x or y");
  double w = perspective ? -p[2][3] : p[3][3];  // clip w per unit of -z, or the constant w
  double sx = p[0][0] / w, sy = p[1][1] / w;
  double aspect = double(width) / double(height);
  if (std::abs(sy / sx / aspect - 1.0) > 1e-3) {
    throw Error("view: the projection's aspect " + std::to_string(sy / sx) + " is not the view's " +
                std::to_string(width) + "x" + std::to_string(height) + " (" + std::to_string(aspect) +
                "): snell's pixels are square");
  }
  v.halfHeight = 1.0 / sy;
  if (perspective) {
    v.shift = glm::dvec2(p[2][0] / p[0][0], p[2][1] / p[1][1]);
  } else {
    v.shift = glm::dvec2(-p[3][0] / p[0][0], -p[3][1] / p[1][1]);
  }
  return v;
}

// The camera `view` names, at the pose.
scene::View cameraOf(const View& view, const scene::Scene& model, const scene::Pose& pose) {
  if (view.sceneCamera >= 0) {
    scene::ViewRequest which;
    which.camera = view.sceneCamera;
    return scene::resolveView(model, pose, which);
  }
  if (view.matrices) return viewFromMatrices(*view.matrices, view.width, view.height);
  const Camera& c = view.camera;
  scene::ViewRequest which;
  which.lookAt = scene::LookAt{glm::dvec3(toVec(c.eye)), glm::dvec3(toVec(c.target)), glm::dvec3(toVec(c.up))};
  which.yfov = c.yfov;
  return scene::resolveView(model, pose, which);
}

// The frame settings of `view` at the pose (its method apart).
render::FrameSettings frameSettings(const View& view, const scene::Scene& model, const scene::Pose& pose) {
  render::FrameSettings settings;
  settings.width = view.width;
  settings.height = view.height;
  settings.view = cameraOf(view, model, pose);
  settings.background = toVec(view.background);
  if (view.maxInterfaces > 1024) throw Error("view: maxInterfaces " + std::to_string(view.maxInterfaces) + " is past 1024");
  settings.maxInterfaces = view.maxInterfaces;
  settings.optics.fresnel = view.fresnel;
  settings.optics.dispersion = view.dispersion;
  settings.optics.volume = view.volume;
  if (view.environment) settings.optics.environment = view.environment->impl();
  return settings;
}

}  // namespace

struct Renderer::Impl {
  std::recursive_mutex& mutex;  ///< the Device's
  vk::Context& context;
  Scene::Impl& scene;
  scene::Pose pose;
  std::map<size_t, glm::dmat4> transforms;  ///< setTransform's, kept over setTime
  std::unique_ptr<render::Renderer> renderer;
  FrameInfo last;
  std::optional<render::MethodChoice> choice;  ///< the last request's (auto keeps timing while it stays)
  render::Method drawn = render::Method::Trace;  ///< the last request's method

  Impl(Device& device, Scene& s, const RendererOptions& options)
      : mutex(device.impl().mutex), context(*device.impl().context), scene(s.impl()),
        pose(scene::evaluate(scene.scene, 0.0)) {
    std::lock_guard lock(mutex);
    render::RendererOptions o;
    o.framesInFlight = options.framesInFlight;
    o.passTimes = options.passTimes;
    o.host = scene.host;
    o.keepVertices = scene.keep;
    renderer = std::make_unique<render::Renderer>(context, scene.scene, pose, o);
  }

  // The renderer's request for a view of the current pose.
  render::ViewRequest request(const View& view) {
    render::FrameSettings settings = frameSettings(view, scene.scene, pose);
    const std::string name = view.method.empty() ? "auto" : view.method;
    const bool viewportOutput = view.output == View::Output::Viewport;
    if (!choice || choice->name() != name || viewportOutput != choice->viewport()) {
      try {
        choice.emplace(name, context.caps().driverRayTracing, viewportOutput);
      } catch (const std::invalid_argument& e) {
        throw Error(std::string("view: ") + e.what() +
                    (name == "driver-rt" ? " (make the Device with DeviceOptions::driverRayTracing)" : ""));
      }
    }
    drawn = choice->next();
    render::RasterOptions raster;
    const bool composite = viewportOutput || render::drawsComposite(drawn);
    if (composite && view.transparentBackground) settings.background = glm::vec3(0.0f), settings.backgroundAlpha = 0.0f;
    if (drawn == render::Method::RefractionMap) bakeMap(settings);
    return choice->view(drawn, settings, raster);
  }

  // The refraction-map method's map: the trace of this view at this pose,
  // baked once per view size; the renderer keeps it.
  void bakeMap(const render::FrameSettings& settings) {
    const render::RefractionMapBuffer& map = renderer->refractionMap();
    if (map.width == settings.width && map.height == settings.height) return;
    render::FrameSettings traced = settings;
    traced.backgroundAlpha = 1.0f;
    renderer->bakeRefractionMap(pose, traced);
  }

  void note(const render::FrameResult& result) {
    if (choice) choice->note(drawn, result.passes);
    const render::FrameStats& s = result.stats;
    last = FrameInfo{};
    last.frame = s.frame;
    last.treesRefit = s.treesRefit, last.treesBuilt = s.treesBuilt, last.treesSkipped = s.treesSkipped;
    last.pixelsTraced = s.pixelsTraced;
    last.skipped = s.viewsSkipped > 0;
    last.itemsDeformed = s.itemsDeformed;
    last.meshesUploaded = s.shapesCopied;
    last.meshesRefined = s.shapesRefined;
    last.verticesRefined = s.verticesRefined;
    last.topLevelBuilt = s.topLevelBuilt > 0, last.topLevelRefit = s.topLevelRefit > 0;
    last.dispatches = s.dispatches, last.draws = s.draws;
    last.method = render::methodName(drawn);
    for (const vk::PassTime& p : result.passes) last.passes.push_back(PassTime{p.name, p.milliseconds});
  }
};

Renderer::Renderer(Device& device, Scene& scene, const RendererOptions& options)
    : impl_(guarded([&] { return std::make_unique<Impl>(device, scene, options); })) {}
Renderer::~Renderer() {
  if (!impl_) return;  // moved from
  std::lock_guard lock(impl_->mutex);
  impl_->renderer.reset();
}
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

void Renderer::setTime(double seconds) {
  guarded([&] {
    if (!std::isfinite(seconds)) throw Error("setTime: the time is not finite");
    impl_->pose = scene::evaluate(impl_->scene.scene, seconds);
    for (const auto& [instance, world] : impl_->transforms) impl_->pose.items[instance].world = world;
  });
}

size_t Renderer::instanceCount() const { return impl_->pose.items.size(); }

void Renderer::setTransform(size_t instance, const Mat4& transform) {
  if (instance >= impl_->pose.items.size()) {
    throw Error("setTransform: no instance " + std::to_string(instance) + " of " +
                std::to_string(impl_->pose.items.size()));
  }
  for (float f : transform) {
    if (!std::isfinite(f)) throw Error("setTransform: instance " + std::to_string(instance) + "'s matrix is not finite");
  }
  impl_->transforms[instance] = toMatrix(transform);
  impl_->pose.items[instance].world = toMatrix(transform);
}

void Renderer::markDirty(int mesh) {
  guarded([&] {
    std::lock_guard lock(impl_->mutex);
    if (mesh < 0 || size_t(mesh) >= impl_->scene.scene.shapes.size()) {
      throw Error("markDirty: no mesh " + std::to_string(mesh) + " of " + std::to_string(impl_->scene.scene.shapes.size()));
    }
    impl_->renderer->markDirty(mesh);
  });
}

Vertices Renderer::vertices(int mesh) {
  return guarded([&] {
    std::lock_guard lock(impl_->mutex);
    if (!impl_->scene.keep) throw Error("vertices: the scene's vertices are the host's own (only a HostScene without buffers has kept ones)");
    if (mesh < 0 || size_t(mesh) >= impl_->scene.scene.shapes.size()) {
      throw Error("vertices: no mesh " + std::to_string(mesh) + " of " + std::to_string(impl_->scene.scene.shapes.size()));
    }
    render::KeptVertices kept = impl_->renderer->keptVertices(mesh);  // waits for the frames that read them
    return Vertices{kept.positions, kept.normals, kept.count};
  });
}

uint64_t Renderer::render(const View& view, const Target& target, const Sync& sync) {
  return guarded([&] {
    std::lock_guard lock(impl_->mutex);
    if (!target.image) throw Error("render: the target image is null");
    if (target.width != view.width || target.height != view.height) {
      throw Error("render: the target is " + std::to_string(target.width) + "x" + std::to_string(target.height) +
                  ", the view " + std::to_string(view.width) + "x" + std::to_string(view.height));
    }
    render::Renderer& renderer = *impl_->renderer;
    render::FrameRequest frame;
    frame.pose = &impl_->pose;
    frame.views.push_back(impl_->request(view));
    const bool composite = frame.views.back().output == render::ViewOutput::Composite;
    frame.record = [&](vk::Commands& commands) {
      const render::ViewImages& images = renderer.viewImages(0);
      commands.blitToImage(composite ? images.composite : images.trace,
                           {target.image, target.width, target.height, target.layoutBefore, target.layoutAfter});
    };
    frame.waitSemaphore = sync.wait;
    frame.waitStage = sync.wait ? sync.waitStage : 0;
    frame.signalSemaphore = sync.signal;
    return renderer.submit(frame);
  });
}

void Renderer::wait(uint64_t frame) {
  guarded([&] {
    std::lock_guard lock(impl_->mutex);
    impl_->note(impl_->renderer->wait(frame));
  });
}

std::vector<float> Renderer::read(const View& view) {
  std::vector<float> out(size_t(view.width) * view.height * 4);
  read(view, out.data());
  return out;
}

void Renderer::read(const View& view, float* rgba) {
  guarded([&] {
    std::lock_guard lock(impl_->mutex);
    if (!rgba) throw Error("read: the output is null");
    render::FrameRequest frame;
    frame.pose = &impl_->pose;
    frame.views.push_back(impl_->request(view));
    // Half floats, converted once, straight into the host's memory; a
    // composite's own picture is all the host asked for.
    frame.readbacks.push_back({.view = 0, .half = true, .trace = false});
    bool composite = frame.views.back().output == render::ViewOutput::Composite;
    const render::FrameResult& result = impl_->renderer->wait(impl_->renderer->submit(frame));
    impl_->note(result);
    const render::ViewPixels& pixels = result.views.at(0);
    const std::vector<uint16_t>& halves = composite ? pixels.compositeHalf : pixels.traceHalf;
    const std::array<float, 65536>& toFloat = halfTable();
    for (size_t i = 0; i < halves.size(); ++i) rgba[i] = toFloat[halves[i]];
  });
}

Aovs Renderer::readAovs(const View& view) {
  return guarded([&] {
    std::lock_guard lock(impl_->mutex);
    const std::string name = view.method.empty() ? "auto" : view.method;
    if (name != "auto" && name != "trace" && name != "trace-1") {
      throw Error("readAovs: the AOVs come from snell's trace; give the method auto, trace or trace-1, not '" + name + "'");
    }
    View traced = view;
    traced.output = View::Output::Trace;
    traced.method = name == "auto" ? "trace" : name;
    render::FrameRequest frame;
    frame.pose = &impl_->pose;
    frame.views.push_back(impl_->request(traced));
    render::ViewRequest& request = frame.views.back();
    request.aov = true;
    frame.readbacks.push_back({.view = 0});
    const render::FrameResult& result = impl_->renderer->wait(impl_->renderer->submit(frame));
    impl_->note(result);
    const render::ViewPixels& pixels = result.views.at(0);

    const size_t count = size_t(view.width) * view.height;
    Aovs out;
    out.width = view.width;
    out.height = view.height;
    out.rgba.resize(count * 4);
    out.depth.resize(count);
    out.normal.resize(count * 3);
    out.instance.resize(count);
    out.primitive.resize(count);
    out.interfaces.resize(count);
    out.cost.resize(count);
    const scene::Scene& model = impl_->scene.scene;
    auto kept = [&](int shape) -> const float* {
      return impl_->scene.keep ? impl_->renderer->keptVertices(shape).positions : nullptr;
    };
    render::FaceNormals normals(model, impl_->pose, kept);
    const std::vector<render::PixelHit> hits = render::pixelHits(pixels.aov);
    for (size_t p = 0; p < count; ++p) {
      const render::PixelHit& hit = hits[p];
      const bool covered = hit.distance >= 0.0;
      const glm::vec4& c = pixels.trace[p];
      std::copy_n(&c.x, 3, &out.rgba[4 * p]);
      out.rgba[4 * p + 3] = covered ? 1.0f : 0.0f;
      out.depth[p] = covered ? float(render::cameraDepth(request.settings.view, view.width, view.height, p, hit.distance))
                             : INFINITY;
      const glm::vec3 n = covered ? normals.of(hit.instance, hit.primitive) : glm::vec3(0.0f);
      std::copy_n(&n.x, 3, &out.normal[3 * p]);
      out.instance[p] = hit.instance;
      out.primitive[p] = hit.primitive;
      out.interfaces[p] = hit.interfaces;
      out.cost[p] = hit.cost;
    }
    return out;
  });
}

FrameInfo Renderer::lastFrame() const { return impl_->last; }

// ---------------------------------------------------------------- Shots

ShotSummary renderFrames(const std::string& devices, Scene& scene, const View& view,
                         const std::function<std::optional<ShotFrame>()>& next,
                         const std::function<void(ShotPicture&&)>& done, const DeviceOptions& options) {
  return guarded([&] {
    if (!next || !done) throw Error("renderFrames: give both the frames (next) and where they go (done)");
    const scene::Scene& model = scene.impl().scene;
    if (scene.impl().host.positions) {
      throw Error("renderFrames: " + model.source + "'s vertices are in the host's buffers, which only its own device reads");
    }
    const std::string method = view.method.empty() ? "auto" : view.method;
    const std::optional<render::Method> named = render::methodFromName(method);
    if (method != "auto" && !named) {
      throw Error("view: no method '" + method + "' (the methods: auto, " + render::methodNames() + ")");
    }
    render::ShotSettings settings;
    const render::FrameSettings first = frameSettings(view, model, scene::evaluate(model, 0.0));
    settings.width = first.width;
    settings.height = first.height;
    settings.view = [&](const scene::Pose& pose) { return cameraOf(view, model, pose); };
    settings.background = first.background;
    settings.maxInterfaces = first.maxInterfaces;
    settings.optics = first.optics;
    settings.method = method;
    settings.viewport = view.output == View::Output::Viewport;
    if (view.transparentBackground && (settings.viewport || (named && render::drawsComposite(*named)))) {
      settings.background = glm::vec3(0.0f), settings.backgroundAlpha = 0.0f;
    }
    settings.keepVertices = scene.impl().keep;

    // No list: one worker, on the device `options` names (or snell's own choice).
    std::vector<render::ShotDevice> workers = render::shotDevices(devices, io::deviceEnvironment(), options.device);
    DeviceOptions shared = options;
    shared.device.clear();

    render::ShotIo io;
    io.next = [&]() -> std::optional<render::ShotFrame> {
      std::optional<ShotFrame> f = next();
      if (!f) return std::nullopt;
      render::ShotFrame frame{.number = f->number, .seconds = f->seconds};
      if (!std::isfinite(f->seconds)) throw Error("renderFrames: frame " + std::to_string(f->number) + "'s time is not finite");
      if (f->camera) frame.view = viewFromMatrices(*f->camera, view.width, view.height);
      for (const auto& [instance, matrix] : f->transforms) frame.transforms.emplace_back(instance, toMatrix(matrix));
      for (auto& [mesh, vertices] : f->vertices) {
        if (!scene.impl().keep) throw Error("renderFrames: frame " + std::to_string(f->number) + " gives vertices of a scene whose vertices snell does not keep");
        frame.vertices.push_back({mesh, std::move(vertices.positions), std::move(vertices.normals)});
      }
      return frame;
    };
    io.done = [&](render::ShotImage&& image) {
      ShotPicture picture{image.frame.number, image.frame.seconds, view.width, view.height, {}, image.worker,
                          image.device, image.method};
      const std::vector<uint16_t>& halves = image.rgbaHalf();
      const std::array<float, 65536>& toFloat = halfTable();
      picture.rgba.resize(halves.size());
      for (size_t i = 0; i < halves.size(); ++i) picture.rgba[i] = toFloat[halves[i]];
      done(std::move(picture));
    };
    const render::ShotReport report = render::renderShot(model, settings, contextDesc(shared), workers, io);
    ShotSummary summary;
    summary.frames = report.frames;
    summary.seconds = report.seconds;
    for (const render::ShotWorker& w : report.workers) {
      summary.workers.push_back({w.device, w.frames, w.loadSeconds, w.gpuWaitSeconds, w.lost, w.validationMessages});
    }
    return summary;
  });
}

// ---------------------------------------------------------------- SharedImage

struct SharedImage::Impl {
  vk::Context& context;
  uint32_t width, height;
  VkFormat format;
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  uint64_t size = 0;
  bool dedicated = false;

  Impl(vk::Context& c, uint32_t w, uint32_t h, VkFormat f) : context(c), width(w), height(h), format(f) {
    VkExternalMemoryImageCreateInfo external{VK_STRUCTURE_TYPE_EXTERNAL_MEMORY_IMAGE_CREATE_INFO};
    external.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO, &external};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = f;
    info.extent = {w, h, 1};
    info.mipLevels = info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    VK_CHECK(vkCreateImage(c.device(), &info, nullptr, &image));
    try {
      VkMemoryDedicatedRequirements dedicatedNeeds{VK_STRUCTURE_TYPE_MEMORY_DEDICATED_REQUIREMENTS};
      VkMemoryRequirements2 needs{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2, &dedicatedNeeds};
      VkImageMemoryRequirementsInfo2 which{VK_STRUCTURE_TYPE_IMAGE_MEMORY_REQUIREMENTS_INFO_2};
      which.image = image;
      vkGetImageMemoryRequirements2(c.device(), &which, &needs);
      dedicated = dedicatedNeeds.prefersDedicatedAllocation || dedicatedNeeds.requiresDedicatedAllocation;
      VkMemoryDedicatedAllocateInfo dedicatedInfo{VK_STRUCTURE_TYPE_MEMORY_DEDICATED_ALLOCATE_INFO};
      dedicatedInfo.image = image;
      VkExportMemoryAllocateInfo exportInfo{VK_STRUCTURE_TYPE_EXPORT_MEMORY_ALLOCATE_INFO,
                                            dedicated ? &dedicatedInfo : nullptr};
      exportInfo.handleTypes = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
      VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &exportInfo};
      allocate.allocationSize = size = needs.memoryRequirements.size;
      allocate.memoryTypeIndex = c.findMemoryType(needs.memoryRequirements.memoryTypeBits,
                                                  VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0);
      if (allocate.memoryTypeIndex == UINT32_MAX) throw Error("shared image: no device-local memory type fits it");
      VK_CHECK(vkAllocateMemory(c.device(), &allocate, nullptr, &memory));
      VK_CHECK(vkBindImageMemory(c.device(), image, memory, 0));
    } catch (...) {
      release();
      throw;
    }
    c.setName(VK_OBJECT_TYPE_IMAGE, image, "shared image");
  }
  ~Impl() { release(); }

  void release() {
    VkDevice device = context.device();
    VkImage i = std::exchange(image, VK_NULL_HANDLE);
    VkDeviceMemory m = std::exchange(memory, VK_NULL_HANDLE);
    context.retire([device, i, m] {
      if (i) vkDestroyImage(device, i, nullptr);
      if (m) vkFreeMemory(device, m, nullptr);
    });
  }
};

SharedImage::SharedImage(Device& device, uint32_t width, uint32_t height, VkFormat format)
    : impl_(guarded([&] {
        vk::Context& context = *device.impl().context;
        if (width == 0 || height == 0) {
          throw Error("shared image: its size is " + std::to_string(width) + "x" + std::to_string(height));
        }
        deviceFunction<PFN_vkGetMemoryFdKHR>(context.device(), "vkGetMemoryFdKHR");
        return std::make_unique<Impl>(context, width, height, format);
      })) {}
SharedImage::~SharedImage() = default;
SharedImage::SharedImage(SharedImage&&) noexcept = default;
SharedImage& SharedImage::operator=(SharedImage&&) noexcept = default;

Target SharedImage::target(VkImageLayout before, VkImageLayout after) const {
  return Target{impl_->image, impl_->format, impl_->width, impl_->height, before, after};
}

int SharedImage::exportMemory() const {
  return guarded([&] {
    auto getFd = deviceFunction<PFN_vkGetMemoryFdKHR>(impl_->context.device(), "vkGetMemoryFdKHR");
    VkMemoryGetFdInfoKHR info{VK_STRUCTURE_TYPE_MEMORY_GET_FD_INFO_KHR};
    info.memory = impl_->memory;
    info.handleType = VK_EXTERNAL_MEMORY_HANDLE_TYPE_OPAQUE_FD_BIT;
    int fd = -1;
    VK_CHECK(getFd(impl_->context.device(), &info, &fd));
    return fd;
  });
}

uint64_t SharedImage::memorySize() const { return impl_->size; }
bool SharedImage::dedicated() const { return impl_->dedicated; }
VkImage SharedImage::image() const { return impl_->image; }

// ---------------------------------------------------------------- SharedSemaphore

struct SharedSemaphore::Impl {
  vk::Context& context;
  VkSemaphore semaphore = VK_NULL_HANDLE;
  explicit Impl(vk::Context& c) : context(c) {}
  ~Impl() {
    VkDevice device = context.device();
    VkSemaphore s = semaphore;
    if (s) context.retire([device, s] { vkDestroySemaphore(device, s, nullptr); });
  }
};

SharedSemaphore::SharedSemaphore(Device& device)
    : impl_(guarded([&] {
        if (!device.exportsSemaphores()) {
          throw Error("shared semaphore: " + device.name() +
                      " cannot export semaphores as file descriptors (or the Device was made without interop)");
        }
        auto impl = std::make_unique<Impl>(*device.impl().context);
        VkExportSemaphoreCreateInfo exportInfo{VK_STRUCTURE_TYPE_EXPORT_SEMAPHORE_CREATE_INFO};
        exportInfo.handleTypes = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
        VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &exportInfo};
        VK_CHECK(vkCreateSemaphore(device.device(), &info, nullptr, &impl->semaphore));
        return impl;
      })) {}
SharedSemaphore::~SharedSemaphore() = default;
SharedSemaphore::SharedSemaphore(SharedSemaphore&&) noexcept = default;
SharedSemaphore& SharedSemaphore::operator=(SharedSemaphore&&) noexcept = default;

VkSemaphore SharedSemaphore::handle() const { return impl_->semaphore; }

int SharedSemaphore::exportFd() const {
  return guarded([&] {
    auto getFd = deviceFunction<PFN_vkGetSemaphoreFdKHR>(impl_->context.device(), "vkGetSemaphoreFdKHR");
    VkSemaphoreGetFdInfoKHR info{VK_STRUCTURE_TYPE_SEMAPHORE_GET_FD_INFO_KHR};
    info.semaphore = impl_->semaphore;
    info.handleType = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
    int fd = -1;
    VK_CHECK(getFd(impl_->context.device(), &info, &fd));
    return fd;
  });
}

}  // namespace snell
