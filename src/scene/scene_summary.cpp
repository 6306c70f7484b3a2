// Scene counts and the per-frame GPU memory estimate behind `snell info`.
#include "scene/scene_summary.h"

#include "scene/subdivision.h"
#include "scene/texture_mips.h"
#include "shared/bvh.h"

#include <algorithm>
#include <cstdio>
#include <functional>
#include <sstream>

namespace snell::scene {

namespace {

// What each element takes on the GPU, for a figure before anything is
// uploaded; Renderer::memoryBytes() measures the real one once it is.
constexpr uint64_t kRestBytesPerVertex = 24 + 16;    // position + normal, two UV sets (one vec4)
constexpr uint64_t kIndexBytesPerTriangle = 12;
constexpr uint64_t kMorphBytesPerVertexTarget = 24;  // position + normal delta
constexpr uint64_t kSkinBytesPerVertex = 32;         // 4 joints (u32) + 4 weights
constexpr uint64_t kDeformedBytesPerVertex = 24;     // deformed position + normal
// The default trees' n - 1 nodes (a leaf is a child reference), each with its
// children's exact boxes and its 4-wide record (shared/bvh.h).
constexpr uint64_t kBvhBytesPerTriangle = sizeof(gpu::BvhNode) + gpu::kBvhChildBoxBytes + 4 * sizeof(gpu::BvhWideEntry);
// rgba16f trace and composite, depth, the transmissive mask, the masked trace's pixel list
constexpr uint64_t kTraceBytesPerPixel = 8 + 8 + 4 + 4 + 4;

/// Calls `visit(node, instanceCount)` for every node under the scene's roots.
void forEachNode(const Scene& scene, const std::function<void(const Node&, size_t)>& visit) {
  std::vector<int> stack(scene.roots.rbegin(), scene.roots.rend());
  while (!stack.empty()) {
    const Node& node = scene.nodes[size_t(stack.back())];
    stack.pop_back();
    visit(node, node.instances.empty() ? 1 : node.instances.size());
    stack.insert(stack.end(), node.children.rbegin(), node.children.rend());
  }
}

}  // namespace

SceneSummary summarize(const Scene& scene, uint32_t width, uint32_t height) {
  SceneSummary s;
  s.shapes = scene.shapes.size();
  for (const Shape& shape : scene.shapes) {
    // A part (Shape::vertexSource) brings triangles only: its vertices, refinement and deformation are its source's.
    s.geometryBytes += (shape.part() ? 0 : shape.vertexCount() * kRestBytesPerVertex) +
                       shape.triangleCount() * kIndexBytesPerTriangle;
    if (shape.part()) continue;
    s.deformBytes += shape.vertexCount() * shape.targets.size() * kMorphBytesPerVertexTarget;
    if (shape.skinned()) s.deformBytes += shape.vertexCount() * kSkinBytesPerVertex;
    s.morphedShapes += shape.morphed();
    s.skinnedShapes += shape.skinned();
    if (shape.refinement) {
      ++s.subdividedShapes;
      // The tables, the cage and its refined vertices.
      s.refineBytes += shape.refinement->bytes() + 12ull * (shape.cageVertices + shape.refinement->refinedVertices);
    }
  }
  forEachNode(scene, [&](const Node& node, size_t copies) {
    ++s.nodes;
    if (node.mesh < 0) return;
    for (int index : scene.meshes[size_t(node.mesh)].shapes) {
      const Shape& shape = scene.shapes[size_t(index)];
      s.instances += copies;
      s.triangles += shape.triangleCount() * copies;
      s.vertices += shape.part() ? 0 : shape.vertexCount() * copies;
      // One BVH per shape; deformed shapes get their own deformed copy and tree per instance.
      bool deforms = shape.morphed() || (shape.skinned() && node.skin >= 0);
      s.bvhBytes += shape.triangleCount() * kBvhBytesPerTriangle * (deforms ? copies : 1);
      if (deforms) s.deformBytes += shape.vertexCount() * kDeformedBytesPerVertex * copies;
    }
  });
  for (const Material& m : scene.materials) s.refractiveMaterials += m.refractive();
  s.textureBytes = textureChainBytes(scene);
  s.imageBytes = uint64_t(width) * height * kTraceBytesPerPixel;
  return s;
}

std::string describe(const Scene& scene, uint32_t width, uint32_t height) {
  SceneSummary s = summarize(scene, width, height);
  std::ostringstream out;
  out << scene.source << "\n";
  out << "  nodes " << s.nodes << " (of " << scene.nodes.size() << "), shapes " << s.shapes << ", instances " << s.instances
      << "\n  triangles " << s.triangles << ", vertices " << s.vertices << " (drawn, all instances)\n";
  out << "  morphed shapes " << s.morphedShapes << ", skinned shapes " << s.skinnedShapes << ", skins " << scene.skins.size()
      << ", textures " << scene.textures.size() << "\n";
  if (!scene.textures.empty()) {
    uint64_t decoded = 0;
    const Texture* largest = &scene.textures[0];
    for (const Texture& t : scene.textures) {
      decoded += t.rgba.size();
      if (uint64_t(t.width) * t.height > uint64_t(largest->width) * largest->height) largest = &t;
    }
    const std::vector<bool> drawn = drawnTextures(scene);
    const size_t undrawn = size_t(std::count(drawn.begin(), drawn.end(), false));
    out << "  texture memory " << mebibytes(decoded) << " decoded (RGBA8), " << mebibytes(s.textureBytes)
        << " on the GPU with mips; largest " << (largest->name.empty() ? "(unnamed)" : "'" + largest->name + "'") << " "
        << largest->width << "x" << largest->height;
    if (undrawn) out << "; " << undrawn << " not uploaded (occlusion or metallic-roughness maps: not drawn)";
    out << "\n";
  }
  if (s.subdividedShapes) {
    out << "  subdivision surfaces " << s.subdividedShapes << " (refined on the GPU when their cage moves)\n";
    for (size_t i = 0; i < scene.shapes.size(); ++i) {
      const Shape& shape = scene.shapes[i];
      if (!shape.refinement || shape.part()) continue;
      const Refinement& r = *shape.refinement;
      size_t triangles = 0;  // every material's: the shape's and its parts'
      for (const Shape& s : scene.shapes) triangles += &s == &shape || s.vertexSource == int(i) ? s.triangleCount() : 0;
      out << "    " << (shape.name.empty() ? "(unnamed)" : "'" + shape.name + "'") << ": " << schemeName(r.scheme)
          << " level " << r.level << ", cage " << r.cageVertices << " vertices and " << r.cageFaces << " faces -> "
          << shape.vertexCount() << " vertices and " << triangles << " triangles"
          << (r.limitSurface ? ", on the limit surface" : "")
          << (r.normals == SubdivisionNormals::Limit ? ", limit normals" : ", mesh normals") << ", tables "
          << mebibytes(r.bytes()) << "\n";
    }
  }
  out << "  materials " << scene.materials.size() << ", refractive " << s.refractiveMaterials << "\n";
  for (size_t m = 0; m < scene.materials.size(); ++m) {
    const Material& material = scene.materials[m];
    if (!material.refractive()) continue;
    out << "    [" << m << "] " << (material.name.empty() ? "(unnamed)" : material.name) << ": transmission "
        << material.transmission << ", ior " << material.ior;
    if (material.attenuates()) {
      out << ", volume: attenuation colour " << material.attenuationColor.r << "," << material.attenuationColor.g << ","
          << material.attenuationColor.b << " over " << material.attenuationDistance << ", thickness " << material.thickness;
    } else if (material.thickness > 0.0f) {
      out << ", volume (clear), thickness " << material.thickness;
    } else {
      out << ", thin-walled";
    }
    if (material.dispersion > 0.0f) {
      out << ", dispersion " << material.dispersion << " (Abbe number " << 20.0f / material.dispersion << ")";
    }
    if (material.iorTexture.present()) {
      out << ", IOR texture " << material.iorTexture.texture << " (ior + " << material.iorOffset << " + "
          << material.iorScale << " x red)";
    }
    if (material.priority != 0) out << ", priority " << material.priority;
    out << ", roughness " << material.roughness;
    out << "\n";
  }
  out << "  lights " << scene.lights.size() << (scene.lights.empty() ? " (a headlight will be used)" : "") << "\n";
  const char* types[] = {"directional", "point", "spot"};
  for (const Light& light : scene.lights) {
    out << "    " << types[int(light.type)] << (light.name.empty() ? "" : " '" + light.name + "'") << ", intensity "
        << light.intensity << "\n";
  }
  out << "  cameras " << scene.cameras.size() << "\n";
  for (const Camera& camera : scene.cameras) {
    out << "    " << (camera.orthographic ? "orthographic" : "perspective") << (camera.name.empty() ? "" : " '" + camera.name + "'");
    if (!camera.orthographic) out << ", yfov " << camera.yfov;
    out << "\n";
  }
  out << "  animations " << scene.animations.size() << "\n";
  for (const Animation& a : scene.animations) {
    out << "    '" << a.name << "': " << a.duration << " s, " << a.channels.size() << " channels\n";
  }
  out << "  GPU memory per frame at " << width << "x" << height << " (estimate): " << mebibytes(s.totalBytes())
      << " = geometry " << mebibytes(s.geometryBytes) << " + deformation " << mebibytes(s.deformBytes)
      << (s.refineBytes ? " + subdivision " + mebibytes(s.refineBytes) : std::string()) << " + BVH "
      << mebibytes(s.bvhBytes) << " + textures " << mebibytes(s.textureBytes) << " + images " << mebibytes(s.imageBytes)
      << "\n";
  for (const std::string& w : scene.warnings) out << "  note: " << w << "\n";
  return out.str();
}

}  // namespace snell::scene
