// Scene::fromHost: a host's meshes, materials, textures, lights, cameras and
// instances (HostScene) checked and turned into a scene::Scene, each error
// naming the scene and the item; subdivision cages refined here once.
#include "snell/snell.h"

#include "api/api_internal.h"
#include "scene/scene_builder.h"
#include "scene/subdivision.h"

#include <cstring>
#include <string>
#include <vector>

namespace snell {

using api::guarded;
using api::toMatrix;
using api::toVec;

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
  const size_t faces = cage ? m.subdivision.faceVertexCounts.size() : m.indices.size() / 3;
  if (!m.faceMaterials.empty() && m.faceMaterials.size() != faces) {
    throw Error(where + ": " + std::to_string(m.faceMaterials.size()) + " face materials for " + std::to_string(faces) +
                (cage ? " cage faces" : " triangles"));
  }
  for (int material : m.faceMaterials) {
    if (material < -1 || material >= int(materials)) {
      throw Error(where + ": face material " + std::to_string(material) + " of " + std::to_string(materials));
    }
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

// The API's subdivision tags as the scene layer's. Switches, not casts of one
// enum's value to the other's: a tag the API gains and this misses fails the
// build (-Wswitch), where a cast would silently read another tag.
scene::SubdivisionScheme schemeOf(Subdivision::Scheme scheme) {
  switch (scheme) {
    case Subdivision::Scheme::Loop: return scene::SubdivisionScheme::Loop;
    case Subdivision::Scheme::Bilinear: return scene::SubdivisionScheme::Bilinear;
    case Subdivision::Scheme::CatmullClark:
    case Subdivision::Scheme::None: break;  // None is no cage; toCage is only asked for cages
  }
  return scene::SubdivisionScheme::CatmullClark;
}

scene::BoundaryInterpolation boundaryOf(Subdivision::Boundary boundary) {
  switch (boundary) {
    case Subdivision::Boundary::None: return scene::BoundaryInterpolation::None;
    case Subdivision::Boundary::EdgeOnly: return scene::BoundaryInterpolation::EdgeOnly;
    case Subdivision::Boundary::EdgeAndCorner: break;
  }
  return scene::BoundaryInterpolation::EdgeAndCorner;
}

scene::FaceVaryingInterpolation faceVaryingOf(Subdivision::FaceVarying rule) {
  switch (rule) {
    case Subdivision::FaceVarying::None: return scene::FaceVaryingInterpolation::None;
    case Subdivision::FaceVarying::CornersOnly: return scene::FaceVaryingInterpolation::CornersOnly;
    case Subdivision::FaceVarying::CornersPlus1: return scene::FaceVaryingInterpolation::CornersPlus1;
    case Subdivision::FaceVarying::CornersPlus2: return scene::FaceVaryingInterpolation::CornersPlus2;
    case Subdivision::FaceVarying::Boundaries: return scene::FaceVaryingInterpolation::Boundaries;
    case Subdivision::FaceVarying::All: break;
  }
  return scene::FaceVaryingInterpolation::All;
}

// A subdivision surface's cage, at rest at `positions` (3 floats a vertex;
// null for a mesh in the host's buffers, which snell never sees at rest).
scene::SubdivisionCage toCage(const Mesh& m, const float* positions) {
  const Subdivision& d = m.subdivision;
  scene::SubdivisionCage cage;
  cage.scheme = schemeOf(d.scheme);
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
  cage.boundary = boundaryOf(d.interpolateBoundary);
  cage.faceVarying = faceVaryingOf(d.faceVarying);
  cage.smoothTriangles = d.smoothTriangles;
  for (size_t i = 0; i + 1 < m.texcoords.size(); i += 2) cage.uvs.emplace_back(m.texcoords[i], m.texcoords[i + 1]);
  cage.uvIndices = d.uvIndices;
  return cage;
}

// Refines mesh `m`'s cage into `shape` (its warnings into the scene's), and
// says each refined triangle's cage face in `triangleFaces`; SceneError becomes Error.
void refineCage(const Mesh& m, const float* positions, scene::Shape& shape, scene::Scene& s, const std::string& where,
                std::vector<uint32_t>& triangleFaces) {
  try {
    std::optional<scene::HostVertices> host = shape.host;
    scene::subdivide(toCage(m, positions), shape, where, s.warnings, scene::kMaxRefinedVertices, &triangleFaces);
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
// are then snell's own, with a rest pose each Renderer keeps a copy of. A
// cage's triangles' cage faces go to `triangleFaces` (per mesh).
void keepVertices(const HostScene& host, Scene::Impl& impl, std::vector<std::vector<uint32_t>>& triangleFaces) {
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
      refineCage(m, v.positions.data(), shape, impl.scene, where, triangleFaces[i]);
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
    std::vector<std::vector<uint32_t>> triangleFaces(host.meshes.size());  // a cage's: each refined triangle's face
    if (keep) {
      keepVertices(host, *impl, triangleFaces);
    } else {
      impl->host = {host.positions, host.normals, host.vertexCapacity};
      for (size_t i = 0; i < host.meshes.size(); ++i) {
        if (host.meshes[i].subdivision.scheme == Subdivision::Scheme::None) continue;
        refineCage(host.meshes[i], nullptr, s.shapes[i], s, host.name + ": mesh " + std::to_string(i), triangleFaces[i]);
      }
    }
    // Each material of a mesh's faces after its first draws as a part that
    // shares the mesh's vertices and its one refinement; parts follow every mesh.
    for (size_t i = 0; i < host.meshes.size(); ++i) {
      const std::vector<int>& faceMaterials = host.meshes[i].faceMaterials;
      if (faceMaterials.empty()) continue;
      const std::vector<uint32_t>& faces = triangleFaces[i];
      std::vector<int> triangleMaterials(s.shapes[i].triangleCount());
      for (size_t t = 0; t < triangleMaterials.size(); ++t) triangleMaterials[t] = faceMaterials[faces.empty() ? t : faces[t]];
      scene::splitByMaterial(s, int(i), triangleMaterials);
    }
    return Scene(std::move(impl));
  });
}

}  // namespace snell
