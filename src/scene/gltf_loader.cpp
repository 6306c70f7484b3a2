// glTF loading: tinygltf parses, this file checks and converts. tinygltf
// accepts many malformed files (see ../shared/assets/README.md), so every
// index, count and range is checked here before it is used.
#include "scene/gltf_loader.h"

#include "scene/gltf_accessors.h"
#include "scene/texture_mips.h"

#include <stb/stb_image.h>
#include <tiny_gltf.h>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <numeric>
#include <set>
#include <thread>

namespace snell::scene {

namespace {
// The largest image side snell decodes: the renderer's own cap on any image (render::checkImageSize).
constexpr int kMaxImageSide = 16384;
}  // namespace

using gltf::AccessorData;
using gltf::Reader;
using gltf::kMaxElements;
using gltf::label;
using gltf::readAccessor;
using gltf::readIndices;
using gltf::readScalars;
using gltf::readVectors;

namespace {

constexpr float kPi = 3.14159265358979f;

const std::vector<std::string> kSupported = {
    "KHR_materials_transmission", "KHR_materials_ior",      "KHR_materials_volume", "KHR_texture_transform",
    "KHR_lights_punctual",        "EXT_mesh_gpu_instancing", "KHR_mesh_quantization",
    "KHR_materials_dispersion",   "SNELL_materials_ior_texture", "SNELL_materials_priority",
};

// ---- textures and materials -------------------------------------------------

double number(const tinygltf::Value& object, const char* key, double fallback) {
  if (!object.IsObject() || !object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

/// KHR_texture_transform: offset, rotation, scale as one UV matrix.
glm::mat3 textureTransform(const tinygltf::ExtensionMap& extensions) {
  auto it = extensions.find("KHR_texture_transform");
  if (it == extensions.end()) return glm::mat3(1.0f);
  const tinygltf::Value& t = it->second;
  glm::vec2 offset(0.0f), scale(1.0f);
  if (t.Has("offset") && t.Get("offset").ArrayLen() == 2) {
    offset = {t.Get("offset").Get(0).GetNumberAsDouble(), t.Get("offset").Get(1).GetNumberAsDouble()};
  }
  if (t.Has("scale") && t.Get("scale").ArrayLen() == 2) {
    scale = {t.Get("scale").Get(0).GetNumberAsDouble(), t.Get("scale").Get(1).GetNumberAsDouble()};
  }
  return uvTransform(offset, static_cast<float>(number(t, "rotation", 0.0)), scale);
}

TextureRef textureRef(const Reader& r, int index, int texCoord, const tinygltf::ExtensionMap& extensions,
                      const std::string& what) {
  TextureRef ref;
  if (index < 0) return ref;
  r.at(r.model.textures, index, what, "texture");
  if (texCoord < 0) r.fail(what + " uses TEXCOORD_" + std::to_string(texCoord));
  if (texCoord > 1) {
    // As a glTF viewer does with a set it lacks: warn and go on with the first.
    r.warn(what + " uses TEXCOORD_" + std::to_string(texCoord) + "; snell reads sets 0 and 1, so it reads set 0");
    texCoord = 0;
  }
  ref.texture = index;
  ref.texCoord = texCoord;
  ref.transform = textureTransform(extensions);
  return ref;
}

/// A texture given inside an extension object ({"index": n, "texCoord": m}).
TextureRef extensionTexture(const Reader& r, const tinygltf::Value& object, const char* key, const std::string& what) {
  if (!object.IsObject() || !object.Has(key)) return {};
  const tinygltf::Value& info = object.Get(key);
  int index = static_cast<int>(number(info, "index", -1));
  int texCoord = static_cast<int>(number(info, "texCoord", 0));
  tinygltf::ExtensionMap extensions;
  if (info.Has("extensions") && info.Get("extensions").IsObject()) {
    const tinygltf::Value& e = info.Get("extensions");
    for (const std::string& k : e.Keys()) extensions[k] = e.Get(k);
  }
  return textureRef(r, index, texCoord, extensions, what);
}

void loadTextures(const Reader& r) {
  for (size_t t = 0; t < r.model.textures.size(); ++t) {
    const tinygltf::Texture& source = r.model.textures[t];
    Texture texture;
    texture.name = source.name;
    std::string what = label("texture", t, source.name);
    if (source.source >= 0) {
      const tinygltf::Image& image = r.at(r.model.images, source.source, what, "image");
      texture.name = texture.name.empty() ? image.uri : texture.name;
      bool decoded = !image.image.empty() && image.width > 0 && image.height > 0 && image.component > 0;
      if (decoded) {
        size_t pixels = size_t(image.width) * size_t(image.height);
        int channels = image.component;
        size_t bytesPerChannel = image.bits == 16 ? 2 : 1;
        if (pixels > kMaxElements || image.image.size() < pixels * size_t(channels) * bytesPerChannel) {
          r.fail(what + ": image data is shorter than its size says");
        }
        texture.width = static_cast<uint32_t>(image.width);
        texture.height = static_cast<uint32_t>(image.height);
        texture.rgba.resize(pixels * 4);
        for (size_t p = 0; p < pixels; ++p) {
          for (int c = 0; c < 4; ++c) {
            int from = channels == 1 ? 0 : channels == 2 ? (c < 3 ? 0 : 1) : c;
            uint8_t value = 255;
            if (c < channels || channels <= 2) {
              size_t at = (p * size_t(channels) + size_t(from)) * bytesPerChannel;
              value = bytesPerChannel == 2 ? image.image[at + 1] : image.image[at];  // high byte of little-endian 16-bit
              if (channels == 1 && c == 3) value = 255;
            }
            texture.rgba[p * 4 + size_t(c)] = value;
          }
        }
      } else if (image.width > kMaxImageSide || image.height > kMaxImageSide) {
        r.fail(what + ": image '" + image.uri + "' is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
               ", beyond snell's limit of " + std::to_string(kMaxImageSide) + " pixels a side");
      } else {
        r.warn(what + ": image '" + image.uri + "' could not be read; materials fall back to their factors");
      }
    }
    if (source.sampler >= 0) {
      const tinygltf::Sampler& sampler = r.at(r.model.samplers, source.sampler, what, "sampler");
      texture.repeatS = sampler.wrapS != TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
      texture.repeatT = sampler.wrapT != TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
      texture.mirrorS = sampler.wrapS == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT;
      texture.mirrorT = sampler.wrapT == TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT;
      texture.linearFilter = sampler.magFilter != TINYGLTF_TEXTURE_FILTER_NEAREST;
    }
    r.scene.textures.push_back(std::move(texture));
  }
}

void loadMaterials(const Reader& r) {
  for (size_t m = 0; m < r.model.materials.size(); ++m) {
    const tinygltf::Material& source = r.model.materials[m];
    std::string what = label("material", m, source.name);
    Material material;
    material.name = source.name;
    const auto& pbr = source.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() == 4) {
      material.baseColorFactor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2],
                                           pbr.baseColorFactor[3]);
    }
    material.baseColorTexture = textureRef(r, pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                                           pbr.baseColorTexture.extensions, what + " baseColorTexture");
    if (source.emissiveFactor.size() == 3) {
      material.emissiveFactor = glm::vec3(source.emissiveFactor[0], source.emissiveFactor[1], source.emissiveFactor[2]);
    }
    material.emissiveTexture = textureRef(r, source.emissiveTexture.index, source.emissiveTexture.texCoord,
                                          source.emissiveTexture.extensions, what + " emissiveTexture");
    material.normalTexture = textureRef(r, source.normalTexture.index, source.normalTexture.texCoord,
                                        source.normalTexture.extensions, what + " normalTexture");
    material.normalScale = static_cast<float>(source.normalTexture.scale);
    if (!std::isfinite(material.normalScale)) r.fail(what + ": normalTexture.scale is not finite");
    material.doubleSided = source.doubleSided;
    material.alphaMode = source.alphaMode == "MASK" ? AlphaMode::Mask : source.alphaMode == "BLEND" ? AlphaMode::Blend : AlphaMode::Opaque;
    material.alphaCutoff = static_cast<float>(source.alphaCutoff);
    if (!(material.alphaCutoff >= 0.0f)) r.fail(what + ": alphaCutoff " + std::to_string(material.alphaCutoff) + " is negative");
    material.roughness = static_cast<float>(std::clamp(pbr.roughnessFactor, 0.0, 1.0));

    auto extension = [&](const char* name) -> const tinygltf::Value* {
      auto it = source.extensions.find(name);
      return it == source.extensions.end() ? nullptr : &it->second;
    };
    if (const tinygltf::Value* t = extension("KHR_materials_transmission")) {
      material.transmission = static_cast<float>(number(*t, "transmissionFactor", 0.0));
      material.transmissionTexture = extensionTexture(r, *t, "transmissionTexture", what + " transmissionTexture");
      if (!(material.transmission >= 0.0f && material.transmission <= 1.0f)) {
        r.fail(what + ": transmissionFactor " + std::to_string(material.transmission) + " is outside [0, 1]");
      }
    }
    if (const tinygltf::Value* ior = extension("KHR_materials_ior")) {
      double value = number(*ior, "ior", 1.5);
      if (!(value == 0.0 || value >= 1.0) || !std::isfinite(value)) {
        r.fail(what + ": ior " + std::to_string(value) + " is invalid (KHR_materials_ior allows 0 or at least 1)");
      }
      if (value == 0.0) {
        r.warn(what + ": ior 0 cannot refract; using the default 1.5");
        value = 1.5;
      }
      material.ior = static_cast<float>(value);
    }
    if (const tinygltf::Value* v = extension("KHR_materials_volume")) {
      material.thickness = static_cast<float>(number(*v, "thicknessFactor", 0.0));
      material.thicknessTexture = extensionTexture(r, *v, "thicknessTexture", what + " thicknessTexture");
      material.attenuationDistance = static_cast<float>(number(*v, "attenuationDistance", INFINITY));
      if (v->Has("attenuationColor") && v->Get("attenuationColor").ArrayLen() == 3) {
        const tinygltf::Value& c = v->Get("attenuationColor");
        material.attenuationColor = glm::vec3(c.Get(0).GetNumberAsDouble(), c.Get(1).GetNumberAsDouble(), c.Get(2).GetNumberAsDouble());
      }
      if (!(material.thickness >= 0.0f)) r.fail(what + ": thicknessFactor " + std::to_string(material.thickness) + " is negative");
      if (!(material.attenuationDistance > 0.0f)) {
        r.fail(what + ": attenuationDistance " + std::to_string(material.attenuationDistance) + " must be positive");
      }
      for (int c = 0; c < 3; ++c) {
        if (!(material.attenuationColor[c] >= 0.0f && material.attenuationColor[c] <= 1.0f)) {
          r.fail(what + ": attenuationColor is outside [0, 1]");
        }
      }
    }
    if (const tinygltf::Value* d = extension("KHR_materials_dispersion")) {
      double value = number(*d, "dispersion", 0.0);
      if (!(value >= 0.0) || !std::isfinite(value)) {
        r.fail(what + ": dispersion " + std::to_string(value) + " is invalid (KHR_materials_dispersion needs 0 or more)");
      }
      material.dispersion = static_cast<float>(value);
    }
    if (const tinygltf::Value* t = extension("SNELL_materials_ior_texture")) {
      material.iorTexture = extensionTexture(r, *t, "iorTexture", what + " iorTexture");
      material.iorScale = static_cast<float>(number(*t, "scale", 1.0));
      material.iorOffset = static_cast<float>(number(*t, "offset", 0.0));
      if (!material.iorTexture.present()) r.fail(what + ": SNELL_materials_ior_texture has no iorTexture");
      if (!std::isfinite(material.iorScale) || !std::isfinite(material.iorOffset)) {
        r.fail(what + ": SNELL_materials_ior_texture scale and offset must be finite");
      }
    }
    if (const tinygltf::Value* p = extension("SNELL_materials_priority")) {
      double value = number(*p, "priority", 0.0);
      if (!(std::abs(value) <= 1e6) || value != std::floor(value)) {
        r.fail(what + ": priority " + std::to_string(value) + " must be a whole number (SNELL_materials_priority)");
      }
      material.priority = static_cast<int>(value);
    }
    r.scene.materials.push_back(material);
  }
  // A texture that could not be decoded is dropped from every material that uses it.
  for (Material& material : r.scene.materials) {
    for (TextureRef* ref : {&material.baseColorTexture, &material.emissiveTexture, &material.normalTexture,
                            &material.transmissionTexture, &material.thicknessTexture, &material.iorTexture}) {
      if (ref->present() && r.scene.textures[size_t(ref->texture)].rgba.empty()) *ref = TextureRef{};
    }
  }
}

// ---- meshes -----------------------------------------------------------------

std::vector<uint32_t> triangleList(const Reader& r, std::vector<uint32_t> indices, int mode, const std::string& what) {
  std::vector<uint32_t> out;
  if (mode == TINYGLTF_MODE_TRIANGLES) {
    if (indices.size() % 3 != 0) {
      r.warn(what + ": " + std::to_string(indices.size()) + " indices is not a whole number of triangles; the rest is dropped");
      indices.resize(indices.size() - indices.size() % 3);
    }
    return indices;
  }
  if (indices.size() < 3) return out;
  for (size_t i = 2; i < indices.size(); ++i) {
    if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      // Every other triangle of a strip is reversed to keep one winding.
      bool even = (i % 2) == 0;
      out.insert(out.end(), {indices[i - 2], even ? indices[i - 1] : indices[i], even ? indices[i] : indices[i - 1]});
    } else {  // fan
      out.insert(out.end(), {indices[0], indices[i - 1], indices[i]});
    }
  }
  return out;
}

std::vector<glm::vec3> generateNormals(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices) {
  std::vector<glm::vec3> normals(positions.size(), glm::vec3(0.0f));
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    glm::vec3 a = positions[indices[t]], b = positions[indices[t + 1]], c = positions[indices[t + 2]];
    glm::vec3 n = glm::cross(b - a, c - a);  // length is twice the area: area-weighted
    for (int k = 0; k < 3; ++k) normals[indices[t + size_t(k)]] += n;
  }
  for (glm::vec3& n : normals) {
    float length = glm::length(n);
    n = length > 0.0f ? n / length : glm::vec3(0.0f, 0.0f, 1.0f);
  }
  return normals;
}

void loadMeshes(const Reader& r) {
  size_t skippedPrimitives = 0;
  for (size_t m = 0; m < r.model.meshes.size(); ++m) {
    const tinygltf::Mesh& source = r.model.meshes[m];
    std::string meshName = label("mesh", m, source.name);
    Mesh mesh;
    mesh.name = source.name;
    size_t targetCount = source.primitives.empty() ? 0 : source.primitives[0].targets.size();
    for (size_t p = 0; p < source.primitives.size(); ++p) {
      const tinygltf::Primitive& primitive = source.primitives[p];
      std::string what = meshName + " primitive " + std::to_string(p);
      int mode = primitive.mode < 0 ? TINYGLTF_MODE_TRIANGLES : primitive.mode;
      // Points and lines are read and checked like triangles, then dropped:
      // a malformed file is refused whatever snell would draw of it.
      if (mode > TINYGLTF_MODE_TRIANGLE_FAN) r.fail(what + " has unknown mode " + std::to_string(mode));
      if (primitive.targets.size() != targetCount) {
        r.fail(meshName + ": its primitives have different numbers of morph targets");
      }
      auto attribute = [&](const char* name) {
        auto it = primitive.attributes.find(name);
        return it == primitive.attributes.end() ? -1 : it->second;
      };
      Shape shape;
      shape.name = source.name.empty() ? what : source.name + (source.primitives.size() > 1 ? "/" + std::to_string(p) : "");
      shape.mesh = static_cast<int>(m);
      if (attribute("POSITION") < 0) r.fail(what + " has no POSITION attribute");
      shape.positions = readVectors<3>(r, attribute("POSITION"), what + " POSITION");
      size_t vertices = shape.positions.size();
      auto sameCount = [&](size_t n, const char* name) {
        if (n != vertices) {
          r.fail(what + ": " + name + " has " + std::to_string(n) + " elements but POSITION has " + std::to_string(vertices));
        }
      };
      if (attribute("NORMAL") >= 0) {
        shape.normals = readVectors<3>(r, attribute("NORMAL"), what + " NORMAL");
        sameCount(shape.normals.size(), "NORMAL");
      }
      if (attribute("TEXCOORD_0") >= 0) {
        shape.texcoords0 = readVectors<2>(r, attribute("TEXCOORD_0"), what + " TEXCOORD_0");
        sameCount(shape.texcoords0.size(), "TEXCOORD_0");
      }
      if (attribute("TEXCOORD_1") >= 0) {
        shape.texcoords1 = readVectors<2>(r, attribute("TEXCOORD_1"), what + " TEXCOORD_1");
        sameCount(shape.texcoords1.size(), "TEXCOORD_1");
      }
      // Up to two sets of four influences; the four strongest are kept.
      std::vector<std::pair<uint32_t, float>> influences;  // vertices x 8
      size_t sets = 0;
      for (const char* set : {"0", "1"}) {
        std::string jointsName = std::string("JOINTS_") + set, weightsName = std::string("WEIGHTS_") + set;
        if ((attribute(jointsName.c_str()) >= 0) != (attribute(weightsName.c_str()) >= 0)) {
          r.fail(what + ": " + jointsName + " and " + weightsName + " must come together");
        }
        if (attribute(jointsName.c_str()) < 0) break;
        std::vector<uint32_t> joints = readIndices(r, attribute(jointsName.c_str()), what + " " + jointsName);
        std::vector<glm::vec4> weights = readVectors<4>(r, attribute(weightsName.c_str()), what + " " + weightsName);
        if (joints.size() != vertices * 4) r.fail(what + ": " + jointsName + " must have 4 components per vertex");
        sameCount(weights.size(), weightsName.c_str());
        influences.resize(vertices * 8);
        for (size_t v = 0; v < vertices; ++v) {
          for (int k = 0; k < 4; ++k) {
            if (weights[v][k] < 0.0f) r.fail(what + ": " + weightsName + " is negative at vertex " + std::to_string(v));
            influences[v * 8 + sets * 4 + size_t(k)] = {joints[v * 4 + size_t(k)], weights[v][k]};
          }
        }
        ++sets;
      }
      if (sets > 0) {
        bool renormalised = false, dropped = false;
        shape.joints.resize(vertices);
        shape.weights.resize(vertices);
        for (size_t v = 0; v < vertices; ++v) {
          auto first = influences.begin() + static_cast<std::ptrdiff_t>(v * 8);
          auto last = first + static_cast<std::ptrdiff_t>(sets * 4);
          std::stable_sort(first, last, [](const auto& a, const auto& b) { return a.second > b.second; });
          float sum = 0.0f, kept = 0.0f;
          for (auto it = first; it != last; ++it) sum += it->second;
          for (int k = 0; k < 4; ++k) {
            shape.joints[v][k] = first[k].first;
            shape.weights[v][k] = first[k].second;
            kept += first[k].second;
            shape.maxJoint = std::max(shape.maxJoint, first[k].first);
          }
          if (!(sum > 0.0f)) r.fail(what + ": the joint weights of vertex " + std::to_string(v) + " sum to zero");
          dropped = dropped || kept < sum;
          renormalised = renormalised || std::abs(sum - 1.0f) > 2e-3f;
          shape.weights[v] /= kept;
        }
        if (dropped) r.warn(what + ": more than 4 joint influences per vertex; the 4 strongest are kept");
        if (renormalised) r.warn(what + ": joint weights did not sum to 1 and were renormalised");
      }

      std::vector<uint32_t> indices;
      if (primitive.indices >= 0) {
        indices = readIndices(r, primitive.indices, what + " indices");
      } else {
        indices.resize(vertices);
        std::iota(indices.begin(), indices.end(), 0u);
      }
      for (size_t i = 0; i < indices.size(); ++i) {
        if (indices[i] >= vertices) {
          r.fail(what + ": index " + std::to_string(indices[i]) + " at position " + std::to_string(i) +
                 " is out of range (" + std::to_string(vertices) + " vertices)");
        }
      }
      if (mode < TINYGLTF_MODE_TRIANGLES) {
        ++skippedPrimitives;
        continue;
      }
      shape.indices = triangleList(r, std::move(indices), mode, what);
      if (shape.normals.empty()) shape.normals = generateNormals(shape.positions, shape.indices);

      for (size_t t = 0; t < primitive.targets.size(); ++t) {
        const auto& attributes = primitive.targets[t];
        std::string targetName = what + " morph target " + std::to_string(t);
        MorphTarget target;
        for (const auto& [name, accessor] : attributes) {
          if (name == "POSITION") {
            target.positions = readVectors<3>(r, accessor, targetName + " POSITION");
            sameCount(target.positions.size(), "a morph target's POSITION");
          } else if (name == "NORMAL") {
            target.normals = readVectors<3>(r, accessor, targetName + " NORMAL");
            sameCount(target.normals.size(), "a morph target's NORMAL");
          }
        }
        shape.targets.push_back(std::move(target));
      }
      if (primitive.material >= 0) r.at(r.model.materials, primitive.material, what, "material");
      shape.material = primitive.material;
      mesh.shapes.push_back(static_cast<int>(r.scene.shapes.size()));
      r.scene.shapes.push_back(std::move(shape));
    }
    if (!source.weights.empty() && source.weights.size() != targetCount) {
      r.fail(meshName + " has " + std::to_string(source.weights.size()) + " default weights for " +
             std::to_string(targetCount) + " morph targets");
    }
    mesh.weights.assign(targetCount, 0.0f);
    for (size_t w = 0; w < source.weights.size(); ++w) mesh.weights[w] = static_cast<float>(source.weights[w]);
    r.scene.meshes.push_back(std::move(mesh));
  }
  if (skippedPrimitives) {
    r.warn(std::to_string(skippedPrimitives) + " point or line primitive(s) skipped: snell draws triangles only");
  }
}

// ---- cameras, lights, skins -------------------------------------------------

void loadCameras(const Reader& r) {
  for (size_t c = 0; c < r.model.cameras.size(); ++c) {
    const tinygltf::Camera& source = r.model.cameras[c];
    std::string what = label("camera", c, source.name);
    Camera camera;
    camera.name = source.name;
    if (source.type == "orthographic") {
      camera.orthographic = true;
      camera.xmag = static_cast<float>(source.orthographic.xmag);
      camera.ymag = static_cast<float>(source.orthographic.ymag);
      camera.znear = static_cast<float>(source.orthographic.znear);
      camera.zfar = static_cast<float>(source.orthographic.zfar);
      if (camera.xmag == 0.0f || camera.ymag == 0.0f) r.fail(what + ": xmag and ymag must not be zero");
      if (!(camera.znear >= 0.0f) || !(camera.zfar > camera.znear)) r.fail(what + ": zfar must be greater than znear >= 0");
    } else if (source.type == "perspective") {
      camera.yfov = static_cast<float>(source.perspective.yfov);
      camera.aspectRatio = static_cast<float>(source.perspective.aspectRatio);
      camera.znear = static_cast<float>(source.perspective.znear);
      if (source.perspective.zfar > 0.0) camera.zfar = static_cast<float>(source.perspective.zfar);
      if (!(camera.yfov > 0.0f && camera.yfov < kPi)) r.fail(what + ": yfov must be between 0 and pi");
      if (!(camera.znear > 0.0f)) r.fail(what + ": znear must be positive");
      if (!(camera.zfar > camera.znear)) r.fail(what + ": zfar " + std::to_string(camera.zfar) + " must be greater than znear " + std::to_string(camera.znear));
      if (camera.aspectRatio < 0.0f) r.fail(what + ": aspectRatio must be positive");
    } else {
      r.fail(what + " has unknown type '" + source.type + "'");
    }
    r.scene.cameras.push_back(camera);
  }
}

// Returns, per light of the file, its index in the scene's lights (-1: skipped).
std::vector<int> loadLights(const Reader& r) {
  std::vector<int> indexOf;
  for (size_t l = 0; l < r.model.lights.size(); ++l) {
    const tinygltf::Light& source = r.model.lights[l];
    std::string what = label("light", l, source.name);
    Light light;
    light.name = source.name;
    if (source.type == "directional") {
      light.type = LightType::Directional;
    } else if (source.type == "point") {
      light.type = LightType::Point;
    } else if (source.type == "spot") {
      light.type = LightType::Spot;
    } else {
      // A type a later KHR_lights_punctual may add: as a glTF viewer does, say so and leave it out.
      r.warn(what + " has type '" + source.type + "', which snell does not know; it is left out");
      indexOf.push_back(-1);
      continue;
    }
    if (source.color.size() == 3) light.color = glm::vec3(source.color[0], source.color[1], source.color[2]);
    light.intensity = static_cast<float>(source.intensity);
    if (source.range > 0.0) light.range = static_cast<float>(source.range);
    if (!(light.intensity >= 0.0f) || source.range < 0.0) r.fail(what + ": intensity and range must not be negative");
    if (light.type == LightType::Spot) {
      light.innerConeAngle = static_cast<float>(source.spot.innerConeAngle);
      light.outerConeAngle = static_cast<float>(source.spot.outerConeAngle);
      if (!(light.innerConeAngle >= 0.0f && light.innerConeAngle < light.outerConeAngle && light.outerConeAngle <= kPi / 2 + 1e-6f)) {
        r.fail(what + ": spot angles must satisfy 0 <= innerConeAngle < outerConeAngle <= pi/2");
      }
    }
    indexOf.push_back(int(r.scene.lights.size()));
    r.scene.lights.push_back(light);
  }
  return indexOf;
}

void loadSkins(const Reader& r) {
  for (size_t s = 0; s < r.model.skins.size(); ++s) {
    const tinygltf::Skin& source = r.model.skins[s];
    std::string what = label("skin", s, source.name);
    Skin skin;
    skin.name = source.name;
    if (source.joints.empty()) r.fail(what + " has no joints");
    for (int joint : source.joints) r.at(r.model.nodes, joint, what + " joint", "node");
    skin.joints = source.joints;
    if (source.skeleton >= 0) r.at(r.model.nodes, source.skeleton, what + " skeleton", "node");
    skin.skeleton = source.skeleton;
    if (source.inverseBindMatrices >= 0) {
      AccessorData matrices = readAccessor(r, source.inverseBindMatrices, what + " inverseBindMatrices");
      if (matrices.components != 16) r.fail(what + ": inverseBindMatrices must be MAT4");
      if (matrices.count != skin.joints.size()) {
        r.fail(what + " has " + std::to_string(matrices.count) + " inverse bind matrices for " +
               std::to_string(skin.joints.size()) + " joints");
      }
      for (size_t j = 0; j < matrices.count; ++j) {
        glm::mat4 m;
        for (int k = 0; k < 16; ++k) {
          double v = matrices.values[j * 16 + size_t(k)];
          if (!std::isfinite(v)) r.fail(what + ": inverse bind matrix " + std::to_string(j) + " is not finite");
          glm::value_ptr(m)[k] = static_cast<float>(v);
        }
        skin.inverseBindMatrices.push_back(m);
      }
    } else {
      skin.inverseBindMatrices.assign(skin.joints.size(), glm::mat4(1.0f));
    }
    r.scene.skins.push_back(std::move(skin));
  }
}

// ---- nodes and scenes -------------------------------------------------------

std::vector<glm::mat4> instancing(const Reader& r, const tinygltf::Value& extension, const std::string& what) {
  if (!extension.Has("attributes")) return {};
  const tinygltf::Value& attributes = extension.Get("attributes");
  std::vector<glm::vec3> translations, scales;
  std::vector<glm::vec4> rotations;
  size_t count = 0;
  auto take = [&](const char* name, auto& out, auto read) {
    if (!attributes.Has(name)) return;
    out = read(static_cast<int>(attributes.Get(name).GetNumberAsInt()), what + " " + name);
    if (count && out.size() != count) r.fail(what + ": instancing attributes differ in count");
    count = out.size();
  };
  take("TRANSLATION", translations, [&](int a, const std::string& w) { return readVectors<3>(r, a, w); });
  take("ROTATION", rotations, [&](int a, const std::string& w) { return readVectors<4>(r, a, w); });
  take("SCALE", scales, [&](int a, const std::string& w) { return readVectors<3>(r, a, w); });
  std::vector<glm::mat4> matrices(count, glm::mat4(1.0f));
  for (size_t i = 0; i < count; ++i) {
    glm::mat4 t = translations.empty() ? glm::mat4(1.0f) : glm::translate(glm::mat4(1.0f), translations[i]);
    glm::mat4 q = rotations.empty() ? glm::mat4(1.0f)
                                    : glm::mat4_cast(glm::normalize(glm::quat(rotations[i].w, rotations[i].x, rotations[i].y, rotations[i].z)));
    glm::mat4 s = scales.empty() ? glm::mat4(1.0f) : glm::scale(glm::mat4(1.0f), scales[i]);
    matrices[i] = t * q * s;
  }
  return matrices;
}

void loadNodes(const Reader& r, const std::vector<int>& lightIndex) {
  const auto& nodes = r.model.nodes;
  r.scene.nodes.resize(nodes.size());
  for (size_t n = 0; n < nodes.size(); ++n) {
    const tinygltf::Node& source = nodes[n];
    std::string what = label("node", n, source.name);
    Node& node = r.scene.nodes[n];
    node.name = source.name;
    for (int child : source.children) {
      r.at(nodes, child, what + " child", "node");
      Node& c = r.scene.nodes[size_t(child)];
      if (c.parent >= 0 || static_cast<size_t>(child) == n) {
        r.fail(label("node", size_t(child), nodes[size_t(child)].name) + " has more than one parent or is its own child");
      }
      c.parent = static_cast<int>(n);
      node.children.push_back(child);
    }
    auto finite = [&](const std::vector<double>& values, size_t size, const char* name) {
      if (!values.empty() && values.size() != size) r.fail(what + ": " + name + " has " + std::to_string(values.size()) + " numbers");
      for (double v : values) {
        if (!std::isfinite(v)) r.fail(what + ": " + name + " is not finite");
      }
      return !values.empty();
    };
    if (finite(source.matrix, 16, "matrix")) {
      glm::mat4 m;
      for (int k = 0; k < 16; ++k) glm::value_ptr(m)[k] = static_cast<float>(source.matrix[size_t(k)]);
      node.matrix = m;
    }
    if (finite(source.translation, 3, "translation")) {
      node.translation = glm::vec3(source.translation[0], source.translation[1], source.translation[2]);
    }
    if (finite(source.rotation, 4, "rotation")) {
      glm::quat q(static_cast<float>(source.rotation[3]), static_cast<float>(source.rotation[0]),
                  static_cast<float>(source.rotation[1]), static_cast<float>(source.rotation[2]));
      float length = glm::length(q);
      if (!(length > 0.0f)) r.fail(what + ": rotation is a zero quaternion");
      node.rotation = q / length;
    }
    if (finite(source.scale, 3, "scale")) node.scale = glm::vec3(source.scale[0], source.scale[1], source.scale[2]);
    if (source.mesh >= 0) r.at(r.scene.meshes, source.mesh, what, "mesh");
    if (source.skin >= 0) r.at(r.scene.skins, source.skin, what, "skin");
    if (source.camera >= 0) r.at(r.scene.cameras, source.camera, what, "camera");
    node.mesh = source.mesh;
    node.skin = source.skin;
    node.camera = source.camera;
    for (double w : source.weights) node.weights.push_back(static_cast<float>(w));
    if (node.mesh >= 0 && !node.weights.empty() && node.weights.size() != r.scene.meshes[size_t(node.mesh)].weights.size()) {
      r.fail(what + " has " + std::to_string(node.weights.size()) + " morph weights for a mesh with " +
             std::to_string(r.scene.meshes[size_t(node.mesh)].weights.size()) + " targets");
    }
    if (auto it = source.extensions.find("KHR_lights_punctual"); it != source.extensions.end()) {
      int light = static_cast<int>(number(it->second, "light", -1));
      r.at(r.model.lights, light, what, "light");
      node.light = lightIndex[size_t(light)];
    }
    if (auto it = source.extensions.find("EXT_mesh_gpu_instancing"); it != source.extensions.end()) {
      node.instances = instancing(r, it->second, what + " EXT_mesh_gpu_instancing");
    }
    if (node.skin >= 0 && node.mesh >= 0) {
      size_t jointCount = r.scene.skins[size_t(node.skin)].joints.size();
      for (int s : r.scene.meshes[size_t(node.mesh)].shapes) {
        const Shape& shape = r.scene.shapes[size_t(s)];
        if (shape.skinned() && shape.maxJoint >= jointCount) {
          r.fail(what + ": a vertex names joint " + std::to_string(shape.maxJoint) + " but skin " +
                 std::to_string(node.skin) + " has " + std::to_string(jointCount) + " joints");
        }
      }
    }
  }
  // Each node has at most one parent, so a walk up that takes longer than the
  // node count has found a cycle (glTF requires a forest).
  for (size_t n = 0; n < nodes.size(); ++n) {
    int at = static_cast<int>(n);
    for (size_t steps = 0; at >= 0; ++steps) {
      if (steps > nodes.size()) r.fail(label("node", n, nodes[n].name) + " is part of a cycle in the node hierarchy");
      at = r.scene.nodes[size_t(at)].parent;
    }
  }
}

void chooseScene(const Reader& r, const LoadOptions& options) {
  const auto& scenes = r.model.scenes;
  int chosen = -1;
  if (!options.scene.empty()) {
    for (size_t s = 0; s < scenes.size(); ++s) {
      if (scenes[s].name == options.scene || std::to_string(s) == options.scene) chosen = static_cast<int>(s);
    }
    if (chosen < 0) {
      std::string names;
      for (size_t s = 0; s < scenes.size(); ++s) names += (s ? ", " : "") + label("scene", s, scenes[s].name);
      r.fail("has no scene '" + options.scene + "' (it has: " + (names.empty() ? "none" : names) + ")");
    }
  } else if (r.model.defaultScene >= 0) {
    r.at(scenes, r.model.defaultScene, "the default scene", "scene");
    chosen = r.model.defaultScene;
  } else if (!scenes.empty()) {
    chosen = 0;
  }
  if (chosen >= 0) {
    for (int node : scenes[size_t(chosen)].nodes) {
      r.at(r.scene.nodes, node, label("scene", size_t(chosen), scenes[size_t(chosen)].name), "node");
      if (r.scene.nodes[size_t(node)].parent >= 0) r.fail(label("scene", size_t(chosen), "") + " lists a node that is not a root");
      r.scene.roots.push_back(node);
    }
  } else {
    for (size_t n = 0; n < r.scene.nodes.size(); ++n) {
      if (r.scene.nodes[n].parent < 0) r.scene.roots.push_back(static_cast<int>(n));
    }
  }
}

// ---- animations -------------------------------------------------------------

void loadAnimations(const Reader& r) {
  for (size_t a = 0; a < r.model.animations.size(); ++a) {
    const tinygltf::Animation& source = r.model.animations[a];
    std::string what = label("animation", a, source.name);
    Animation animation;
    animation.name = source.name.empty() ? "animation " + std::to_string(a) : source.name;
    std::vector<int> samplerComponents(source.samplers.size(), -1);
    for (size_t c = 0; c < source.channels.size(); ++c) {
      const tinygltf::AnimationChannel& channel = source.channels[c];
      std::string channelName = what + " channel " + std::to_string(c);
      if (channel.target_node < 0) continue;  // allowed: the target lives in an extension
      const Node& node = r.at(r.scene.nodes, channel.target_node, channelName, "node");
      r.at(source.samplers, channel.sampler, channelName, "sampler");
      AnimationChannel out;
      out.node = channel.target_node;
      out.sampler = channel.sampler;
      int components = 0;
      if (channel.target_path == "translation") out.path = AnimationPath::Translation, components = 3;
      else if (channel.target_path == "rotation") out.path = AnimationPath::Rotation, components = 4;
      else if (channel.target_path == "scale") out.path = AnimationPath::Scale, components = 3;
      else if (channel.target_path == "weights") {
        out.path = AnimationPath::Weights;
        if (node.mesh < 0) r.fail(channelName + " animates weights of a node without a mesh");
        components = static_cast<int>(r.scene.meshes[size_t(node.mesh)].weights.size());
      } else {
        r.fail(channelName + " has unknown path '" + channel.target_path + "'");
      }
      if (node.matrix && out.path != AnimationPath::Weights) r.fail(channelName + " animates a node given by a matrix");
      int& expected = samplerComponents[size_t(channel.sampler)];
      if (expected >= 0 && expected != components) r.fail(channelName + " shares a sampler with a channel of another size");
      expected = components;
      animation.channels.push_back(out);
    }
    for (size_t s = 0; s < source.samplers.size(); ++s) {
      const tinygltf::AnimationSampler& sampler = source.samplers[s];
      std::string samplerName = what + " sampler " + std::to_string(s);
      AnimationSampler out;
      out.interpolation = sampler.interpolation == "STEP" ? Interpolation::Step
                          : sampler.interpolation == "CUBICSPLINE" ? Interpolation::CubicSpline
                                                                   : Interpolation::Linear;
      out.times = readScalars(r, sampler.input, samplerName + " input");
      out.values = readScalars(r, sampler.output, samplerName + " output");
      out.components = std::max(samplerComponents[s], 0);
      for (size_t k = 1; k < out.times.size(); ++k) {
        if (!(out.times[k] > out.times[k - 1])) r.fail(samplerName + ": key times must increase");
      }
      if (!out.times.empty() && out.times[0] < 0.0f) r.fail(samplerName + ": key times must not be negative");
      size_t perKey = size_t(out.components) * (out.interpolation == Interpolation::CubicSpline ? 3 : 1);
      if (out.components > 0 && out.values.size() != out.times.size() * perKey) {
        r.fail(samplerName + " has " + std::to_string(out.values.size()) + " output values for " +
               std::to_string(out.times.size()) + " keys of " + std::to_string(perKey));
      }
      if (out.components > 0 && out.times.empty()) r.fail(samplerName + " has no keys");
      if (!out.times.empty()) animation.duration = std::max(animation.duration, out.times.back());
      animation.samplers.push_back(std::move(out));
    }
    r.scene.animations.push_back(std::move(animation));
  }
}

std::vector<unsigned char> readHead(const std::string& path, size_t bytes) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw SceneError(path + ": cannot open the file");
  std::vector<unsigned char> head(bytes);
  file.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(bytes));
  head.resize(static_cast<size_t>(file.gcount()));
  return head;
}

// Images are decoded after parsing, all at once on every core: tinygltf
// hands each image's encoded bytes to this loader, which keeps them.
struct EncodedImages {
  std::mutex mutex;
  std::map<int, std::vector<unsigned char>> bytes;  // by image index
  const tinygltf::Model* model = nullptr;           // being parsed: its buffers come before its images
};

// Debian's tinygltf (2.8) hands over an image in a bufferView without checking
// that the view lies inside its buffer (found by fuzzing, tests/fuzz): the
// view is checked here before a byte is read.
bool imageViewInBounds(const tinygltf::Model& model, const tinygltf::Image& image) {
  if (image.bufferView < 0) return true;
  if (size_t(image.bufferView) >= model.bufferViews.size()) return false;
  const tinygltf::BufferView& view = model.bufferViews[size_t(image.bufferView)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size()) return false;
  size_t bufferSize = model.buffers[size_t(view.buffer)].data.size();
  return view.byteOffset <= bufferSize && view.byteLength <= bufferSize - view.byteOffset;
}

bool keepEncoded(tinygltf::Image* image, const int index, std::string* error, std::string*, int, int,
                 const unsigned char* bytes, int size, void* user) {
  auto* encoded = static_cast<EncodedImages*>(user);
  if (image && encoded->model && !imageViewInBounds(*encoded->model, *image)) {
    if (error) *error += "image " + std::to_string(index) + ": its bufferView lies outside its buffer";
    return false;
  }
  if (size < 0) return false;
  std::lock_guard<std::mutex> lock(encoded->mutex);
  encoded->bytes[index].assign(bytes, bytes + size);
  return true;
}

// Whether a PNG's chunks lie inside its bytes. stb allocates what a chunk's
// length field claims before reading it (found by fuzzing: a 60 KB file asked
// for 2 GB), so a PNG whose chunks overrun its bytes is not handed to stb.
bool pngChunksFit(const std::vector<unsigned char>& bytes) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kSignature, 8) != 0) return true;  // not a PNG: stb checks the rest
  size_t at = 8;
  while (at + 12 <= bytes.size()) {
    uint64_t length = uint64_t(bytes[at]) << 24 | uint64_t(bytes[at + 1]) << 16 | uint64_t(bytes[at + 2]) << 8 | bytes[at + 3];
    if (length > bytes.size() - at - 12) return false;
    if (std::memcmp(&bytes[at + 4], "IEND", 4) == 0) return true;
    at += 12 + size_t(length);
  }
  return false;  // no IEND before the end
}

// What tinygltf's own loader does with stb_image (RGBA, 16 bits where the
// file has them); an image it cannot read stays empty, as tinygltf leaves it.
void decodeImage(tinygltf::Image& image, const std::vector<unsigned char>& bytes) {
  const int size = static_cast<int>(bytes.size());
  int w = 0, h = 0, comp = 0, bits = 8;
  // An image's header may claim any size: one beyond snell's limit is not
  // decoded (found by fuzzing: stb would allocate what the header says), and
  // the texture that uses it is refused with the size it claims.
  if (stbi_info_from_memory(bytes.data(), size, &w, &h, &comp) && (w > kMaxImageSide || h > kMaxImageSide)) {
    image.width = w;
    image.height = h;
    return;
  }
  if (!pngChunksFit(bytes)) return;
  unsigned char* data = nullptr;
  if (stbi_is_16_bit_from_memory(bytes.data(), size)) {
    data = reinterpret_cast<unsigned char*>(stbi_load_16_from_memory(bytes.data(), size, &w, &h, &comp, 4));
    if (data) bits = 16;
  }
  if (!data) data = stbi_load_from_memory(bytes.data(), size, &w, &h, &comp, 4);
  if (!data) return;
  if (w > 0 && h > 0) {
    image.width = w;
    image.height = h;
    image.component = 4;
    image.bits = bits;
    image.pixel_type = bits == 16 ? TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT : TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    image.image.assign(data, data + size_t(w) * size_t(h) * 4 * size_t(bits / 8));
  }
  stbi_image_free(data);
}

unsigned decodeImages(tinygltf::Model& model, EncodedImages& encoded) {
  std::vector<std::pair<int, const std::vector<unsigned char>*>> work;
  for (const auto& [index, bytes] : encoded.bytes) {
    if (index >= 0 && size_t(index) < model.images.size()) work.emplace_back(index, &bytes);
  }
  // Largest first, so one big image does not start last.
  std::sort(work.begin(), work.end(), [](const auto& a, const auto& b) { return a.second->size() > b.second->size(); });
  unsigned threads = std::clamp<unsigned>(std::thread::hardware_concurrency(), 1u, std::max<unsigned>(1u, unsigned(work.size())));
  std::atomic<size_t> next{0};
  auto run = [&] {
    for (size_t i = next++; i < work.size(); i = next++) decodeImage(model.images[size_t(work[i].first)], *work[i].second);
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(run);
  run();
  for (std::thread& t : pool) t.join();
  return threads;
}

}  // namespace

Scene loadGltf(const std::string& path, const LoadOptions& options) {
  std::vector<unsigned char> head = readHead(path, 4);
  if (head.empty()) throw SceneError(path + ": the file is empty");
  bool binary = head.size() == 4 && std::memcmp(head.data(), "glTF", 4) == 0;
  bool glbName = path.size() >= 4 && path.compare(path.size() - 4, 4, ".glb") == 0;
  if (glbName && !binary && head[0] != '{') {
    throw SceneError(path + ": not a GLB file: it does not start with the magic 'glTF'");
  }
  if (!binary && head.size() >= 3 && head[0] == 0xEF && head[1] == 0xBB && head[2] == 0xBF) {
    throw SceneError(path + ": starts with a UTF-8 byte-order mark, which glTF JSON must not have");
  }

  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  tinygltf::TinyGLTF parser;
  EncodedImages encoded;
  tinygltf::Model model;
  encoded.model = &model;
  parser.SetImageLoader(keepEncoded, &encoded);
  std::string error, warning;
  bool ok = binary ? parser.LoadBinaryFromFile(&model, &error, &warning, path)
                   : parser.LoadASCIIFromFile(&model, &error, &warning, path);
  if (!ok) {
    while (!error.empty() && (error.back() == '\n' || error.back() == ' ')) error.pop_back();
    for (size_t at = error.find('\n'); at != std::string::npos; at = error.find('\n', at)) error.replace(at, 1, "; ");
    throw SceneError(path + ": not a readable glTF file: " + (error.empty() ? "the parser gave no reason" : error));
  }

  Scene scene;
  scene.source = path;
  const Clock::time_point parsed = Clock::now();
  scene.loadTimes.decodeThreads = decodeImages(model, encoded);
  encoded.bytes.clear();
  scene.loadTimes.parseSeconds = std::chrono::duration<double>(parsed - start).count();
  scene.loadTimes.decodeSeconds = std::chrono::duration<double>(Clock::now() - parsed).count();
  Reader r{path, model, scene};
  for (const std::string& required : model.extensionsRequired) {
    bool supported = std::find(kSupported.begin(), kSupported.end(), required) != kSupported.end();
    bool ignored = std::find(options.ignoredExtensions.begin(), options.ignoredExtensions.end(), required) !=
                   options.ignoredExtensions.end();
    if (ignored && !supported) r.warn("required extension " + required + " ignored on request; the scene may look wrong");
    if (!supported && !ignored) {
      r.fail("requires extension " + required + ", which snell does not implement (load it anyway with --ignore-extension " +
             required + ")");
    }
  }
  for (const std::string& used : model.extensionsUsed) {
    if (std::find(kSupported.begin(), kSupported.end(), used) == kSupported.end() &&
        std::find(model.extensionsRequired.begin(), model.extensionsRequired.end(), used) == model.extensionsRequired.end()) {
      r.warn("optional extension " + used + " is not implemented and was ignored");
    }
  }
  loadTextures(r);
  loadMaterials(r);
  loadMeshes(r);
  loadCameras(r);
  const std::vector<int> lightIndex = loadLights(r);
  loadSkins(r);
  loadNodes(r, lightIndex);
  chooseScene(r, options);
  loadAnimations(r);
  if (options.textureBudget) {
    for (std::string& note : fitTextureBudget(scene, options.textureBudget)) scene.warnings.push_back(std::move(note));
  }
  return scene;
}

}  // namespace snell::scene
