// Mirrors shaders/common/scene.glsl and the traversal of shaders/comp/trace.comp: the same scene
// and closest hit, reached by an independent build (median split, watertight test in double).
#include "ref/prepared_scene.h"

#include "scene/texture_mips.h"
#include "shared/trace.h"

namespace snell::ref::detail {

namespace {

constexpr uint32_t kLeafSize = 4;

// The contract's headlight is a float; the reference uses exactly that value.
constexpr double kHeadlight = double(gpu::kHeadlight);

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

PreparedScene::PreparedScene(const scene::Scene& scene, const scene::Pose& pose, const scene::View& view) {
  textures_.reserve(scene.textures.size());
  // Only drawn textures get their mip chains (the others are never sampled).
  const std::vector<bool> colour = scene::colourTextures(scene), drawn = scene::drawnTextures(scene);
  for (size_t t = 0; t < scene.textures.size(); ++t) {
    textures_.push_back(drawn[t] ? decode(scene.textures[t], colour[t]) : LinearTexture{});
  }
  auto use = [&](const scene::TextureRef& ref) {
    TextureUse u;
    if (ref.texture >= 0 && size_t(ref.texture) < textures_.size() && !textures_[size_t(ref.texture)].levels.empty()) {
      u.texture = &textures_[size_t(ref.texture)];
      u.lodOffset = scene::textureLodOffset(scene.textures[size_t(ref.texture)], ref);
    }
    u.texCoord = ref.texCoord;
    u.transform = glm::dmat3(ref.transform);
    return u;
  };
  for (const scene::Material& m : scene.materials) {
    ResolvedMaterial r;
    r.baseFactor = glm::dvec3(glm::vec3(m.baseColorFactor));
    r.baseAlpha = double(m.baseColorFactor.a);
    r.alphaMode = m.alphaMode == scene::AlphaMode::Mask    ? gpu::kAlphaMask
                  : m.alphaMode == scene::AlphaMode::Blend ? gpu::kAlphaBlend
                                                           : gpu::kAlphaOpaque;
    r.alphaCutoff = double(m.alphaCutoff);
    r.emissiveFactor = glm::dvec3(m.emissiveFactor);
    r.base = use(m.baseColorTexture);
    r.emissive = use(m.emissiveTexture);
    r.normal = use(m.normalTexture);
    r.normalScale = double(m.normalScale);
    r.refractive = m.refractive();
    r.baseIor = double(m.ior);
    r.ior = use(m.iorTexture);
    r.iorScale = double(m.iorScale);
    r.iorOffset = double(m.iorOffset);
    r.roughness = double(m.roughness);
    r.dispersion = double(m.dispersion);
    r.priority = double(m.priority);
    r.attenuationColor = glm::dvec3(m.attenuationColor);
    r.attenuationDistance = m.attenuates() ? double(m.attenuationDistance) : 0.0;
    materials_.push_back(r);
  }

  for (size_t n = 0; n < scene.nodes.size() && n < pose.world.size(); ++n) {
    int index = scene.nodes[n].light;
    if (index < 0 || size_t(index) >= scene.lights.size()) continue;
    const scene::Light& light = scene.lights[size_t(index)];
    glm::dmat4 m(pose.world[n]);
    ResolvedLight r;
    r.type = light.type;
    r.position = glm::dvec3(m[3]);
    r.direction = -unitOrZero(glm::dvec3(m[2]));  // glTF lights shine down their node's -Z
    r.radiance = glm::dvec3(light.color) * double(light.intensity);
    r.range = light.range > 0.0f && std::isfinite(light.range) ? double(light.range) : kInfinity;
    r.cosInner = std::cos(double(light.innerConeAngle));
    r.cosOuter = std::cos(double(light.outerConeAngle));
    lights_.push_back(r);
  }
  if (lights_.empty()) {
    ResolvedLight headlight;
    headlight.type = scene::LightType::Directional;
    headlight.direction = unitOrZero(view.forward);
    headlight.radiance = glm::dvec3(kHeadlight);
    lights_.push_back(headlight);
  }

  for (size_t i = 0; i < pose.items.size(); ++i) addItem(scene, pose.items[i], int32_t(i));
  buildBvh();
}

void PreparedScene::addItem(const scene::Scene& scene, const scene::DrawItem& item, int32_t itemIndex) {
  if (item.shape < 0 || size_t(item.shape) >= scene.shapes.size()) return;
  const scene::Shape& shape = scene.shapes[size_t(item.shape)];
  const size_t vertices = shape.vertexCount();

  std::vector<glm::dvec3> positions, normals;
  if (item.deforms()) {
    if (shape.normals.size() == vertices) {
      scene::deformOnCpu(item, positions, normals);
    } else {
      // deformOnCpu reads a normal per vertex; give it zeros (shading falls back to Ng).
      scene::Scene scratch;
      scratch.shapes.push_back(shape);
      scratch.shapes[0].normals.assign(vertices, glm::vec3(0.0f));
      scene::DrawItem copy = item;
      copy.scene = &scratch;
      copy.shape = 0;
      scene::deformOnCpu(copy, positions, normals);
    }
  } else {
    positions.assign(shape.positions.begin(), shape.positions.end());
    normals.assign(vertices, glm::dvec3(0.0));
    if (shape.normals.size() == vertices) normals.assign(shape.normals.begin(), shape.normals.end());
  }

  const glm::dmat4 world(item.world);
  const glm::dmat3 normalMatrix = glm::transpose(glm::inverse(glm::dmat3(world)));
  for (size_t v = 0; v < vertices; ++v) {
    positions[v] = glm::dvec3(world * glm::dvec4(positions[v], 1.0));
    // Vertex normals are unit in world space before they are interpolated;
    // a non-uniform scale would otherwise weight them unevenly.
    normals[v] = unitOrZero(normalMatrix * normals[v]);
  }
  auto texcoords = [&](const std::vector<glm::vec2>& set, uint32_t v) {
    return set.size() == vertices ? glm::dvec2(set[v]) : glm::dvec2(0.0);
  };

  // A mirroring transform turns a face's winding round in the world, not
  // its front (glTF: its front is then clockwise); the reference tests
  // facing in the world, so its corners are taken the other way round. The
  // trace tests them in the instance's own space, where nothing turns.
  const bool mirrored = glm::determinant(glm::dmat3(world)) < 0.0;
  for (size_t t = 0; t < shape.triangleCount(); ++t) {
    const uint32_t* index = &shape.indices[t * 3];
    if (index[0] >= vertices || index[1] >= vertices || index[2] >= vertices) continue;
    TriangleData d;
    for (int k = 0; k < 3; ++k) {
      const uint32_t corner = index[mirrored && k > 0 ? 3 - k : k];
      d.v[k] = positions[corner];
      d.n[k] = normals[corner];
      d.uv[0][k] = texcoords(shape.texcoords0, corner);
      d.uv[1][k] = texcoords(shape.texcoords1, corner);
    }
    if (!finite(d.v[0]) || !finite(d.v[1]) || !finite(d.v[2])) continue;
    glm::dvec3 e1 = d.v[1] - d.v[0], e2 = d.v[2] - d.v[0];
    d.ng = unitOrZero(glm::cross(e1, e2));
    if (d.ng == glm::dvec3(0.0)) continue;  // no area: never hit
    const double worldArea = glm::length(glm::cross(e1, e2));
    for (int set = 0; set < 2; ++set) {
      glm::dvec2 d1 = d.uv[set][1] - d.uv[set][0], d2 = d.uv[set][2] - d.uv[set][0];
      d.density[set] = 0.5 * std::log2(std::abs(d1.x * d2.y - d1.y * d2.x) / worldArea);
    }
    if (d.n[0] != glm::dvec3(0.0) && d.n[1] != glm::dvec3(0.0) && d.n[2] != glm::dvec3(0.0)) {
      glm::dvec3 n[3] = {glm::normalize(d.n[0]), glm::normalize(d.n[1]), glm::normalize(d.n[2])};
      const double side = glm::dot(n[0] + n[1] + n[2], d.ng) < 0.0 ? -1.0 : 1.0;  // normals turned to ng's side
      double sum = 0.0;
      int edges = 0;
      for (int a = 0; a < 3; ++a) {
        int b = (a + 1) % 3;
        const glm::dvec3 edge = d.v[b] - d.v[a];
        const double length2 = glm::dot(edge, edge);
        if (length2 > 0.0) sum += side * glm::dot(n[b] - n[a], edge) / length2, ++edges;
      }
      const double k = edges > 0 ? sum / edges : 0.0;
      d.curvature = std::abs(k) < 1e30 ? k : 0.0;  // NaN and infinity: 0
    }
    d.item = itemIndex;
    d.primitive = int32_t(t);
    d.material = shape.material;
    // glTF's and USD's doubleSided false (the default material's too); glass is seen from both sides.
    const bool known = shape.material >= 0 && size_t(shape.material) < scene.materials.size();
    const scene::Material& m = known ? scene.materials[size_t(shape.material)] : scene::Material{};
    d.singleSided = !m.doubleSided && !m.refractive();
    data_.push_back(d);
  }
}

void PreparedScene::buildBvh() {
  const uint32_t count = uint32_t(data_.size());
  std::vector<Aabb> boxes(count);
  std::vector<glm::dvec3> centroids(count);
  Aabb all;
  for (uint32_t i = 0; i < count; ++i) {
    for (const glm::dvec3& v : data_[i].v) boxes[i].extend(v);
    // Padding keeps the slab test conservative where a hit lies on the
    // box's face and rounding would put the ray a hair outside it.
    double pad = 1e-9 * std::max(maxAbs(boxes[i].lo), maxAbs(boxes[i].hi));
    boxes[i].lo -= pad;
    boxes[i].hi += pad;
    centroids[i] = boxes[i].centroid();
    all.extend(boxes[i]);
  }
  size_ = count ? maxAbs(all.hi - all.lo) : 0.0;

  std::vector<uint32_t> order(count);
  for (uint32_t i = 0; i < count; ++i) order[i] = i;
  nodes_.clear();
  nodes_.push_back({});
  struct Task {
    uint32_t node, begin, end;
  };
  std::vector<Task> work{{0, 0, count}};
  while (!work.empty()) {
    Task task = work.back();
    work.pop_back();
    Aabb box, centres;
    for (uint32_t i = task.begin; i < task.end; ++i) {
      box.extend(boxes[order[i]]);
      centres.extend(centroids[order[i]]);
    }
    nodes_[task.node].box = box;
    if (task.end - task.begin <= kLeafSize) {
      nodes_[task.node].first = task.begin;
      nodes_[task.node].count = task.end - task.begin;
      continue;
    }
    // Median split on the axis where the centroids spread the most.
    glm::dvec3 extent = centres.hi - centres.lo;
    int axis = extent.x >= extent.y && extent.x >= extent.z ? 0 : extent.y >= extent.z ? 1 : 2;
    uint32_t middle = task.begin + (task.end - task.begin) / 2;
    std::nth_element(order.begin() + task.begin, order.begin() + middle, order.begin() + task.end,
                     [&](uint32_t a, uint32_t b) { return centroids[a][axis] < centroids[b][axis]; });
    uint32_t children = uint32_t(nodes_.size());
    nodes_[task.node].first = children;
    nodes_[task.node].count = 0;
    nodes_.push_back({});
    nodes_.push_back({});
    work.push_back({children + 1, middle, task.end});
    work.push_back({children, task.begin, middle});
  }

  // Triangles in leaf order, so a leaf reads a contiguous run.
  std::vector<TriangleData> sorted(count);
  corners_.resize(count);
  for (uint32_t i = 0; i < count; ++i) {
    sorted[i] = data_[order[i]];
    corners_[i] = {{sorted[i].v[0], sorted[i].v[1], sorted[i].v[2]}, sorted[i].singleSided};
  }
  data_ = std::move(sorted);
}

namespace {

/// The ray's parameter interval inside the box, clipped to [tMin, tMax];
/// false when empty. Axes the ray runs parallel to are tested by the origin,
/// which avoids 0 * inf.
bool slabs(const Aabb& box, const glm::dvec3& origin, const glm::dvec3& direction, const glm::dvec3& inverse,
           double tMin, double tMax, double& entry) {
  for (int a = 0; a < 3; ++a) {
    if (direction[a] == 0.0) {
      if (origin[a] < box.lo[a] || origin[a] > box.hi[a]) return false;
      continue;
    }
    double t0 = (box.lo[a] - origin[a]) * inverse[a], t1 = (box.hi[a] - origin[a]) * inverse[a];
    if (t0 > t1) std::swap(t0, t1);
    tMin = std::max(tMin, t0);
    tMax = std::min(tMax, t1);
    if (tMin > tMax) return false;
  }
  entry = tMin;
  return true;
}

}  // namespace

Hit PreparedScene::intersect(const glm::dvec3& origin, const glm::dvec3& direction, double tMin,
                             uint32_t excluded) const {
  Hit best;
  if (corners_.empty()) return best;
  const glm::dvec3 inverse = 1.0 / direction;
  // Watertight ray/triangle test (Woop, Benthin and Wald 2013) in double: the
  // ray's dominant axis becomes z, the triangle is sheared into the ray's
  // frame, and three edge functions decide. A shared edge's function is the
  // same expression of the same two vertices in both of its triangles, so a
  // ray through the edge is inside one of them whatever the rounding (the
  // first, Möller-Trumbore version let rays aimed at shared edges slip through).
  int kz = 0;
  for (int a = 1; a < 3; ++a) {
    if (std::abs(direction[a]) > std::abs(direction[kz])) kz = a;
  }
  int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
  if (direction[kz] < 0.0) std::swap(kx, ky);  // keeps the winding, so the edge functions' signs mean the same
  const double sx = direction[kx] / direction[kz], sy = direction[ky] / direction[kz], sz = 1.0 / direction[kz];
  double entry = 0.0;
  if (!slabs(nodes_[0].box, origin, direction, inverse, tMin, kInfinity, entry)) return best;
  struct Entry {
    uint32_t node;
    double t;
  };
  Entry stack[128];
  int top = 0;
  stack[top++] = {0, entry};
  while (top > 0) {
    Entry e = stack[--top];
    if (e.t > best.t) continue;
    const BvhNode& node = nodes_[e.node];
    if (node.count > 0) {
      for (uint32_t i = node.first; i < node.first + node.count; ++i) {
        if (i == excluded) continue;
        const Corners& tri = corners_[i];
        const glm::dvec3 a = tri.v[0] - origin, b = tri.v[1] - origin, c = tri.v[2] - origin;
        const double ax = a[kx] - sx * a[kz], ay = a[ky] - sy * a[kz];
        const double bx = b[kx] - sx * b[kz], by = b[ky] - sy * b[kz];
        const double cx = c[kx] - sx * c[kz], cy = c[ky] - sy * c[kz];
        const double u = cx * by - cy * bx, v = ax * cy - ay * cx, w = bx * ay - by * ax;
        if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) continue;
        const double det = u + v + w;
        // det > 0: the ray meets the triangle's front (counter-clockwise seen from the ray's origin).
        if (det == 0.0 || (tri.singleSided && det < 0.0)) continue;
        const double t = (u * sz * a[kz] + v * sz * b[kz] + w * sz * c[kz]) / det;
        if (!(t > tMin)) continue;
        const double b1 = v / det, b2 = w / det;
        if (t < best.t || (t == best.t && i < best.triangle)) best = {t, i, b1, b2};
      }
      continue;
    }
    double t0 = 0.0, t1 = 0.0;
    bool hit0 = slabs(nodes_[node.first].box, origin, direction, inverse, tMin, best.t, t0);
    bool hit1 = slabs(nodes_[node.first + 1].box, origin, direction, inverse, tMin, best.t, t1);
    // Nearer child on top of the stack. The depth of a median-split tree is
    // log2 of the triangle count, far below the stack's size.
    if (hit0 && hit1) {
      if (t0 <= t1) {
        stack[top++] = {node.first + 1, t1};
        stack[top++] = {node.first, t0};
      } else {
        stack[top++] = {node.first, t0};
        stack[top++] = {node.first + 1, t1};
      }
    } else if (hit0) {
      stack[top++] = {node.first, t0};
    } else if (hit1) {
      stack[top++] = {node.first + 1, t1};
    }
  }
  return best;
}

}  // namespace snell::ref::detail
