// The reference tracer: world-space triangles in double, a median-split BVH,
// and the refraction and shading rules of shaders/shared/trace.h, one
// std::thread per share of the rows.
#include "ref/reference_tracer.h"

#include "ref/sah_bvh.h"
#include "scene/texture_mips.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>

namespace snell::ref {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kInfinity = std::numeric_limits<double>::infinity();
// A secondary ray starts on the face it leaves; besides that face (excluded
// by id), it ignores hits closer than this fraction of the larger of its
// origin's magnitude and the scene's size, which is far above double
// rounding of the hit point (~1e-16 relative) and far below any feature.
constexpr double kSecondaryEpsilon = 1e-9;
constexpr uint32_t kLeafSize = 4;

// The contract's constants are floats; the reference uses exactly those values.
constexpr double kAmbient = double(gpu::kAmbient);
constexpr double kSpecular = double(gpu::kSpecular);
constexpr double kShininess = double(gpu::kShininess);
constexpr double kHeadlight = double(gpu::kHeadlight);

double maxAbs(const glm::dvec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }

bool finite(const glm::dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

/// The unit vector along v, or zero when v has no usable length.
glm::dvec3 unitOrZero(const glm::dvec3& v) {
  double length = glm::length(v);
  return length > 0.0 && std::isfinite(length) ? v / length : glm::dvec3(0.0);
}

// ---------------------------------------------------------------------------
// Textures

/// One mip level decoded once (sRGB decode per texel, before filtering).
struct LinearLevel {
  int64_t width = 0, height = 0;
  std::vector<glm::dvec3> texels;  // linear RGB; row 0 is the image's first row
  std::vector<glm::dvec3> data;    // the same texels as bytes / 255 (data textures: the IOR's)
};

/// A texture's mip chain (scene::mipChain, the GPU's rule) decoded.
struct LinearTexture {
  std::vector<LinearLevel> levels;  // empty: unusable, sampled as white
  uint32_t wrapS = gpu::kWrapRepeat, wrapT = gpu::kWrapRepeat;
  bool nearest = false;
};

uint32_t wrapMode(bool repeat, bool mirror) {
  if (mirror) return gpu::kWrapMirror;
  return repeat ? gpu::kWrapRepeat : gpu::kWrapClamp;
}

LinearTexture decode(const scene::Texture& t, bool colour) {
  LinearTexture out;
  double table[256];
  for (int v = 0; v < 256; ++v) table[v] = scene::srgbToLinear(uint8_t(v));
  for (const scene::MipLevel& level : scene::mipChain(t, colour)) {
    LinearLevel l;
    l.width = level.width;
    l.height = level.height;
    const size_t count = size_t(level.width) * level.height;
    l.texels.resize(count);
    l.data.resize(count);
    for (size_t i = 0; i < count; ++i) {
      const uint8_t* rgba = &level.rgba[i * 4];
      l.texels[i] = {table[rgba[0]], table[rgba[1]], table[rgba[2]]};
      l.data[i] = glm::dvec3(rgba[0], rgba[1], rgba[2]) / 255.0;
    }
    out.levels.push_back(std::move(l));
  }
  out.wrapS = wrapMode(t.repeatS, t.mirrorS);
  out.wrapT = wrapMode(t.repeatT, t.mirrorT);
  out.nearest = !t.linearFilter;
  return out;
}

int64_t wrapIndex(int64_t i, int64_t n, uint32_t mode) {
  if (mode == gpu::kWrapClamp) return std::clamp<int64_t>(i, 0, n - 1);
  if (mode == gpu::kWrapMirror) {
    int64_t m = ((i % (2 * n)) + 2 * n) % (2 * n);
    return m < n ? m : 2 * n - 1 - m;
  }
  return ((i % n) + n) % n;
}

/// floor(x) as an integer; NaN and huge values are kept in a range where the
/// conversion is defined (they only arise from broken texture coordinates).
int64_t floorIndex(double x) {
  if (!(x == x)) return 0;
  return int64_t(std::floor(std::clamp(x, -1e15, 1e15)));
}

glm::dvec3 bilinear(const LinearTexture& t, size_t level, const glm::dvec2& uv, bool srgb) {
  const LinearLevel& l = t.levels[level];
  const std::vector<glm::dvec3>& texels = srgb ? l.texels : l.data;
  auto texel = [&](int64_t x, int64_t y) {
    return texels[size_t(wrapIndex(y, l.height, t.wrapT) * l.width + wrapIndex(x, l.width, t.wrapS))];
  };
  double x = uv.x * double(l.width) - 0.5, y = uv.y * double(l.height) - 0.5;
  int64_t x0 = floorIndex(x), y0 = floorIndex(y);
  double fx = std::clamp(x - double(x0), 0.0, 1.0), fy = std::clamp(y - double(y0), 0.0, 1.0);
  glm::dvec3 top = glm::mix(texel(x0, y0), texel(x0 + 1, y0), fx);
  glm::dvec3 bottom = glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), fx);
  return glm::mix(top, bottom, fy);
}

/// The texture at uv and level of detail `lod` (trace.h: Textures).
glm::dvec3 sample(const LinearTexture& t, const glm::dvec2& uv, bool srgb, double lod) {
  if (t.nearest) {
    const LinearLevel& l = t.levels[0];
    const std::vector<glm::dvec3>& texels = srgb ? l.texels : l.data;
    int64_t x = wrapIndex(floorIndex(uv.x * double(l.width)), l.width, t.wrapS);
    int64_t y = wrapIndex(floorIndex(uv.y * double(l.height)), l.height, t.wrapT);
    return texels[size_t(y * l.width + x)];
  }
  if (!(lod > 0.0)) lod = 0.0;  // magnified, no footprint, or not finite: level 0
  lod = std::min(lod, double(t.levels.size() - 1));
  const size_t level = size_t(lod);
  const double f = lod - double(level);
  glm::dvec3 c = bilinear(t, level, uv, srgb);
  if (f > 0.0) c = glm::mix(c, bilinear(t, level + 1, uv, srgb), f);
  return c;
}

// ---------------------------------------------------------------------------
// Materials and lights

struct TextureUse {
  const LinearTexture* texture = nullptr;  // null: white
  int texCoord = 0;
  glm::dmat3 transform{1.0};
  double lodOffset = 0.0;  // scene::textureLodOffset
};

struct ResolvedMaterial {
  glm::dvec3 baseFactor{1.0};
  glm::dvec3 emissiveFactor{0.0};
  TextureUse base, emissive, ior;
  bool refractive = false;
  double baseIor = 1.5;
  double iorScale = 1.0, iorOffset = 0.0;
  double roughness = 1.0;
  double dispersion = 0.0;
  double priority = 0.0;
  glm::dvec3 attenuationColor{1.0};
  double attenuationDistance = 0.0;  // 0: no volume
};

struct ResolvedLight {
  scene::LightType type = scene::LightType::Directional;
  glm::dvec3 position{0.0};
  glm::dvec3 direction{0.0, 0.0, -1.0};  // the way it shines, unit
  glm::dvec3 radiance{0.0};              // colour * intensity
  double range = kInfinity;
  double cosInner = 1.0, cosOuter = 0.0;
};

// ---------------------------------------------------------------------------
// Geometry

/// What shading needs of a triangle; intersection reads the compact Corners.
struct TriangleData {
  glm::dvec3 v[3];
  glm::dvec3 n[3];   // world, unit, or zero where the shape has none
  glm::dvec2 uv[2][3];  // TEXCOORD_0 and _1, (0, 0) where missing
  glm::dvec3 ng;     // unit geometric normal
  double density[2] = {0.0, 0.0};  // 0.5 log2(UV area / world area) per UV set (trace.h: Textures)
  double curvature = 0.0;          // the largest turn of the unit vertex normals per unit of edge
  int32_t item = -1, primitive = -1;
  int material = -1;
};

// The corners exactly as every triangle sharing them sees them: the
// watertight test needs a shared vertex to be bit-for-bit the same in each.
struct Corners {
  glm::dvec3 v[3];
};

struct BvhNode {
  Aabb box;
  uint32_t first = 0;  // leaf: first triangle; internal: first of two adjacent children
  uint32_t count = 0;  // triangles in a leaf; 0 for an internal node
};

struct Hit {
  double t = kInfinity;
  uint32_t triangle = std::numeric_limits<uint32_t>::max();
  double b1 = 0.0, b2 = 0.0;
  bool found() const { return triangle != std::numeric_limits<uint32_t>::max(); }
};

class PreparedScene {
 public:
  PreparedScene(const scene::Scene& scene, const scene::Pose& pose, const scene::View& view);

  /// The closest triangle with tMin < t, other than `excluded`. Equal
  /// distances go to the triangle stored first, so that the answer does not
  /// depend on the traversal order (nor on the thread count).
  Hit intersect(const glm::dvec3& origin, const glm::dvec3& direction, double tMin, uint32_t excluded) const;

  const TriangleData& triangle(uint32_t i) const { return data_[i]; }
  const ResolvedMaterial& material(int index) const {
    return index >= 0 && size_t(index) < materials_.size() ? materials_[size_t(index)] : defaultMaterial_;
  }
  int materialCount() const { return int(materials_.size()); }
  const std::vector<ResolvedLight>& lights() const { return lights_; }
  double size() const { return size_; }

 private:
  void addItem(const scene::Scene& scene, const scene::DrawItem& item, int32_t itemIndex);
  void buildBvh();

  std::vector<TriangleData> data_;
  std::vector<Corners> corners_;
  std::vector<BvhNode> nodes_;
  std::vector<LinearTexture> textures_;
  std::vector<ResolvedMaterial> materials_;
  ResolvedMaterial defaultMaterial_;  // white, opaque
  std::vector<ResolvedLight> lights_;
  double size_ = 0.0;  // the largest extent of the geometry's bounds
};

PreparedScene::PreparedScene(const scene::Scene& scene, const scene::Pose& pose, const scene::View& view) {
  textures_.reserve(scene.textures.size());
  // Only drawn textures get their mip chains (normal maps and the like are never sampled).
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
    r.emissiveFactor = glm::dvec3(m.emissiveFactor);
    r.base = use(m.baseColorTexture);
    r.emissive = use(m.emissiveTexture);
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

  for (size_t t = 0; t < shape.triangleCount(); ++t) {
    const uint32_t* index = &shape.indices[t * 3];
    if (index[0] >= vertices || index[1] >= vertices || index[2] >= vertices) continue;
    TriangleData d;
    for (int k = 0; k < 3; ++k) {
      d.v[k] = positions[index[k]];
      d.n[k] = normals[index[k]];
      d.uv[0][k] = texcoords(shape.texcoords0, index[k]);
      d.uv[1][k] = texcoords(shape.texcoords1, index[k]);
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
      double k = 0.0;
      for (int a = 0; a < 3; ++a) {
        int b = (a + 1) % 3;
        k = std::max(k, glm::length(d.n[b] - d.n[a]) / glm::length(d.v[b] - d.v[a]));
      }
      d.curvature = k < 1e30 ? k : 0.0;  // NaN and infinity: 0
    }
    d.item = itemIndex;
    d.primitive = int32_t(t);
    d.material = shape.material;
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
    corners_[i] = {{sorted[i].v[0], sorted[i].v[1], sorted[i].v[2]}};
  }
  data_ = std::move(sorted);
}

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
        if (det == 0.0) continue;
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

// ---------------------------------------------------------------------------
// Tracing

/// Where a ray meets a face: its hit weights and the level of detail per UV
/// set that a texture of lodOffset 0 is read at there.
struct SurfacePoint {
  double b0, b1, b2;
  glm::dvec2 lods;
};

/// The cone's level of detail terms on `tri` (trace.h: Textures).
glm::dvec2 coneLods(const TriangleData& tri, double width, const glm::dvec3& d) {
  const double footprint = std::log2(width) - std::log2(std::abs(glm::dot(d, tri.ng)));
  return {tri.density[0] + footprint, tri.density[1] + footprint};
}

/// The UV `use` reads at `at`: its set's UV through its KHR_texture_transform.
glm::dvec2 textureUv(const TextureUse& use, const TriangleData& tri, const SurfacePoint& at) {
  glm::dvec2 uv(0.0);
  if (use.texCoord == 0 || use.texCoord == 1) {
    const glm::dvec2* set = tri.uv[use.texCoord];
    uv = at.b0 * set[0] + at.b1 * set[1] + at.b2 * set[2];
  }
  return glm::dvec2(use.transform * glm::dvec3(uv, 1.0));
}

glm::dvec3 textureColor(const TextureUse& use, const TriangleData& tri, const SurfacePoint& at, bool srgb = true) {
  if (!use.texture) return glm::dvec3(1.0);
  const double lod = (use.texCoord == 1 ? at.lods.y : at.lods.x) + use.lodOffset;
  return sample(*use.texture, textureUv(use, tri, at), srgb, lod);
}

/// Light `light` as seen from p: the unit direction towards it and its
/// irradiance; false where it has no direction (a light on the point).
bool lightAt(const ResolvedLight& light, const glm::dvec3& p, glm::dvec3& l, glm::dvec3& e) {
  if (light.type == scene::LightType::Directional) {
    l = -light.direction;
    e = light.radiance;
    return true;
  }
  glm::dvec3 toLight = light.position - p;
  double distance = glm::length(toLight);
  if (!(distance > 0.0)) return false;
  l = toLight / distance;
  double window = 1.0;
  if (std::isfinite(light.range)) {
    double ratio = distance / light.range;
    window = std::clamp(1.0 - ratio * ratio * ratio * ratio, 0.0, 1.0);
    window *= window;
  }
  e = light.radiance / (distance * distance) * window;
  if (light.type == scene::LightType::Spot) {
    double s = std::clamp((glm::dot(light.direction, -l) - light.cosOuter) / std::max(1e-4, light.cosInner - light.cosOuter),
                          0.0, 1.0);
    e *= s * s;
  }
  return true;
}

glm::dvec3 shadeOpaque(const PreparedScene& prepared, const glm::dvec3& p, const glm::dvec3& shadingNormal,
                       const glm::dvec3& d, const glm::dvec3& base, const glm::dvec3& emissive) {
  const glm::dvec3 v = -d;
  const glm::dvec3 n = glm::dot(shadingNormal, v) < 0.0 ? -shadingNormal : shadingNormal;
  glm::dvec3 sum(0.0);
  for (const ResolvedLight& light : prepared.lights()) {
    glm::dvec3 l, e;
    if (!lightAt(light, p, l, e)) continue;
    double nDotL = glm::dot(n, l);
    // Also covers l = -v, where H would be undefined (n faces v, so n.l <= 0).
    if (!(nDotL > 0.0)) continue;
    glm::dvec3 h = glm::normalize(l + v);
    double specular = kSpecular * std::pow(std::max(glm::dot(n, h), 0.0), kShininess);
    sum += e * nDotL * (base / kPi + specular);
  }
  return emissive + kAmbient * base + sum;
}

struct PixelResult {
  glm::dvec3 color{0.0};
  double distance = kInfinity;
  int32_t instance = -1, primitive = -1;
  uint32_t interfaces = 0;
  uint32_t outcome = gpu::kOutcomeMiss;
  double energyError = 0.0;
  glm::dvec2 landing{std::numeric_limits<double>::quiet_NaN()};
};

// ---------------------------------------------------------------------------
// Optics: Fresnel, media, highlights, the environment

/// Unpolarised dielectric reflectance for cosine c > 0 and eta = n1 / n2; 1 past the critical angle.
double fresnelReflectance(double eta, double c) {
  double k = 1.0 - eta * eta * (1.0 - c * c);
  if (k < 0.0) return 1.0;
  double ct = std::sqrt(k);
  double rs = (eta * c - ct) / (eta * c + ct), rp = (eta * ct - c) / (eta * ct + c);
  return 0.5 * (rs * rs + rp * rp);
}

/// The transmittance from the transmission amplitudes ts, tp (Born & Wolf),
/// written apart from 1 - R so that R + T = 1 is a check, not an identity.
double fresnelTransmittance(double eta, double c) {
  double k = 1.0 - eta * eta * (1.0 - c * c);
  if (k < 0.0) return 0.0;
  double ct = std::sqrt(k);
  double ts = 2.0 * eta * c / (eta * c + ct), tp = 2.0 * eta * c / (eta * ct + c);
  return (ct / (eta * c)) * 0.5 * (ts * ts + tp * tp);
}

double channelIor(double ior, double dispersion, int channel) {
  if (channel < 0 || channel == 1 || dispersion <= 0.0) return ior;
  double spread = 0.025 * dispersion * (ior - 1.0);
  return channel == 0 ? ior - spread : ior + spread;
}

/// The media a ray is inside (shared/trace.h: nested dielectrics).
struct Media {
  int material[gpu::kMaxMedia] = {};
  uint32_t count = 0;

  int current(const PreparedScene& prepared) const {
    int best = -1;
    for (uint32_t i = 0; i < count; ++i) {
      if (best < 0 || prepared.material(material[i]).priority >= prepared.material(material[best]).priority) best = int(i);
    }
    return best;
  }
  void enter(int m) {
    if (count == gpu::kMaxMedia) {
      for (uint32_t i = 1; i < gpu::kMaxMedia; ++i) material[i - 1] = material[i];
      --count;
    }
    material[count++] = m;
  }
  int leave(int m) {
    int at = -1;
    for (uint32_t i = 0; i < count; ++i) {
      if (material[i] == m) at = int(i);
    }
    if (at < 0) return -1;
    for (uint32_t i = uint32_t(at) + 1; i < count; ++i) material[i - 1] = material[i];
    --count;
    return at;
  }
};

glm::dvec3 studioGradient(const glm::dvec3& d) {
  const glm::dvec3 ground(gpu::kStudioGround[0], gpu::kStudioGround[1], gpu::kStudioGround[2]);
  const glm::dvec3 horizon(gpu::kStudioHorizon[0], gpu::kStudioHorizon[1], gpu::kStudioHorizon[2]);
  const glm::dvec3 zenith(gpu::kStudioZenith[0], gpu::kStudioZenith[1], gpu::kStudioZenith[2]);
  return d.y >= 0.0 ? glm::mix(horizon, zenith, d.y) : glm::mix(horizon, ground, std::min(1.0, -4.0 * d.y));
}

glm::dvec3 environmentColor(const scene::Optics& optics, const glm::dvec3& d) {
  if (!optics.environment) return studioGradient(d);
  const scene::Environment& env = *optics.environment;
  const int64_t w = env.width, h = env.height;
  double u = 0.5 + std::atan2(d.x, -d.z) / (2.0 * kPi), v = std::acos(std::clamp(d.y, -1.0, 1.0)) / kPi;
  double x = u * double(w) - 0.5, y = v * double(h) - 0.5;
  int64_t x0 = floorIndex(x), y0 = floorIndex(y);
  double fx = x - double(x0), fy = y - double(y0);
  auto texel = [&](int64_t tx, int64_t ty) {
    tx = ((tx % w) + w) % w;
    ty = std::clamp<int64_t>(ty, 0, h - 1);
    return glm::dvec3(env.texels[size_t(ty * w + tx)]);
  };
  glm::dvec3 top = glm::mix(texel(x0, y0), texel(x0 + 1, y0), fx);
  glm::dvec3 bottom = glm::mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), fx);
  return glm::mix(top, bottom, fy);
}

/// Every light's GGX highlight on a boundary of normal n (the viewer's side).
glm::dvec3 highlight(const PreparedScene& prepared, const glm::dvec3& p, const glm::dvec3& n, const glm::dvec3& d,
                     double roughness, double eta) {
  const glm::dvec3 v = -d;
  const double a = std::max(roughness * roughness, double(gpu::kMinAlpha)), a2 = a * a;
  const double nv = std::max(glm::dot(n, v), 1e-4);
  glm::dvec3 sum(0.0);
  for (const ResolvedLight& light : prepared.lights()) {
    glm::dvec3 l, e;
    if (!lightAt(light, p, l, e) || !(glm::dot(n, l) > 0.0)) continue;
    glm::dvec3 h = glm::normalize(l + v);
    double nh = glm::dot(n, h), vh = glm::dot(v, h);
    if (!(nh > 0.0) || !(vh > 0.0)) continue;
    double dd = nh * nh * (a2 - 1.0) + 1.0;
    sum += e * (a2 / (kPi * dd * dd)) * fresnelReflectance(eta, vh) / (4.0 * nv);
  }
  return sum;
}

struct Tracer {
  const PreparedScene& prepared;
  const ReferenceSettings& settings;

  double tMinFrom(const glm::dvec3& origin) const {
    return kSecondaryEpsilon * std::max(maxAbs(origin), prepared.size());
  }

  double surfaceIor(const ResolvedMaterial& m, const TriangleData& tri, const SurfacePoint& at, int channel) const {
    double ior = m.baseIor;
    if (m.ior.texture) ior = std::max(1.0, ior + m.iorOffset + m.iorScale * textureColor(m.ior, tri, at, false).r);
    return channelIor(ior, m.dispersion, channel);
  }

  double mediumIor(int material, int channel) const {
    const ResolvedMaterial& m = prepared.material(material);
    return channelIor(m.baseIor, m.dispersion, channel);
  }

  /// The point a hit lands on and its shading normal, turned to the
  /// geometric normal's side (the geometric normal where the shading one is 0).
  static void surfaceAt(const TriangleData& tri, double b0, double b1, double b2, glm::dvec3& p, glm::dvec3& ns) {
    p = b0 * tri.v[0] + b1 * tri.v[1] + b2 * tri.v[2];
    ns = unitOrZero(b0 * tri.n[0] + b1 * tri.n[1] + b2 * tri.n[2]);
    if (ns == glm::dvec3(0.0)) ns = tri.ng;
    if (glm::dot(ns, tri.ng) < 0.0) ns = -ns;
  }

  /// Where a ray meets `tri`: its weights and level of detail terms (level 0 with Optics::textureLod off).
  SurfacePoint pointOf(const Hit& hit, const TriangleData& tri, double width, double spread, const glm::dvec3& d) const {
    SurfacePoint at{1.0 - hit.b1 - hit.b2, hit.b1, hit.b2, glm::dvec2(-kInfinity)};  // off: level 0
    if (settings.optics.textureLod) at.lods = coneLods(tri, width + spread * hit.t, d);
    return at;
  }

  /// What a reflected ray from p, its cone `width` wide there and opening by
  /// `spread`, sees: the opaque face it meets, else the environment.
  glm::dvec3 reflected(const glm::dvec3& p, const glm::dvec3& d, uint32_t from, double width, double spread) const {
    Hit hit = prepared.intersect(p, d, tMinFrom(p), from);
    if (hit.found()) {
      const TriangleData& tri = prepared.triangle(hit.triangle);
      const ResolvedMaterial& m = prepared.material(tri.material);
      if (!m.refractive) {
        const SurfacePoint at = pointOf(hit, tri, width, spread, d);
        glm::dvec3 q, ns;
        surfaceAt(tri, at.b0, at.b1, at.b2, q, ns);
        return shadeOpaque(prepared, q, ns, d, m.baseFactor * textureColor(m.base, tri, at),
                           m.emissiveFactor * textureColor(m.emissive, tri, at));
      }
    }
    return environmentColor(settings.optics, d);
  }

  /// One path for `channel` (0-2, or -1: every channel at the base IOR).
  /// With channel -1, returns false at the first dispersive boundary: the
  /// caller traces the pixel once per channel.
  /// The ray's cone (trace.h: Textures) is `width` wide at the origin and opens by `spread`.
  bool path(glm::dvec3 origin, glm::dvec3 d, double width, double spread, int channel, PixelResult& result) const {
    result = PixelResult{};
    const bool fresnel = settings.optics.fresnel;
    uint32_t reflections = fresnel ? settings.optics.reflections : 0u;
    glm::dvec3 throughput(1.0);
    Media media;
    double tMin = 0.0;  // primary rays: any t > 0
    uint32_t excluded = std::numeric_limits<uint32_t>::max();
    for (bool primary = true;; primary = false) {
      Hit hit = prepared.intersect(origin, d, tMin, excluded);
      if (!hit.found()) {
        result.color += throughput * settings.background;
        result.outcome = gpu::kOutcomeMiss;
        return true;
      }
      const int inside = media.current(prepared);
      if (inside >= 0 && settings.optics.volume) {  // Beer-Lambert over the segment
        const ResolvedMaterial& volume = prepared.material(media.material[inside]);
        if (volume.attenuationDistance > 0.0) {
          for (int c = 0; c < 3; ++c) throughput[c] *= std::pow(volume.attenuationColor[c], hit.t / volume.attenuationDistance);
        }
      }
      const TriangleData& tri = prepared.triangle(hit.triangle);
      if (primary) {
        result.distance = hit.t;
        result.instance = tri.item;
        result.primitive = tri.primitive;
      }
      const SurfacePoint here = pointOf(hit, tri, width, spread, d);
      width += spread * hit.t;  // the cone where it meets the face
      const glm::dvec3& ng = tri.ng;
      glm::dvec3 p, ns;
      surfaceAt(tri, here.b0, here.b1, here.b2, p, ns);

      const ResolvedMaterial& material = prepared.material(tri.material);
      const glm::dvec3 base = material.baseFactor * textureColor(material.base, tri, here);
      if (!material.refractive) {
        if (result.interfaces > 0 && material.base.texture) result.landing = textureUv(material.base, tri, here);
        const glm::dvec3 emissive = material.emissiveFactor * textureColor(material.emissive, tri, here);
        result.color += throughput * shadeOpaque(prepared, p, ns, d, base, emissive);
        result.outcome = gpu::kOutcomeOpaque;
        return true;
      }
      if (result.interfaces >= settings.maxInterfaces) {
        result.color += throughput * settings.background;  // ends as a miss
        result.outcome = gpu::kOutcomeInterfaceLimit;
        return true;
      }

      const bool entering = glm::dot(d, ng) < 0.0;
      bool boundary;  // a true boundary: the medium changes here
      double n1, n2;
      auto dispersive = [&](int other) {
        return settings.optics.dispersion &&
               (material.dispersion > 0.0 || (other >= 0 && prepared.material(media.material[other]).dispersion > 0.0));
      };
      if (entering) {
        boundary = inside < 0 || prepared.material(media.material[inside]).priority <= material.priority;
        if (boundary && channel < 0 && dispersive(inside)) return false;
        n1 = inside < 0 ? 1.0 : mediumIor(media.material[inside], channel);
        n2 = surfaceIor(material, tri, here, channel);
        media.enter(tri.material);
      } else {
        const int at = media.leave(tri.material);
        boundary = at < 0 || at == inside;
        const int outside = media.current(prepared);
        if (boundary && channel < 0 && dispersive(outside)) return false;
        n1 = surfaceIor(material, tri, here, channel);
        n2 = outside < 0 ? 1.0 : mediumIor(media.material[outside], channel);
      }
      const bool bends = boundary && result.interfaces < settings.maxBends;
      ++result.interfaces;
      if (bends) {
        glm::dvec3 n = entering ? ns : -ns;
        const double eta = n1 / n2;
        double c = -glm::dot(d, n);
        if (c <= 0.0) {
          n = entering ? ng : -ng;
          c = -glm::dot(d, n);
        }
        const double k = 1.0 - eta * eta * (1.0 - c * c);
        const double widening = tri.curvature * width;  // how far the normal turns across the cone
        glm::dvec3 next;
        if (k < 0.0) {
          next = d + 2.0 * c * n;  // total internal reflection keeps everything
          spread += 2.0 * widening;
        } else {
          const double r = fresnel ? fresnelReflectance(eta, c) : 0.0;
          if (fresnel) {
            result.energyError = std::max(result.energyError, std::abs(r + fresnelTransmittance(eta, c) - 1.0));
          }
          if (reflections > 0) {
            --reflections;
            if (r > 0.0) {
              result.color += throughput * (r * reflected(p, unitOrZero(d + 2.0 * c * n), hit.triangle, width,
                                                          spread + 2.0 * widening) +
                                            highlight(prepared, p, n, d, material.roughness, eta));
            }
          }
          next = eta * d + (eta * c - std::sqrt(k)) * n;
          spread = eta * spread + std::abs(1.0 - eta) * widening;
          throughput *= 1.0 - r;
        }
        next = unitOrZero(next);
        if (next != glm::dvec3(0.0)) d = next;
      }
      if (boundary) throughput *= base;

      origin = p;
      excluded = hit.triangle;
      tMin = tMinFrom(origin);
    }
  }
};

PixelResult trace(const PreparedScene& prepared, const glm::dvec3& origin, const glm::dvec3& d, double width,
                  double spread, const ReferenceSettings& settings) {
  const Tracer tracer{prepared, settings};
  PixelResult result;
  if (tracer.path(origin, d, width, spread, -1, result)) return result;
  PixelResult red, blue;
  tracer.path(origin, d, width, spread, 0, red);
  tracer.path(origin, d, width, spread, 1, result);
  tracer.path(origin, d, width, spread, 2, blue);
  result.color = {red.color.r, result.color.g, blue.color.b};
  result.energyError = std::max({red.energyError, result.energyError, blue.energyError});
  return result;
}

}  // namespace

ReferenceImage renderReference(const scene::Scene& scene, const scene::Pose& pose, const ReferenceSettings& settings) {
  ReferenceImage image;
  image.width = settings.width;
  image.height = settings.height;
  const size_t pixels = size_t(settings.width) * settings.height;
  image.color.assign(pixels, glm::dvec3(0.0));
  image.distance.assign(pixels, kInfinity);
  image.instance.assign(pixels, -1);
  image.primitive.assign(pixels, -1);
  image.interfaces.assign(pixels, 0);
  image.outcome.assign(pixels, gpu::kOutcomeMiss);
  image.energyError.assign(pixels, 0.0);
  image.landing.assign(pixels, glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
  if (pixels == 0) return image;
  if (!settings.rays.empty() && settings.rays.size() != pixels) {
    throw std::invalid_argument("reference: " + std::to_string(settings.rays.size()) + " rays for " +
                                std::to_string(pixels) + " pixels");
  }

  const PreparedScene prepared(scene, pose, settings.view);
  const scene::View& view = settings.view;
  const double w = settings.width, h = settings.height;
  const glm::dvec3 forward = glm::normalize(view.forward);

  std::atomic<uint32_t> nextRow{0};
  auto work = [&] {
    for (uint32_t y = nextRow++; y < settings.height; y = nextRow++) {
      for (uint32_t x = 0; x < settings.width; ++x) {
        double sx = (2.0 * (double(x) + 0.5) / w - 1.0) * view.halfHeight * w / h + view.shift.x;
        double sy = (1.0 - 2.0 * (double(y) + 0.5) / h) * view.halfHeight + view.shift.y;
        glm::dvec3 origin = view.eye, direction = forward;
        double width = 0.0, spread = 0.0;  // listed rays have no footprint: level 0
        if (!settings.rays.empty()) {
          origin = settings.rays[image.index(x, y)].origin;
          direction = glm::normalize(settings.rays[image.index(x, y)].direction);
        } else if (view.orthographic) {
          origin = view.eye + view.right * sx + view.up * sy;
          width = 2.0 * view.halfHeight / h;
        } else {
          direction = glm::normalize(view.forward + sx * view.right + sy * view.up);
          spread = std::atan(2.0 * view.halfHeight / h);
        }
        PixelResult r = trace(prepared, origin, direction, width, spread, settings);
        size_t i = image.index(x, y);
        image.color[i] = r.color;
        image.distance[i] = r.distance;
        image.instance[i] = r.instance;
        image.primitive[i] = r.primitive;
        image.interfaces[i] = r.interfaces;
        image.outcome[i] = r.outcome;
        image.energyError[i] = r.energyError;
        image.landing[i] = r.landing;
      }
    }
  };
  unsigned threads = settings.threads ? settings.threads : std::max(1u, std::thread::hardware_concurrency());
  threads = std::min<unsigned>(threads, settings.height);
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  return image;
}

}  // namespace snell::ref
