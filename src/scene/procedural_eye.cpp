// Geometry, materials, rig and animation of the procedural eye.
#include "scene/procedural_eye.h"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace snell::scene {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kEyeRadius = 0.012f;      // metres: a human eye is about 24 mm across
constexpr float kLimbusRadius = 0.0058f;  // where the cornea meets the sclera
constexpr float kCorneaGap = 0.0002f;     // the cornea shell sits this far outside the sclera
constexpr float kPupilRadius = 0.0020f;
constexpr float kIrisCone = 0.0003f;      // the pupil edge stands this far in front of the iris rim
constexpr float kDilation = 0.0012f;      // how far "dilate" widens the pupil
constexpr glm::vec3 kSquash{1.08f, 1.08f, 0.75f};  // "squash": per-axis scale at weight 1

enum Part { kSclera, kCorneaTip, kCorneaRest, kIris, kPupil, kAqueous, kPartCount };
constexpr float kCorneaThickness = 0.00055f;  // central corneal thickness: the aqueous starts this far in
constexpr float kAqueousIor = 1.336f;
enum Target { kTargetSquash, kTargetDilate };

/// Adds a band of a sphere (centre (0, 0, centreZ)) between polar angles
/// theta0 and theta1 from +Z; a band that reaches a pole closes it with a fan.
void addSphereBand(Shape& s, float radius, float centreZ, float theta0, float theta1, uint32_t rings, uint32_t segments) {
  uint32_t base = static_cast<uint32_t>(s.positions.size());
  bool northPole = theta0 <= 0.0f, southPole = theta1 >= kPi;
  uint32_t first = northPole ? 1 : 0, last = southPole ? rings - 1 : rings;
  auto emit = [&](float theta, float phi) {
    glm::vec3 n(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
    s.positions.push_back(glm::vec3(0, 0, centreZ) + radius * n);
    s.normals.push_back(n);
    s.texcoords0.push_back({phi / (2 * kPi), theta / kPi});
  };
  for (uint32_t r = first; r <= last; ++r) {
    float theta = theta0 + (theta1 - theta0) * float(r) / float(rings);
    for (uint32_t k = 0; k <= segments; ++k) emit(theta, 2 * kPi * float(k) / float(segments));
  }
  uint32_t rowCount = last - first + 1, stride = segments + 1;
  for (uint32_t r = 0; r + 1 < rowCount; ++r) {
    for (uint32_t k = 0; k < segments; ++k) {
      uint32_t a = base + r * stride + k, b = a + stride;
      s.indices.insert(s.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
  }
  auto fan = [&](float theta, uint32_t ring, bool north) {
    uint32_t pole = static_cast<uint32_t>(s.positions.size());
    emit(theta, 0.0f);
    for (uint32_t k = 0; k < segments; ++k) {
      uint32_t a = base + ring * stride + k;
      if (north) s.indices.insert(s.indices.end(), {pole, a, a + 1});
      else s.indices.insert(s.indices.end(), {a, pole, a + 1});
    }
  };
  if (northPole) fan(0.0f, 0, true);
  if (southPole) fan(kPi, rowCount - 1, false);
}

/// The iris: an annulus from the pupil to the limbus, its inner edge pushed
/// forward into a shallow cone; planar UVs for the radial texture.
void addIris(Shape& s, float z, uint32_t rings, uint32_t segments) {
  float outer = kLimbusRadius * 0.98f;
  for (uint32_t r = 0; r <= rings; ++r) {
    float t = float(r) / float(rings);  // 0 at the pupil, 1 at the rim
    float radius = kPupilRadius + (outer - kPupilRadius) * t;
    float height = z + kIrisCone * (1.0f - t);
    glm::vec3 normal = glm::normalize(glm::vec3(0, 0, 1) + glm::vec3(kIrisCone / (outer - kPupilRadius)) * glm::vec3(1, 1, 0));
    for (uint32_t k = 0; k <= segments; ++k) {
      float phi = 2 * kPi * float(k) / float(segments);
      glm::vec2 d(std::cos(phi), std::sin(phi));
      s.positions.push_back({radius * d.x, radius * d.y, height});
      s.normals.push_back(glm::normalize(glm::vec3(d.x * normal.x, d.y * normal.y, normal.z)));
      s.texcoords0.push_back({0.5f + 0.5f * radius * d.x / outer, 0.5f - 0.5f * radius * d.y / outer});
    }
  }
  for (uint32_t r = 0; r < rings; ++r) {
    for (uint32_t k = 0; k < segments; ++k) {
      uint32_t a = r * (segments + 1) + k, b = a + segments + 1;  // b: the next ring out
      // Counter-clockwise seen from the front (+z), where its normals point: glTF's front face.
      s.indices.insert(s.indices.end(), {a, b, a + 1, a + 1, b, b + 1});
    }
  }
}

/// A disc facing +Z (or -Z, wound the other way, when `back`).
void addDisc(Shape& s, float radius, float z, uint32_t segments, bool back = false) {
  uint32_t base = static_cast<uint32_t>(s.positions.size());
  glm::vec3 normal(0, 0, back ? -1.0f : 1.0f);
  s.positions.push_back({0, 0, z});
  s.normals.push_back(normal);
  s.texcoords0.push_back(glm::vec2(0.5f));
  for (uint32_t k = 0; k <= segments; ++k) {
    float phi = 2 * kPi * float(k) / float(segments);
    s.positions.push_back({radius * std::cos(phi), radius * std::sin(phi), z});
    s.normals.push_back(normal);
    s.texcoords0.push_back(glm::vec2(0.5f));
  }
  for (uint32_t k = 0; k < segments; ++k) {
    if (back) s.indices.insert(s.indices.end(), {base, base + k + 2, base + k + 1});
    else s.indices.insert(s.indices.end(), {base, base + k + 1, base + k + 2});
  }
}

/// "squash" scales about the eye's centre; "dilate" widens the pupil and
/// pulls the inner iris with it (zero for sclera and cornea).
void addTargets(Shape& s, Part part) {
  MorphTarget squash, dilate;
  for (size_t v = 0; v < s.vertexCount(); ++v) {
    glm::vec3 p = s.positions[v], n = s.normals[v];
    squash.positions.push_back(p * kSquash - p);
    squash.normals.push_back(glm::normalize(n / kSquash) - n);  // normals scale by the inverse
    glm::vec2 radial(p.x, p.y);
    float r = glm::length(radial);
    float pull = 0.0f;
    if (part == kPupil) pull = r / kPupilRadius;  // the whole disc scales
    if (part == kIris) pull = std::clamp((kLimbusRadius - r) / (kLimbusRadius - kPupilRadius), 0.0f, 1.0f);
    glm::vec2 move = r > 0.0f ? radial / r * (kDilation * pull) : glm::vec2(0.0f);
    dilate.positions.push_back({move.x, move.y, 0.0f});
    dilate.normals.push_back(glm::vec3(0.0f));
  }
  s.targets = {squash, dilate};
}

/// Radial fibres, a darker collarette and limbal ring, in hazel and blue.
Texture irisTexture() {
  Texture t;
  t.name = "iris";
  t.width = t.height = 256;
  t.rgba.resize(size_t(256) * 256 * 4);
  t.repeatS = t.repeatT = false;
  for (uint32_t y = 0; y < 256; ++y) {
    for (uint32_t x = 0; x < 256; ++x) {
      glm::vec2 d = (glm::vec2(float(x), float(y)) + 0.5f) / 128.0f - 1.0f;
      float r = glm::length(d), angle = std::atan2(d.y, d.x);
      float fibres = 0.5f + 0.5f * std::sin(angle * 90.0f + 6.0f * std::sin(angle * 7.0f + r * 11.0f));
      float collarette = std::exp(-std::pow((r - 0.55f) / 0.06f, 2.0f));
      glm::vec3 inner(0.55f, 0.38f, 0.15f), outer(0.20f, 0.35f, 0.55f);
      glm::vec3 colour = glm::mix(inner, outer, std::clamp((r - 0.3f) / 0.6f, 0.0f, 1.0f));
      colour *= 0.7f + 0.3f * fibres;
      colour *= 1.0f - 0.35f * collarette;
      colour *= 1.0f - 0.6f * std::clamp((r - 0.9f) / 0.1f, 0.0f, 1.0f);  // limbal ring
      uint8_t* px = &t.rgba[(size_t(y) * 256 + x) * 4];
      for (int c = 0; c < 3; ++c) px[c] = static_cast<uint8_t>(std::clamp(colour[c], 0.0f, 1.0f) * 255.0f + 0.5f);
      px[3] = 255;
    }
  }
  return t;
}

Material plain(const char* name, glm::vec3 colour) {
  Material m;
  m.name = name;
  m.baseColorFactor = glm::vec4(colour, 1.0f);
  return m;
}

struct EyeRig {
  int joint = -1;
  std::vector<int> meshNodes;
};

/// Adds one eye under `parent` at `offset`: a root and a joint, and the four
/// part nodes skinned to that joint. The part nodes are scene roots: a skinned
/// mesh ignores its node's transform, and glTF validators warn otherwise.
EyeRig addEyeRig(Scene& scene, int parent, glm::vec3 offset, const std::string& name) {
  auto node = [&](const std::string& n, int p) {
    scene.nodes.push_back({});
    scene.nodes.back().name = n;
    scene.nodes.back().parent = p;
    int index = static_cast<int>(scene.nodes.size() - 1);
    if (p >= 0) scene.nodes[size_t(p)].children.push_back(index);
    else scene.roots.push_back(index);
    return index;
  };
  int root = node(name, parent);
  scene.nodes[size_t(root)].translation = offset;
  int joint = node(name + "_joint", root);
  Skin skin;
  skin.name = name + "_skin";
  skin.joints = {joint};
  skin.skeleton = joint;
  // The joint rests at the eye's centre, unrotated: the mesh's own space (the
  // eye centred at its origin) is the joint's space at bind, so the inverse
  // bind is the identity and the joint's world transform places the eye.
  // (Undoing the joint's world placement here stacked every eye of a crowd
  // at the world's origin.)
  skin.inverseBindMatrices = {glm::mat4(1.0f)};
  scene.skins.push_back(skin);
  EyeRig rig;
  rig.joint = joint;
  const char* parts[] = {"sclera", "cornea", "iris", "pupil", "aqueous"};
  for (int m = 0; m < int(scene.meshes.size()); ++m) {
    int n = node(name + "_" + parts[m], -1);
    scene.nodes[size_t(n)].mesh = m;
    scene.nodes[size_t(n)].skin = static_cast<int>(scene.skins.size() - 1);
    rig.meshNodes.push_back(n);
  }
  return rig;
}

void addClip(Scene& scene, const std::vector<int>& joints, const std::vector<std::vector<int>>& meshNodes,
             const std::vector<float>& delays) {
  Animation clip;
  clip.name = "look_around";
  for (size_t e = 0; e < joints.size(); ++e) {
    float delay = delays[e];
    AnimationSampler turn;
    turn.components = 4;
    const float yaw[] = {0, 20, -15, 0, 0}, pitch[] = {0, 0, -10, 10, 0};
    for (int k = 0; k < 5; ++k) {
      turn.times.push_back(delay + float(k));
      glm::quat q = glm::angleAxis(glm::radians(yaw[k]), glm::vec3(0, 1, 0)) *
                    glm::angleAxis(glm::radians(pitch[k]), glm::vec3(1, 0, 0));
      turn.values.insert(turn.values.end(), {q.x, q.y, q.z, q.w});
    }
    AnimationSampler weights;
    weights.components = 2;
    const float times[] = {0.0f, 1.3f, 1.5f, 1.7f, 2.5f, 4.0f};
    const float squash[] = {0, 0, 1, 0, 0, 0}, dilate[] = {0, 0, 0, 0, 1, 0};
    for (int k = 0; k < 6; ++k) {
      weights.times.push_back(delay + times[k]);
      weights.values.insert(weights.values.end(), {squash[k], dilate[k]});
    }
    int turnIndex = static_cast<int>(clip.samplers.size());
    clip.samplers.push_back(turn);
    clip.samplers.push_back(weights);
    clip.channels.push_back({joints[e], AnimationPath::Rotation, turnIndex});
    for (int n : meshNodes[e]) clip.channels.push_back({n, AnimationPath::Weights, turnIndex + 1});
    clip.duration = std::max(clip.duration, delay + 4.0f);
  }
  scene.animations.push_back(clip);
}

}  // namespace

void checkEyeOptions(const EyeOptions& o) {
  auto range = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument(what);
  };
  range(o.ior >= 1.0f && o.ior <= 4.0f, "--ior must be between 1 and 4");
  range(o.irisDepth >= 0.0f && o.irisDepth <= 0.003f, "--iris-depth must be between 0 and 0.003 (metres)");
  range(o.corneaBulge >= 0.0005f && o.corneaBulge <= 0.005f, "--cornea-bulge must be between 0.0005 and 0.005 (metres)");
  range(o.resolution >= 8 && o.resolution <= 2048, "--resolution must be between 8 and 2048");
  range(o.crowd <= 10000, "--crowd must be at most 10000");
  range(!o.aqueous || o.corneaBulge >= 0.0015f, "--aqueous needs a --cornea-bulge of at least 0.0015 (metres)");
}

Scene makeEye(const EyeOptions& o) {
  checkEyeOptions(o);
  Scene scene;
  scene.source = "procedural eye";
  const uint32_t segments = o.resolution, rings = std::max(4u, o.resolution / 2);

  // Cornea geometry: a spherical cap through the limbus circle of the shell,
  // its apex `corneaBulge` in front of the limbus plane.
  const float shell = kEyeRadius + kCorneaGap;
  const float limbusZ = std::sqrt(shell * shell - kLimbusRadius * kLimbusRadius);
  const float corneaRadius = (kLimbusRadius * kLimbusRadius + o.corneaBulge * o.corneaBulge) / (2 * o.corneaBulge);
  const float corneaCentre = limbusZ + o.corneaBulge - corneaRadius;
  const float corneaTheta = std::asin(std::min(1.0f, kLimbusRadius / corneaRadius));
  const float scleraTheta = std::asin(kLimbusRadius / kEyeRadius);
  const float irisZ = std::sqrt(kEyeRadius * kEyeRadius - kLimbusRadius * kLimbusRadius) - o.irisDepth - kIrisCone;

  scene.materials = {plain("sclera", {0.93f, 0.90f, 0.86f}), plain("cornea_tip", {1, 1, 1}),
                     plain("cornea_rest", {0.93f, 0.90f, 0.86f}), plain("iris", {1, 1, 1}), plain("pupil", {0.02f, 0.02f, 0.02f})};
  // The sclera is a shell open behind the cornea: its inside is seen through it.
  scene.materials[kSclera].doubleSided = true;
  scene.materials[kCorneaTip].transmission = 1.0f;
  scene.materials[kCorneaTip].ior = o.ior;
  scene.materials[kCorneaTip].doubleSided = true;
  scene.materials[kCorneaTip].roughness = 0.2f;
  if (o.aqueous) {
    scene.materials.push_back(plain("aqueous", {1, 1, 1}));
    scene.materials[kAqueous].transmission = 1.0f;
    scene.materials[kAqueous].ior = kAqueousIor;
    scene.materials[kAqueous].roughness = 0.2f;
    scene.materials[kAqueous].priority = 1;  // inside the cornea's medium, the aqueous wins
  }
  scene.materials[kIris].baseColorTexture.texture = 0;
  scene.textures.push_back(irisTexture());

  std::vector<Shape> parts(kPartCount);
  addSphereBand(parts[kSclera], kEyeRadius, 0.0f, scleraTheta, kPi, rings, segments);
  addSphereBand(parts[kCorneaTip], corneaRadius, corneaCentre, 0.0f, corneaTheta, std::max(4u, rings / 2), segments);
  addSphereBand(parts[kCorneaRest], shell, 0.0f, std::asin(kLimbusRadius / shell), kPi, rings, segments);
  addIris(parts[kIris], irisZ, std::max(4u, rings / 2), segments);
  addDisc(parts[kPupil], kPupilRadius, irisZ - 0.0001f, segments);
  // The aqueous: a cap concentric with the cornea, kCorneaThickness inside it,
  // closed by a disc behind the pupil (so nothing in front of the iris sees the disc).
  const float aqueousRadius = corneaRadius - kCorneaThickness, aqueousBack = irisZ - 0.0003f;
  const float aqueousTheta = std::acos(std::clamp((aqueousBack - corneaCentre) / aqueousRadius, -1.0f, 1.0f));
  addSphereBand(parts[kAqueous], aqueousRadius, corneaCentre, 0.0f, aqueousTheta, std::max(4u, rings / 2), segments);
  addDisc(parts[kAqueous], aqueousRadius * std::sin(aqueousTheta), aqueousBack, segments, true);
  const int partCount = o.aqueous ? kPartCount : kAqueous;
  const char* names[] = {"sclera", "cornea_tip", "cornea_rest", "iris", "pupil", "aqueous"};
  for (int p = 0; p < partCount; ++p) {
    Shape& s = parts[size_t(p)];
    s.name = names[p];
    s.material = p;
    if (s.texcoords0.empty()) s.texcoords0.assign(s.vertexCount(), glm::vec2(0.5f));
    s.joints.assign(s.vertexCount(), glm::uvec4(0));
    s.weights.assign(s.vertexCount(), glm::vec4(1, 0, 0, 0));
    addTargets(s, Part(p));
    scene.shapes.push_back(std::move(s));
  }
  // Meshes: sclera, cornea (tip + rest: one mesh, two materials), iris, pupil.
  std::vector<std::vector<int>> meshShapes = {{kSclera}, {kCorneaTip, kCorneaRest}, {kIris}, {kPupil}};
  if (o.aqueous) meshShapes.push_back({kAqueous});
  const char* meshNames[] = {"sclera", "cornea", "iris", "pupil", "aqueous"};
  for (size_t m = 0; m < meshShapes.size(); ++m) {
    Mesh mesh;
    mesh.name = meshNames[m];
    mesh.shapes = meshShapes[m];
    mesh.weights = {0.0f, 0.0f};
    for (int s : mesh.shapes) scene.shapes[size_t(s)].mesh = static_cast<int>(m);
    scene.meshes.push_back(mesh);
  }

  std::vector<int> joints;
  std::vector<std::vector<int>> meshNodes;
  std::vector<float> delays;
  auto rig = [&](int parent, glm::vec3 offset, const std::string& name, float delay) {
    EyeRig eye = addEyeRig(scene, parent, offset, name);
    joints.push_back(eye.joint);
    meshNodes.push_back(eye.meshNodes);
    delays.push_back(delay);
  };
  float frameHalfHeight = kEyeRadius * 1.15f;
  if (o.crowd == 0) {
    rig(-1, glm::vec3(0.0f), "eye", 0.0f);
  } else {
    const float spacing = 0.15f, eyeSeparation = 0.064f;  // metres between heads; between pupils
    uint32_t columns = static_cast<uint32_t>(std::ceil(std::sqrt(float(o.crowd))));
    uint32_t rows = (o.crowd + columns - 1) / columns;
    for (uint32_t c = 0; c < o.crowd; ++c) {
      scene.nodes.push_back({});
      Node& head = scene.nodes.back();
      head.name = "character_" + std::to_string(c);
      head.translation = {(float(c % columns) - 0.5f * float(columns - 1)) * spacing,
                          (float(c / columns) - 0.5f * float(rows - 1)) * spacing, 0.0f};
      int headIndex = static_cast<int>(scene.nodes.size() - 1);
      scene.roots.push_back(headIndex);
      float delay = std::fmod(0.37f * float(c), 4.0f);  // staggered, so the crowd does not move in lockstep
      rig(headIndex, {-eyeSeparation / 2, 0, 0}, head.name + "_left_eye", delay);
      rig(headIndex, {eyeSeparation / 2, 0, 0}, scene.nodes[size_t(headIndex)].name + "_right_eye", delay);
    }
    frameHalfHeight = 0.5f * spacing * float(std::max(rows, columns));
  }
  addClip(scene, joints, meshNodes, delays);

  Camera camera;
  camera.name = "front";
  camera.yfov = 0.45f;
  camera.znear = 0.001f;
  camera.zfar = 100.0f;
  scene.cameras.push_back(camera);
  Node cameraNode;
  cameraNode.name = "camera";
  cameraNode.camera = 0;
  cameraNode.translation = {0.0f, 0.0f, 0.015f + frameHalfHeight / std::tan(camera.yfov / 2)};
  scene.nodes.push_back(cameraNode);
  scene.roots.push_back(static_cast<int>(scene.nodes.size() - 1));

  Light key;
  key.name = "key";
  key.type = LightType::Directional;
  key.intensity = 3.0f;
  Light fill;
  fill.name = "fill";
  fill.type = LightType::Point;
  fill.color = {0.8f, 0.85f, 1.0f};
  fill.intensity = 0.05f;
  scene.lights = {key, fill};
  Node keyNode;
  keyNode.name = "key_light";
  keyNode.light = 0;
  keyNode.rotation = glm::quatLookAt(glm::normalize(glm::vec3(0.4f, -0.5f, -1.0f)), glm::vec3(0, 1, 0));
  Node fillNode;
  fillNode.name = "fill_light";
  fillNode.light = 1;
  fillNode.translation = {-0.05f, 0.03f, 0.08f};
  for (Node& n : {std::ref(keyNode), std::ref(fillNode)}) {
    scene.nodes.push_back(n);
    scene.roots.push_back(static_cast<int>(scene.nodes.size() - 1));
  }
  return scene;
}

}  // namespace snell::scene
