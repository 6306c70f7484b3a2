// The scene the renderer consumes: shapes (one per glTF triangle primitive),
// the node graph that places them, materials, textures, lights, cameras, skins
// and animation clips. Loaded from glTF (gltf_loader.h) or built in code
// (the procedural eye); evaluated at a time by evaluate.h.
#pragma once

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace snell::scene {

/// A file that cannot become a scene, or a scene that cannot be used; the
/// message starts with the file's path.
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Linear RGB where nothing is drawn, unless a command or a host asks for
/// another: the GPU's frames, the CPU reference and every command's default.
/// (The public API, include/snell/snell.h, states the same value for hosts.)
inline const glm::dvec3 kDefaultBackground{0.02, 0.02, 0.025};

/// Bytes as "12.3 MiB", for messages and summaries.
inline std::string mebibytes(uint64_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  return text;
}

/// A decoded texture, always RGBA8 (sRGB or linear is the material's business).
struct Texture {
  std::string name;
  uint32_t width = 0;
  uint32_t height = 0;
  std::vector<uint8_t> rgba;  ///< width * height * 4 bytes
  bool repeatS = true, repeatT = true, mirrorS = false, mirrorT = false;
  bool linearFilter = true;
};

/// The linear value of an 8-bit sRGB channel (IEC 61966-2-1), exact in double:
/// the reference decodes with it and the GPU looks up its float rounding.
inline double srgbToLinear(uint8_t value) {
  double c = double(value) / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

/// A material's use of a texture: which one, which UV set, and the
/// KHR_texture_transform applied to the UVs.
struct TextureRef {
  int texture = -1;  ///< index into Scene::textures; -1: none
  int texCoord = 0;  ///< TEXCOORD_n
  glm::mat3 transform{1.0f};
  bool present() const { return texture >= 0; }
};

/// KHR_texture_transform's UV matrix: translate(offset) * rotate(rotation) * scale(scale).
inline glm::mat3 uvTransform(glm::vec2 offset, float rotation, glm::vec2 scale) {
  float c = std::cos(rotation), s = std::sin(rotation);
  // Column-major, as glm stores them.
  glm::mat3 translate(1, 0, 0, 0, 1, 0, offset.x, offset.y, 1);
  glm::mat3 rotate(c, -s, 0, s, c, 0, 0, 0, 1);
  glm::mat3 scaling(scale.x, 0, 0, 0, scale.y, 0, 0, 0, 1);
  return translate * rotate * scaling;
}

enum class AlphaMode { Opaque, Mask, Blend };

struct Material {
  std::string name;
  glm::vec4 baseColorFactor{1.0f};
  TextureRef baseColorTexture;
  glm::vec3 emissiveFactor{0.0f};
  TextureRef emissiveTexture;
  /// A tangent-space normal map (glTF normalTexture); x and y are scaled by normalScale.
  TextureRef normalTexture;
  float normalScale = 1.0f;
  bool doubleSided = false;
  AlphaMode alphaMode = AlphaMode::Opaque;
  float alphaCutoff = 0.5f;
  float roughness = 1.0f;  ///< pbrMetallicRoughness.roughnessFactor: the width of a glass face's highlights
  // KHR_materials_transmission
  float transmission = 0.0f;
  TextureRef transmissionTexture;
  // KHR_materials_ior
  float ior = 1.5f;
  // KHR_materials_volume
  float thickness = 0.0f;  ///< 0: thin-walled
  TextureRef thicknessTexture;
  glm::vec3 attenuationColor{1.0f};
  float attenuationDistance = std::numeric_limits<float>::infinity();
  // KHR_materials_dispersion: 20 / Abbe number; 0: none
  float dispersion = 0.0f;
  // SNELL_materials_ior_texture: ior + iorOffset + iorScale * red channel (linear)
  TextureRef iorTexture;
  float iorScale = 1.0f, iorOffset = 0.0f;
  // SNELL_materials_priority: which of overlapping media a ray is in (larger wins)
  int priority = 0;

  /// A volume attenuates the light crossing it (thin-walled materials do not).
  bool attenuates() const {
    return thickness > 0.0f && std::isfinite(attenuationDistance) && attenuationDistance > 0.0f;
  }

  /// Faces with this material refract (the talk's cornea tip).
  bool refractive() const { return transmission > 0.0f; }
};

/// One morph target's per-vertex deltas; a missing attribute is empty.
struct MorphTarget {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
};

/// Where a host application keeps a shape's vertices (the embedding API):
/// positions and normals in the host's own GPU buffers, from vertex `first` on.
struct HostVertices {
  uint32_t first = 0, count = 0;
  /// A box the host promises the vertices stay in, in the shape's space; an
  /// empty box (lo > hi) promises nothing and the shape is never culled.
  glm::vec3 lo{INFINITY}, hi{-INFINITY};
};

struct Refinement;  // subdivision.h

/// One glTF triangle primitive: topology and rest pose. Normals are generated
/// (area-weighted) when the file has none.
struct Shape {
  std::string name;
  int mesh = -1;  ///< the glTF mesh it belongs to (morph weights are per mesh)
  int material = -1;  ///< -1: the default material
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> texcoords0, texcoords1;
  std::vector<uint32_t> indices;  ///< triangle list, 3 per triangle
  std::vector<MorphTarget> targets;
  std::vector<glm::uvec4> joints;  ///< indices into the skin's joint list
  std::vector<glm::vec4> weights;  ///< the 4 strongest influences, summing to 1
  uint32_t maxJoint = 0;           ///< the largest joint index used, checked against the skin
  /// Set for a host's shape: its vertices live on the GPU only (positions and normals stay empty).
  std::optional<HostVertices> host;
  /// Set for a subdivision surface (subdivision.h): the vertices above are
  /// then its refined ones at rest, `refinedVertexCount` of them, made from
  /// a cage of `cageVertices`, which is what a host writes (host->count).
  std::shared_ptr<const Refinement> refinement;
  uint32_t cageVertices = 0, refinedVertexCount = 0;
  /// Set for a part of shape `vertexSource` drawn with another material (a
  /// mesh with a material per face, splitByMaterial): its triangles index
  /// that shape's vertices, which it carries too (its host range, its
  /// refinement, a copy of its positions) for what reads a shape alone, but
  /// the GPU's vertices are the source's, uploaded, copied, kept and refined once.
  int vertexSource = -1;

  /// The vertices its triangles index.
  size_t vertexCount() const { return refinement ? refinedVertexCount : host ? host->count : positions.size(); }
  /// The vertices a host writes: the cage's of a subdivision surface.
  size_t writtenVertexCount() const { return refinement ? cageVertices : vertexCount(); }
  bool subdivided() const { return refinement != nullptr; }
  bool part() const { return vertexSource >= 0; }
  size_t triangleCount() const { return indices.size() / 3; }
  bool morphed() const { return !targets.empty(); }
  bool skinned() const { return !joints.empty(); }
};

/// A glTF mesh: the shapes of its primitives and their shared default weights.
struct Mesh {
  std::string name;
  std::vector<int> shapes;
  std::vector<float> weights;  ///< one per morph target
};

struct Camera {
  std::string name;
  bool orthographic = false;
  float yfov = 0.8f;         ///< radians, perspective
  float aspectRatio = 0.0f;  ///< 0: use the image's
  float xmag = 1.0f, ymag = 1.0f;  ///< orthographic half extents
  float znear = 0.01f;
  float zfar = std::numeric_limits<float>::infinity();
};

enum class LightType { Directional, Point, Spot };

/// KHR_lights_punctual: intensity in candela (point, spot) or lux (directional).
struct Light {
  std::string name;
  LightType type = LightType::Point;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;
  float range = std::numeric_limits<float>::infinity();
  float innerConeAngle = 0.0f;
  float outerConeAngle = 0.7853982f;
};

struct Skin {
  std::string name;
  std::vector<int> joints;  ///< node indices
  std::vector<glm::mat4> inverseBindMatrices;
  int skeleton = -1;
};

struct Node {
  std::string name;
  int parent = -1;
  std::vector<int> children;
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 scale{1.0f};
  std::optional<glm::mat4> matrix;  ///< when the file gives a matrix (not animatable)
  int mesh = -1;
  int skin = -1;
  int camera = -1;
  int light = -1;
  std::vector<float> weights;  ///< overrides the mesh's default morph weights
  std::vector<glm::mat4> instances;  ///< EXT_mesh_gpu_instancing, local to the node
};

enum class AnimationPath { Translation, Rotation, Scale, Weights };
enum class Interpolation { Step, Linear, CubicSpline };

struct AnimationSampler {
  Interpolation interpolation = Interpolation::Linear;
  std::vector<float> times;   ///< seconds, increasing
  std::vector<float> values;  ///< flat: per key `components` floats (x3 for cubic: in, value, out)
  int components = 0;         ///< 3, 4 (rotation) or the number of morph targets
};

struct AnimationChannel {
  int node = -1;
  AnimationPath path = AnimationPath::Translation;
  int sampler = -1;
};

struct Animation {
  std::string name;
  std::vector<AnimationSampler> samplers;
  std::vector<AnimationChannel> channels;
  float duration = 0.0f;  ///< the last key time of any sampler
};

struct Scene {
  std::string source;  ///< the file it came from, for messages
  std::vector<Shape> shapes;
  std::vector<Mesh> meshes;
  std::vector<Material> materials;
  std::vector<Texture> textures;
  std::vector<Camera> cameras;
  std::vector<Light> lights;
  std::vector<Skin> skins;
  std::vector<Node> nodes;
  std::vector<int> roots;  ///< root nodes of the chosen glTF scene
  std::vector<Animation> animations;
  std::vector<std::string> warnings;  ///< things that loaded but were dropped or repaired
  /// Where loading spent its time (loadGltf): parsing the file, then decoding
  /// its images on `decodeThreads` threads.
  struct LoadTimes {
    double parseSeconds = 0.0, decodeSeconds = 0.0;
    unsigned decodeThreads = 0;
  } loadTimes;
};

}  // namespace snell::scene
