// snell's public API: refraction through deforming meshes, traced by Vulkan
// compute, for a host application (a DCC viewport plug-in, an engine, a tool)
// that embeds it as a renderer backend. docs/embedding.md walks through it.
//
// Errors: every function reports failure by throwing snell::Error, whose
// message says what failed (and which file, for files). snell never aborts
// the host; after an Error the object that threw is still safe to destroy.
//
// Threads: Renderers on one Device may be used from different threads at once:
// their calls that use the GPU (construction, render, wait, read, destruction)
// take turns on a lock the Device holds. A Scene is read-only once made and
// may be shared by them. Each Renderer (and each SharedImage, SharedSemaphore)
// belongs to one thread at a time. Different Devices are independent. snell
// submits to the Device's queue; a host that submits to the same queue from
// another thread must lock around snell's calls that submit (Renderer::render,
// Renderer::read), as Vulkan requires of any queue.
#pragma once

#include <snell/defaults.h>
#include <snell/host_device.h>
#include <vulkan/vulkan.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

// libsnell.so exports this header's names and hides everything else.
#pragma GCC visibility push(default)

namespace snell {

/// The library's version, "major.minor.patch".
const char* version();

/// A way of drawing glass that View::method takes, as `snell render --method` does.
struct MethodDescription {
  std::string name;     ///< what View::method takes: "trace", "iris-plane", ...
  std::string summary;  ///< one line on what it draws and what it costs
};
/// Every method, from the full trace to the screen-space ones, then the
/// driver's ray tracing; "auto" (View::method's default) picks among them.
std::vector<MethodDescription> methods();

/// Every failure snell reports: bad input, a missing device feature, a Vulkan call that failed.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Three floats: a point, a direction or a linear RGB colour.
using Vec3 = std::array<float, 3>;
/// A 4x4 matrix in column-major order (as OpenGL and GLM store them).
using Mat4 = std::array<float, 16>;
/// The identity matrix.
inline constexpr Mat4 kIdentity{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

/// How snell creates a device of its own.
struct DeviceOptions {
  /// A device index or a substring of its name; empty: the SNELL_DEVICE
  /// environment variable, else the first device that meets snell's needs.
  std::string device;
  /// Turn on the Khronos validation layer (it must be installed); messages are counted.
  bool validation = false;
  /// With validation: check synchronisation too.
  bool synchronizationValidation = false;
  /// Enable VK_KHR_external_memory_fd, so a SharedImage can hand its memory to
  /// OpenGL (creation fails if the device lacks it), and VK_KHR_external_semaphore_fd
  /// where the device has it (Device::exportsSemaphores).
  bool interop = false;
  /// Enable the driver's ray tracing, for View::method "driver-rt" (the peer
  /// snell measures itself against; creation fails if the device lacks it).
  bool driverRayTracing = false;
};

/// The GPU snell runs on: its own, or the host's. Outlives every object made on it.
class Device {
 public:
  /// Creates an instance and device; throws Error listing each device and why it was refused.
  static Device create(const DeviceOptions& options = {});
  /// Wraps the host's device; throws Error naming what it lacks.
  static Device adopt(const HostDevice& host);
  ~Device();
  Device(Device&&) noexcept;
  Device& operator=(Device&&) noexcept;

  VkInstance instance() const;
  VkPhysicalDevice physicalDevice() const;
  VkDevice device() const;
  VkQueue queue() const;
  uint32_t queueFamily() const;
  /// The device's name, as the driver gives it.
  std::string name() const;
  /// Validation messages seen so far (0 when validation is off or the device is adopted).
  uint64_t validationMessages() const;
  /// Whether a SharedSemaphore can be exported as a file descriptor (DeviceOptions::interop).
  bool exportsSemaphores() const;
  /// Waits until the device is idle.
  void waitIdle();

  struct Impl;
  Impl& impl() const { return *impl_; }

 private:
  explicit Device(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// How a material's texture reads its UVs: glTF's KHR_texture_transform,
/// uv' = translate(offset) * rotate(rotation) * scale(scale) * uv.
struct TextureTransform {
  std::array<float, 2> offset{0, 0};
  float rotation = 0;  ///< radians, as the extension's rotation
  std::array<float, 2> scale{1, 1};
};

/// A glTF metallic-roughness material with the transmission, IOR and volume extensions.
struct Material {
  std::string name;
  std::array<float, 4> baseColor{1, 1, 1, 1};  ///< linear RGBA; alpha counts as alphaMode says
  int baseColorTexture = -1;                   ///< index into HostScene::textures; -1: none
  TextureTransform baseColorTransform;
  /// How alpha (baseColor[3] times the base texture's alpha) covers an
  /// opaque face: ignored; Mask: there where alpha >= alphaCutoff, else not;
  /// Blend: the face's light times alpha over what lies behind. Glass ignores it.
  enum class Alpha { Opaque, Mask, Blend } alphaMode = Alpha::Opaque;
  float alphaCutoff = 0.5f;
  float transmission = 0;                      ///< > 0: the faces refract
  float ior = 1.5f;
  float roughness = 1;    ///< the width of a glass face's highlights
  float thickness = 0;    ///< 0: thin-walled
  Vec3 attenuationColor{1, 1, 1};
  float attenuationDistance = INFINITY;
  bool doubleSided = false;  ///< false: opaque faces seen from behind are not drawn (glTF's rule; glass always is)
  Vec3 emissive{0, 0, 0};  ///< linear RGB the faces give off
  int emissiveTexture = -1;  ///< sRGB, multiplies `emissive`; -1: none
  TextureTransform emissiveTransform;
  /// A tangent-space normal map as glTF's normalTexture (+Y up the image,
  /// read as data, not sRGB); its frame comes from each triangle's UVs. -1: none.
  int normalTexture = -1;
  float normalScale = 1;  ///< scales the map's X and Y
  TextureTransform normalTransform;
  float dispersion = 0;    ///< KHR_materials_dispersion: 20 / Abbe number; 0: none
};

/// An 8-bit RGBA texture, row 0 at the top: sRGB colour for a base colour or
/// emissive texture, data for a normal map.
struct Texture {
  std::string name;
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;  ///< width * height * 4 bytes
  enum class Wrap { Repeat, Clamp, Mirror };
  Wrap wrapS = Wrap::Repeat, wrapT = Wrap::Repeat;  ///< across u and v
  bool nearest = false;  ///< the nearest texel of the full size, not filtered
};

/// How a Mesh is a subdivision surface, with USD's UsdGeomMesh tags: its
/// faces are then a cage, which snell refines once on the CPU (OpenSubdiv)
/// into stencil tables, and on the GPU every frame its vertices change. The
/// host writes the cage's vertices (Mesh::vertexCount of them); snell draws,
/// traces and reads back the refined surface.
struct Subdivision {
  /// None: Mesh::indices are triangles, and the rest of this is unread.
  enum class Scheme { None, CatmullClark, Loop, Bilinear } scheme = Scheme::None;
  uint32_t level = 2;  ///< uniform refinement levels (each splits a quad in four), 1 to 8
  /// The cage's faces: Mesh::indices holds their vertices, face after face
  /// (USD's faceVertexCounts and faceVertexIndices), counter-clockwise seen
  /// from the front unless `leftHanded`.
  std::vector<uint32_t> faceVertexCounts;
  bool leftHanded = false;
  std::vector<uint32_t> holeIndices;  ///< faces left out
  /// Runs of creaseLengths[i] vertices in creaseIndices, each with one
  /// sharpness or one per edge (10 or more: infinitely sharp).
  std::vector<uint32_t> creaseIndices, creaseLengths;
  std::vector<float> creaseSharpnesses;
  std::vector<uint32_t> cornerIndices;
  std::vector<float> cornerSharpnesses;
  enum class Boundary { None, EdgeOnly, EdgeAndCorner } interpolateBoundary = Boundary::EdgeAndCorner;
  /// USD's faceVaryingLinearInterpolation, for face-varying texcoords.
  enum class FaceVarying { None, CornersOnly, CornersPlus1, CornersPlus2, Boundaries, All } faceVarying =
      FaceVarying::CornersPlus1;
  bool smoothTriangles = false;  ///< triangleSubdivisionRule "smooth" (Catmull-Clark)
  /// Vertices on the limit surface (Blender's "Use Limit Surface"); else the
  /// refined vertices themselves, as usdview draws a uniform refinement.
  bool limitSurface = false;
  /// Normals from the refined triangles (area weighted, as Blender and
  /// usdview shade), or from the limit surface's tangents. A mesh in the
  /// host's buffers, whose rest pose snell never sees, shades with the triangles'.
  enum class Normals { Limit, Mesh } normals = Normals::Mesh;
  /// Face-varying texcoords: one index per face corner into Mesh::texcoords,
  /// which then holds 2 floats a value; empty: Mesh::texcoords is per vertex.
  std::vector<uint32_t> uvIndices;
};

/// A triangle mesh whose vertices live in the host's buffers (HostScene::positions and normals).
struct Mesh {
  std::string name;
  uint32_t firstVertex = 0;  ///< where its vertices start in the host's buffers
  uint32_t vertexCount = 0;  ///< its vertices (a subdivision surface's: the cage's)
  std::vector<uint32_t> indices;  ///< 3 per triangle, counted from firstVertex (a subdivision surface's: its faces')
  std::vector<float> texcoords;   ///< 2 per vertex (u, v), or empty
  int material = -1;              ///< index into HostScene::materials; -1: a grey default
  /// A material per face (a subdivision surface's cage faces, else its
  /// triangles): an index into HostScene::materials, -1 the grey default;
  /// empty: `material` for every face. The faces of each material are drawn
  /// with it from the mesh's one set of vertices, and a subdivision surface
  /// is refined once for all of them (USD's GeomSubsets, Blender's material_index).
  std::vector<int> faceMaterials;
  /// A box, in the mesh's space, the host promises its vertices stay in; the
  /// default (empty) promises nothing, and the mesh is then never culled.
  Vec3 boundsLo{INFINITY, INFINITY, INFINITY}, boundsHi{-INFINITY, -INFINITY, -INFINITY};
  /// A subdivision surface's scheme and tags; by default none.
  Subdivision subdivision;
};

/// A mesh placed in the world. Renderer::setTransform moves it.
struct Instance {
  int mesh = 0;
  Mat4 transform = kIdentity;  ///< mesh space to world
};

/// A punctual light (KHR_lights_punctual): candela for point and spot lights, lux for directional.
struct Light {
  enum class Type { Directional, Point, Spot } type = Type::Point;
  Vec3 color{1, 1, 1};
  float intensity = 1;
  Vec3 position{0, 0, 0};
  Vec3 direction{0, 0, -1};  ///< where the light points (directional, spot)
  float innerConeAngle = 0, outerConeAngle = 0.7853982f;  ///< radians (spot)
};

/// A camera of a HostScene, for View::sceneCamera.
struct SceneCamera {
  std::string name;
  Mat4 transform = kIdentity;  ///< camera to world: it looks down its -Z axis, +Y up
  bool orthographic = false;
  float yfov = float(kDefaultYfov);  ///< radians (perspective)
  float ymag = 1;           ///< half the view's height (orthographic)
};

/// One mesh's vertices, for a HostScene whose vertices snell keeps.
struct MeshVertices {
  std::vector<float> positions;  ///< 3 floats a vertex
  std::vector<float> normals;    ///< 3 floats a vertex, unit length (a subdivision cage's may be empty: snell makes its own)
};

/// A scene built from the host's own data, with its vertices in one of two places:
///
/// - The host's GPU buffers (`positions` and `normals` set): packed float
///   triples (12 bytes a vertex) in two VkBuffers made with
///   VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, each mesh at its firstVertex: one
///   buffer for all meshes, as an engine's skinning output usually is. snell
///   reads them in place and never frees them. A scene with a subdivision
///   surface is the one exception: its refined vertices are snell's, and the
///   trace reads one vertex buffer, so snell copies every other mesh's vertices
///   from the host's buffers into its own, all of them at the first frame and
///   then each mesh when the host marks it dirty (Renderer::markDirty). The
///   cages are read in place. In such a scene, a mesh rewritten without
///   markDirty keeps drawing its old vertices.
/// - snell's own buffers (`positions` and `normals` null): `vertices` gives
///   each mesh's vertices (Mesh::vertexCount of them; firstVertex is
///   ignored). Each Renderer keeps a copy on the GPU and a mapped one the host
///   rewrites between frames (Renderer::vertices); a host without Vulkan (a
///   script, a DCC) uses these.
struct HostScene {
  std::string name = "host scene";  ///< for messages
  VkBuffer positions = VK_NULL_HANDLE, normals = VK_NULL_HANDLE;
  uint32_t vertexCapacity = 0;  ///< vertices each buffer holds
  std::vector<MeshVertices> vertices;  ///< one per mesh, when snell keeps them
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Instance> instances;
  std::vector<Light> lights;
  std::vector<SceneCamera> cameras;
};

/// What is drawn: a glTF file, or the host's data.
class Scene {
 public:
  /// Loads a glTF 2.0 file (.gltf or .glb); throws Error naming the file and the problem.
  static Scene load(const std::string& path);
  /// Wraps the host's data; the host's buffers must outlive every Renderer of
  /// this scene. Throws Error naming the mesh, material or instance at fault.
  static Scene fromHost(const HostScene& host);
  ~Scene();
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;

  std::string name() const;
  /// Meshes: glTF primitives, or HostScene::meshes (the index markDirty takes).
  size_t meshCount() const;
  /// Cameras the file (or HostScene::cameras) defines (View::sceneCamera).
  size_t cameraCount() const;
  /// Mesh `mesh`'s vertex count (Scene::meshCount meshes): the cage's, of a subdivision surface.
  uint32_t vertexCount(int mesh) const;
  /// The vertices and triangles mesh `mesh` is drawn with: a subdivision
  /// surface's refined ones, else its own (all its materials' together).
  uint32_t drawnVertexCount(int mesh) const;
  uint32_t drawnTriangleCount(int mesh) const;
  /// What loading repaired or left out, and what a subdivision cage could not
  /// be (each names the file or mesh): what a host shows its user as warnings.
  std::vector<std::string> warnings() const;
  /// Whether snell keeps the vertices (a HostScene without buffers: Renderer::vertices).
  bool keepsVertices() const;
  /// The longest animation, in seconds (0: static).
  double duration() const;

  struct Impl;
  Impl& impl() const { return *impl_; }

 private:
  explicit Scene(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// A look-at camera with a vertical field of view.
struct Camera {
  Vec3 eye{0, 0, 3}, target{0, 0, 0}, up{0, 1, 0};
  float yfov = float(kDefaultYfov);  ///< radians

  /// The camera `snell render` frames a scene without one with: looking down
  /// -Z at the centre of the world box [lo, hi], far enough back to see its
  /// whole bounding sphere. An empty box (lo > hi) frames the origin.
  static Camera framing(const Vec3& lo, const Vec3& hi, float yfov = float(kDefaultYfov));
};

/// A camera given as the host's own matrices (a DCC viewport's), OpenGL's conventions.
struct CameraMatrices {
  Mat4 view = kIdentity;  ///< world to camera: the camera looks down its -Z axis, +Y up
  /// Camera to clip space: perspective (an off-centre frustum for lens
  /// shift) or orthographic (the same with an offset), depth range
  /// ignored. Its aspect (the width its x covers over the height its y
  /// covers) must be the view's width / height: pixels are square.
  Mat4 projection = kIdentity;
};

/// What glass reflects (View::environment): an equirectangular (lat-long)
/// map of linear RGB radiance, as `snell render --environment` reads one:
/// row 0 looks up (+Y), the middle column looks down -Z, and the columns turn
/// towards +X to the right of the middle. Shared, not copied, by the Views
/// that hold it: a Renderer uploads each environment once.
class Environment {
 public:
  /// From the host's pixels: width * height * 3 floats (RGB, row 0 at the
  /// top), each finite and 0 or more. One wider than 4096 texels is halved
  /// (a box filter) until it fits. Throws Error naming `name` and the problem.
  static Environment fromPixels(uint32_t width, uint32_t height, const float* rgb,
                                const std::string& name = "environment");
  /// Its size once fitted.
  uint32_t width() const;
  uint32_t height() const;
  /// The name messages give it.
  std::string name() const;

  struct Impl;
  const std::shared_ptr<const Impl>& impl() const { return impl_; }

 private:
  explicit Environment(std::shared_ptr<const Impl> impl);
  std::shared_ptr<const Impl> impl_;
};

/// One picture of the scene.
struct View {
  uint32_t width = 640, height = 480;
  /// The scene's camera of this index; -1: `matrices`, else `camera` below.
  int sceneCamera = -1;
  Camera camera;
  /// The host's matrices instead of `camera` (when sceneCamera is -1).
  std::optional<CameraMatrices> matrices;
  enum class Output {
    Viewport,  ///< rasterised, with only the refracting pixels traced: the talk's viewport
    Trace,     ///< every pixel traced
  } output = Output::Viewport;
  /// How glass is drawn: "auto" or a name methods() lists (those of `snell
  /// render --method`: "trace", "iris-plane", ...); empty: "auto", which is
  /// "trace" unless the Device has the driver's ray tracing
  /// (DeviceOptions::driverRayTracing) and the first frames time "driver-rt"
  /// faster. With Output::Viewport the traced methods trace only the
  /// refracting pixels under the raster pass; a raster method draws the
  /// viewport whatever `output` says.
  /// "refraction-map" bakes its map with the trace at the first frame that
  /// draws it (again when the view's size changes).
  std::string method;
  /// Refractive faces a ray may cross (at most 1024).
  uint32_t maxInterfaces = 8;
  bool fresnel = true;     ///< glass reflects as well as refracts: highlights, catch lights, the environment
  bool dispersion = true;  ///< KHR_materials_dispersion splits the colours
  bool volume = true;      ///< KHR_materials_volume tints light inside thick glass
  Vec3 background{0.02f, 0.02f, 0.025f};  ///< linear RGB where nothing is drawn
  /// What the rays that glass reflects see where they meet nothing (with
  /// `fresnel`); none: snell's studio gradient. Camera rays and the rays
  /// glass transmits see `background` there.
  std::optional<Environment> environment;
  /// Viewport only: alpha 0 (and black) where nothing is drawn, so the host
  /// composites the image over its own with premultiplied alpha.
  bool transparentBackground = false;
};

/// A host image snell writes a view into, on the Device's queue family. Its
/// size must be the view's; it needs VK_IMAGE_USAGE_TRANSFER_DST_BIT and a
/// format that can be a blit destination (RGBA8 UNORM or SRGB, BGRA8, RGBA16F,
/// RGBA32F). snell moves it from `layoutBefore` (UNDEFINED: its contents are
/// discarded) to TRANSFER_DST_OPTIMAL, writes it with a blit (an SRGB format
/// gets sRGB-encoded values), and leaves it in `layoutAfter`.
struct Target {
  VkImage image = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_R8G8B8A8_SRGB;
  uint32_t width = 0, height = 0;
  VkImageLayout layoutBefore = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImageLayout layoutAfter = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
};

/// How a frame's submission orders against the host's work. snell submits one
/// command buffer per frame to the Device's queue; it starts with a full
/// barrier, so work the host submitted to that queue before (its own writes
/// to the vertex buffers or the target included) is finished and visible.
struct Sync {
  /// Binary semaphore snell's submission waits for (e.g. the host's skinning
  /// on another queue, or a swapchain acquire); VK_NULL_HANDLE: none.
  VkSemaphore wait = VK_NULL_HANDLE;
  VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
  /// Binary semaphore signalled once the target is written and in layoutAfter; VK_NULL_HANDLE: none.
  VkSemaphore signal = VK_NULL_HANDLE;
};

/// How a Renderer works.
struct RendererOptions {
  /// Frames recorded ahead of the GPU; render() waits for the frame this many frames back.
  uint32_t framesInFlight = 2;
  /// GPU timestamps around each pass, for FrameInfo::passes; off, frames record none.
  bool passTimes = true;
  /// Trees of 40 bytes a triangle, whose walk decodes each node's 8-bit
  /// quantised child boxes; off (the default), 216 bytes a triangle, the
  /// children's exact boxes and grandchildren's 4-wide records kept beside
  /// each node, and a faster walk (bench/results/walk-counts.md). The
  /// pictures are the same.
  bool compactTrees = false;
};

/// GPU time of one pass of a frame.
struct PassTime {
  std::string name;  ///< deform, blas build, blas refit, tlas, raster depth, trace list, trace, raster shading, ...
  double milliseconds = 0;
};

/// What the last frame did (for the host's statistics overlay).
struct FrameInfo {
  uint64_t frame = 0;
  uint32_t treesRefit = 0, treesBuilt = 0, treesSkipped = 0;
  uint64_t pixelsTraced = 0;
  bool skipped = false;  ///< nothing changed since the view was last drawn: the image was reused
  uint32_t itemsDeformed = 0;   ///< glTF items whose morphs or skin snell deformed
  uint32_t meshesUploaded = 0;  ///< meshes whose vertices were copied to the GPU: kept ones, or a host's beside a subdivision surface
  uint32_t meshesRefined = 0;   ///< subdivision surfaces whose moved cage the GPU refined
  uint32_t verticesRefined = 0; ///< the vertices those became
  bool topLevelBuilt = false, topLevelRefit = false;
  uint32_t dispatches = 0, draws = 0;
  std::string method;            ///< how glass was drawn
  std::vector<PassTime> passes;  ///< GPU time per pass, in order
};

/// What the trace found at each pixel of a view (Renderer::readAovs), row 0
/// at the top, as `snell render --aov` writes them into an EXR.
struct Aovs {
  uint32_t width = 0, height = 0;
  /// The traced picture, linear RGBA; alpha is coverage: 1 where the pixel's ray met a surface.
  std::vector<float> rgba;
  /// Camera-space depth of the first surface along the view's axis; +infinity where none.
  std::vector<float> depth;
  /// 3 per pixel: the first surface's unit world-space face normal; 0 where
  /// none, and everywhere for a scene whose vertices are in the host's buffers.
  std::vector<float> normal;
  /// The first surface's draw item (Renderer::instanceCount) and its triangle; UINT32_MAX where none.
  std::vector<uint32_t> instance, primitive;
  std::vector<uint32_t> interfaces;  ///< glass (and see-through) faces the pixel's path crossed
  std::vector<uint32_t> cost;        ///< tree nodes the pixel's paths visited
};

/// Where the host rewrites a kept mesh's vertices (Renderer::vertices).
struct Vertices {
  float* positions = nullptr;  ///< count * 3 floats
  float* normals = nullptr;    ///< count * 3 floats
  uint32_t count = 0;
};

/// Draws views of one scene, updating only what changed between frames.
class Renderer {
 public:
  /// Uploads the scene (the host's buffers are used in place). The Device and
  /// Scene must outlive the Renderer.
  Renderer(Device& device, Scene& scene, const RendererOptions& options = {});
  ~Renderer();
  Renderer(Renderer&&) noexcept;
  Renderer& operator=(Renderer&&) noexcept;

  /// Poses a glTF scene at `seconds` (its animations, morphs and skins).
  /// Transforms set with setTransform stay in force.
  void setTime(double seconds);
  /// Draw items: one per instance of a host scene, one per placed glTF primitive.
  size_t instanceCount() const;
  /// Moves instance `instance` (mesh space to world); the next frame refits the top-level tree only.
  void setTransform(size_t instance, const Mat4& transform);
  /// Says the host rewrote mesh `mesh`'s vertices (in its buffers, or in
  /// those Renderer::vertices hands out): the next frame refits that mesh's
  /// tree and redraws. Write the vertices, then call this, then render().
  void markDirty(int mesh);
  /// A kept mesh's vertices (Scene::keepsVertices) in mapped host memory,
  /// for the host to rewrite in place, then markDirty: the next frame
  /// copies them to the GPU and bounds them anew. Waits for the frames in
  /// flight, so the memory is the host's until the next render() or read();
  /// the pointers stay valid for the Renderer's life.
  Vertices vertices(int mesh);

  /// Renders `view` into `target`, submitted with `sync`; returns the frame's
  /// number. The host may record its own use of the target once `sync.signal`
  /// is waited for, or after wait(frame).
  uint64_t render(const View& view, const Target& target, const Sync& sync = {});
  /// Blocks until frame `frame` is complete on the GPU.
  void wait(uint64_t frame);
  /// Renders `view` and reads it back: linear RGBA floats, row 0 at the top (tests, thumbnails).
  std::vector<float> read(const View& view);
  /// The same into the host's memory: view.width * view.height * 4 floats.
  void read(const View& view, float* rgba);
  /// Traces every pixel of `view` (whatever its output says) and reads the
  /// picture back with what each pixel's ray found. The method must trace:
  /// "auto" (empty), "trace" or "trace-1".
  Aovs readAovs(const View& view);
  /// What the last frame did.
  FrameInfo lastFrame() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// One frame of a shot (renderFrames): a time of the scene's animation, and
/// what the host changes at it over the scene's own pose (a DCC's animation).
struct ShotFrame {
  long number = 0;       ///< the host's frame number, handed back with its picture
  double seconds = 0.0;  ///< the scene's time (a glTF scene's animations)
  /// The camera at this frame (a DCC's matrices); none: the shot's View's camera.
  std::optional<CameraMatrices> camera;
  /// Instances placed at this frame (mesh space to world), as Renderer::setTransform takes them.
  std::vector<std::pair<size_t, Mat4>> transforms;
  /// Kept meshes' vertices at this frame (Scene::keepsVertices), by mesh index.
  /// Each device keeps what the frames it drew gave: a mesh that one frame
  /// rewrites should come in every frame, or a frame's pixels would depend on
  /// which device drew it.
  std::vector<std::pair<int, MeshVertices>> vertices;
};

/// A frame of a shot, drawn.
struct ShotPicture {
  long number = 0;
  double seconds = 0.0;
  uint32_t width = 0, height = 0;
  std::vector<float> rgba;  ///< linear RGBA, row 0 at the top
  size_t worker = 0;        ///< which entry of the devices drew it
  std::string device;       ///< that device's name
  std::string method;       ///< how its glass was drawn
};

/// What a shot did, per worker.
struct ShotSummary {
  struct Worker {
    std::string device;
    size_t frames = 0;
    double loadSeconds = 0.0;     ///< its device, the scene's upload and pipelines, before its first frame
    double gpuWaitSeconds = 0.0;  ///< waiting for its frames' GPU work
    std::string lost;             ///< why its device stopped early ("" when it ran to the end)
    uint64_t validationMessages = 0;  ///< what the validation layer said on its device (DeviceOptions::validation)
  };
  std::vector<Worker> workers;
  size_t frames = 0;
  double seconds = 0.0;
};

/// Draws a shot: each frame `next` gives (until it gives none) as `view`
/// sets it up, handed to `done` once drawn, in the order the frames finish.
/// One worker per device of `devices` ("all": every GPU, or every one a
/// launcher's CUDA_VISIBLE_DEVICES lists; or indices and UUIDs, "0,1", an
/// entry twice giving two workers on one device; empty: the one device
/// `options.device` names) with its own Vulkan device made by `options`, scene upload and trees,
/// so a slower device takes fewer frames, and a lost one hands its frames to
/// the others. Every frame is drawn afresh, so its pixels do not depend on
/// which device drew it. `next` and `done` run on the calling thread (a DCC's
/// main thread), a few frames ahead of the workers. "auto" on several devices is "trace".
ShotSummary renderFrames(const std::string& devices, Scene& scene, const View& view,
                         const std::function<std::optional<ShotFrame>()>& next,
                         const std::function<void(ShotPicture&&)>& done, const DeviceOptions& options = {});

/// An image whose memory another API imports: OpenGL through
/// GL_EXT_memory_object_fd (glImportMemoryFdEXT, then glTextureStorageMem2DEXT
/// with the same size, a format of the same bytes and optimal tiling). Needs
/// a Device made with DeviceOptions::interop.
class SharedImage {
 public:
  /// An exportable image, usable as a Target (TRANSFER_DST and SAMPLED).
  SharedImage(Device& device, uint32_t width, uint32_t height, VkFormat format = VK_FORMAT_R8G8B8A8_SRGB);
  ~SharedImage();
  SharedImage(SharedImage&&) noexcept;
  SharedImage& operator=(SharedImage&&) noexcept;

  /// A Target of this image, moved between the layouts given.
  Target target(VkImageLayout before, VkImageLayout after) const;
  /// A new file descriptor of the image's memory; the importer owns it
  /// (glImportMemoryFdEXT takes it over).
  int exportMemory() const;
  /// The memory's size in bytes (glImportMemoryFdEXT's size).
  uint64_t memorySize() const;
  /// Whether the memory is a dedicated allocation (then set GL_DEDICATED_MEMORY_OBJECT_EXT).
  bool dedicated() const;
  VkImage image() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// A binary semaphore another API imports (OpenGL through GL_EXT_semaphore_fd),
/// where Device::exportsSemaphores() says the device can.
class SharedSemaphore {
 public:
  explicit SharedSemaphore(Device& device);
  ~SharedSemaphore();
  SharedSemaphore(SharedSemaphore&&) noexcept;
  SharedSemaphore& operator=(SharedSemaphore&&) noexcept;

  VkSemaphore handle() const;
  /// A new file descriptor of the semaphore; the importer owns it.
  int exportFd() const;

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

/// An image file's samples as it stores them, decoded; row 0 at the top.
struct ImageFile {
  uint32_t width = 0, height = 0;
  uint32_t channels = 0;  ///< 1 grey, 2 grey and alpha, 3 RGB, 4 RGBA
  uint32_t bits = 8;      ///< 8 or 16 (unsigned integers, native-endian) or 32 (float: Radiance HDR)
  std::vector<uint8_t> data;  ///< width * height * channels samples of bits / 8 bytes, row after row
};

/// Decodes an image file as stb_image reads it (PNG of 8 or 16 bits, JPEG,
/// TGA, BMP, PSD, GIF, Radiance HDR, PIC, PNM: the decoder snell's glTF
/// loader uses), so a host needs no image library of its own. Throws Error
/// naming the file and the problem (another format, such as EXR, included).
ImageFile readImageFile(const std::string& path);

/// Writes linear RGBA floats (width * height * 4, row 0 at the top) as an
/// 8-bit sRGB PNG, as `snell render` writes one: into a temporary file in the
/// same folder, renamed into place once complete, so a failed write leaves
/// nothing. Alpha is kept where `alpha` is set, else opaque. Throws Error
/// naming the file and the problem.
void writePng(const std::string& path, uint32_t width, uint32_t height, const float* rgba, bool alpha = false);

}  // namespace snell

#pragma GCC visibility pop
