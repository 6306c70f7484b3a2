// Scene -> tinygltf::Model -> .glb. Every array goes into one buffer, each in
// its own 4-byte-aligned buffer view, with min/max on positions as glTF requires.
#include "scene/gltf_writer.h"

#include "scene/png.h"

#include <tiny_gltf.h>

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace snell::scene {

namespace {

/// Appends `data` to a buffer, 4-byte aligned, as a new buffer view.
struct BufferBuilder {
  tinygltf::Model& model;
  std::vector<unsigned char>& bytes;

  int view(const void* data, size_t size, int target = 0) {
    while (bytes.size() % 4) bytes.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = bytes.size();
    v.byteLength = size;
    v.target = target;
    const auto* p = static_cast<const unsigned char*>(data);
    bytes.insert(bytes.end(), p, p + size);
    model.bufferViews.push_back(v);
    return static_cast<int>(model.bufferViews.size() - 1);
  }

  template <typename T>
  int accessor(const std::vector<T>& values, int componentType, int type, size_t components, int target = 0,
               bool minMax = false) {
    tinygltf::Accessor a;
    a.bufferView = view(values.data(), values.size() * sizeof(T), target);
    a.componentType = componentType;
    a.type = type;
    a.count = values.size() * sizeof(T) / (components * 4);
    if (minMax && a.count) {
      const float* f = reinterpret_cast<const float*>(values.data());
      a.minValues.assign(components, INFINITY);
      a.maxValues.assign(components, -INFINITY);
      for (size_t i = 0; i < a.count * components; ++i) {
        a.minValues[i % components] = std::min<double>(a.minValues[i % components], f[i]);
        a.maxValues[i % components] = std::max<double>(a.maxValues[i % components], f[i]);
      }
    }
    model.accessors.push_back(a);
    return static_cast<int>(model.accessors.size() - 1);
  }
};

tinygltf::Value textureInfo(const TextureRef& ref) {
  tinygltf::Value::Object o;
  o["index"] = tinygltf::Value(ref.texture);
  if (ref.texCoord) o["texCoord"] = tinygltf::Value(ref.texCoord);
  return tinygltf::Value(o);
}

tinygltf::Value numbers(std::initializer_list<double> values) {
  tinygltf::Value::Array a;
  for (double v : values) a.push_back(tinygltf::Value(v));
  return tinygltf::Value(a);
}

}  // namespace

void saveGltf(const Scene& scene, const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext != ".glb" && ext != ".gltf") {
    throw SceneError(path + ": a scene is written as .glb (binary) or .gltf (JSON and a .bin beside it), not '" + ext + "'");
  }
  const bool binary = ext == ".glb";
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "snell";
  model.buffers.resize(1);
  BufferBuilder b{model, model.buffers[0].data};
  std::vector<std::string> used;
  auto use = [&](const char* extension) {
    if (std::find(used.begin(), used.end(), extension) == used.end()) used.push_back(extension);
  };

  for (const Texture& t : scene.textures) {
    std::vector<uint8_t> png = encodePng(t.width, t.height, t.rgba);
    tinygltf::Image image;
    image.name = t.name;
    image.mimeType = "image/png";
    image.bufferView = b.view(png.data(), png.size());
    model.images.push_back(image);
    tinygltf::Sampler sampler;
    sampler.wrapS = t.mirrorS ? TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT : t.repeatS ? TINYGLTF_TEXTURE_WRAP_REPEAT : TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    sampler.wrapT = t.mirrorT ? TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT : t.repeatT ? TINYGLTF_TEXTURE_WRAP_REPEAT : TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
    sampler.magFilter = t.linearFilter ? TINYGLTF_TEXTURE_FILTER_LINEAR : TINYGLTF_TEXTURE_FILTER_NEAREST;
    sampler.minFilter = t.linearFilter ? TINYGLTF_TEXTURE_FILTER_LINEAR : TINYGLTF_TEXTURE_FILTER_NEAREST;
    model.samplers.push_back(sampler);
    tinygltf::Texture texture;
    texture.source = texture.sampler = static_cast<int>(model.images.size() - 1);
    model.textures.push_back(texture);
  }

  for (const Material& m : scene.materials) {
    tinygltf::Material out;
    out.name = m.name;
    out.pbrMetallicRoughness.baseColorFactor = {m.baseColorFactor.r, m.baseColorFactor.g, m.baseColorFactor.b, m.baseColorFactor.a};
    out.pbrMetallicRoughness.metallicFactor = 0.0;
    out.pbrMetallicRoughness.roughnessFactor = m.roughness;
    if (m.baseColorTexture.present()) {
      out.pbrMetallicRoughness.baseColorTexture.index = m.baseColorTexture.texture;
      out.pbrMetallicRoughness.baseColorTexture.texCoord = m.baseColorTexture.texCoord;
    }
    out.emissiveFactor = {m.emissiveFactor.r, m.emissiveFactor.g, m.emissiveFactor.b};
    if (m.emissiveTexture.present()) {
      out.emissiveTexture.index = m.emissiveTexture.texture;
      out.emissiveTexture.texCoord = m.emissiveTexture.texCoord;
    }
    if (m.normalTexture.present()) {
      out.normalTexture.index = m.normalTexture.texture;
      out.normalTexture.texCoord = m.normalTexture.texCoord;
      out.normalTexture.scale = m.normalScale;
    }
    out.doubleSided = m.doubleSided;
    out.alphaMode = m.alphaMode == AlphaMode::Mask ? "MASK" : m.alphaMode == AlphaMode::Blend ? "BLEND" : "OPAQUE";
    if (m.alphaMode == AlphaMode::Mask) out.alphaCutoff = m.alphaCutoff;
    if (m.refractive()) {
      tinygltf::Value::Object transmission{{"transmissionFactor", tinygltf::Value(double(m.transmission))}};
      if (m.transmissionTexture.present()) transmission["transmissionTexture"] = textureInfo(m.transmissionTexture);
      out.extensions["KHR_materials_transmission"] = tinygltf::Value(transmission);
      out.extensions["KHR_materials_ior"] = tinygltf::Value(tinygltf::Value::Object{{"ior", tinygltf::Value(double(m.ior))}});
      use("KHR_materials_transmission");
      use("KHR_materials_ior");
      if (m.thickness > 0.0f) {
        tinygltf::Value::Object volume{{"thicknessFactor", tinygltf::Value(double(m.thickness))},
                                       {"attenuationColor", numbers({m.attenuationColor.r, m.attenuationColor.g, m.attenuationColor.b})}};
        if (std::isfinite(m.attenuationDistance)) volume["attenuationDistance"] = tinygltf::Value(double(m.attenuationDistance));
        out.extensions["KHR_materials_volume"] = tinygltf::Value(volume);
        use("KHR_materials_volume");
      }
      if (m.dispersion > 0.0f) {
        out.extensions["KHR_materials_dispersion"] =
            tinygltf::Value(tinygltf::Value::Object{{"dispersion", tinygltf::Value(double(m.dispersion))}});
        use("KHR_materials_dispersion");
      }
      if (m.iorTexture.present()) {
        out.extensions["SNELL_materials_ior_texture"] = tinygltf::Value(tinygltf::Value::Object{
            {"iorTexture", textureInfo(m.iorTexture)},
            {"scale", tinygltf::Value(double(m.iorScale))},
            {"offset", tinygltf::Value(double(m.iorOffset))}});
        use("SNELL_materials_ior_texture");
      }
      if (m.priority != 0) {
        out.extensions["SNELL_materials_priority"] =
            tinygltf::Value(tinygltf::Value::Object{{"priority", tinygltf::Value(m.priority)}});
        use("SNELL_materials_priority");
      }
    }
    model.materials.push_back(out);
  }

  for (const Mesh& mesh : scene.meshes) {
    tinygltf::Mesh out;
    out.name = mesh.name;
    for (float w : mesh.weights) out.weights.push_back(w);
    for (int index : mesh.shapes) {
      const Shape& s = scene.shapes[size_t(index)];
      tinygltf::Primitive p;
      p.mode = TINYGLTF_MODE_TRIANGLES;
      p.material = s.material;
      p.attributes["POSITION"] = b.accessor(s.positions, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, 3,
                                            TINYGLTF_TARGET_ARRAY_BUFFER, true);
      p.attributes["NORMAL"] = b.accessor(s.normals, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, 3, TINYGLTF_TARGET_ARRAY_BUFFER);
      if (!s.texcoords0.empty()) {
        p.attributes["TEXCOORD_0"] = b.accessor(s.texcoords0, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC2, 2, TINYGLTF_TARGET_ARRAY_BUFFER);
      }
      if (s.skinned()) {
        std::vector<uint16_t> joints;
        for (const glm::uvec4& j : s.joints) joints.insert(joints.end(), {uint16_t(j.x), uint16_t(j.y), uint16_t(j.z), uint16_t(j.w)});
        tinygltf::Accessor a;
        a.bufferView = b.view(joints.data(), joints.size() * 2, TINYGLTF_TARGET_ARRAY_BUFFER);
        a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
        a.type = TINYGLTF_TYPE_VEC4;
        a.count = s.joints.size();
        model.accessors.push_back(a);
        p.attributes["JOINTS_0"] = static_cast<int>(model.accessors.size() - 1);
        p.attributes["WEIGHTS_0"] = b.accessor(s.weights, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC4, 4, TINYGLTF_TARGET_ARRAY_BUFFER);
      }
      for (const MorphTarget& t : s.targets) {
        std::map<std::string, int> target;
        if (!t.positions.empty()) target["POSITION"] = b.accessor(t.positions, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, 3, 0, true);
        if (!t.normals.empty()) target["NORMAL"] = b.accessor(t.normals, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3, 3);
        p.targets.push_back(target);
      }
      p.indices = b.accessor(s.indices, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, TINYGLTF_TYPE_SCALAR, 1, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
      out.primitives.push_back(p);
    }
    model.meshes.push_back(out);
  }

  for (const Skin& skin : scene.skins) {
    tinygltf::Skin out;
    out.name = skin.name;
    out.joints = skin.joints;
    out.skeleton = skin.skeleton;
    out.inverseBindMatrices = b.accessor(skin.inverseBindMatrices, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_MAT4, 16);
    model.skins.push_back(out);
  }

  for (const Camera& c : scene.cameras) {
    tinygltf::Camera out;
    out.name = c.name;
    if (c.orthographic) {
      out.type = "orthographic";
      out.orthographic.xmag = c.xmag, out.orthographic.ymag = c.ymag;
      out.orthographic.znear = c.znear, out.orthographic.zfar = c.zfar;
    } else {
      out.type = "perspective";
      out.perspective.yfov = c.yfov;
      out.perspective.znear = c.znear;
      if (std::isfinite(c.zfar)) out.perspective.zfar = c.zfar;
      if (c.aspectRatio > 0.0f) out.perspective.aspectRatio = c.aspectRatio;
    }
    model.cameras.push_back(out);
  }

  for (const Light& l : scene.lights) {
    tinygltf::Light out;
    out.name = l.name;
    out.type = l.type == LightType::Directional ? "directional" : l.type == LightType::Spot ? "spot" : "point";
    out.color = {l.color.r, l.color.g, l.color.b};
    out.intensity = l.intensity;
    if (std::isfinite(l.range)) out.range = l.range;
    out.spot.innerConeAngle = l.innerConeAngle;
    out.spot.outerConeAngle = l.outerConeAngle;
    model.lights.push_back(out);
  }

  for (const Node& n : scene.nodes) {
    tinygltf::Node out;
    out.name = n.name;
    out.children = n.children;
    out.mesh = n.mesh;
    out.skin = n.skin;
    out.camera = n.camera;
    if (n.matrix) {
      const float* m = glm::value_ptr(*n.matrix);
      out.matrix.assign(m, m + 16);
    } else {
      if (n.translation != glm::vec3(0.0f)) out.translation = {n.translation.x, n.translation.y, n.translation.z};
      if (n.rotation != glm::quat(1, 0, 0, 0)) out.rotation = {n.rotation.x, n.rotation.y, n.rotation.z, n.rotation.w};
      if (n.scale != glm::vec3(1.0f)) out.scale = {n.scale.x, n.scale.y, n.scale.z};
    }
    for (float w : n.weights) out.weights.push_back(w);
    if (n.light >= 0) out.extensions["KHR_lights_punctual"] = tinygltf::Value(tinygltf::Value::Object{{"light", tinygltf::Value(n.light)}});
    model.nodes.push_back(out);
  }
  if (!scene.lights.empty()) use("KHR_lights_punctual");

  for (const Animation& a : scene.animations) {
    tinygltf::Animation out;
    out.name = a.name;
    for (const AnimationSampler& s : a.samplers) {
      tinygltf::AnimationSampler sampler;
      sampler.input = b.accessor(s.times, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_SCALAR, 1, 0, true);
      // Rotations are VEC4, translations and scales VEC3; weights are scalars.
      int type = s.components == 4 ? TINYGLTF_TYPE_VEC4 : s.components == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_SCALAR;
      size_t components = type == TINYGLTF_TYPE_SCALAR ? 1 : size_t(s.components);
      sampler.output = b.accessor(s.values, TINYGLTF_COMPONENT_TYPE_FLOAT, type, components);
      sampler.interpolation = s.interpolation == Interpolation::Step ? "STEP" : s.interpolation == Interpolation::CubicSpline ? "CUBICSPLINE" : "LINEAR";
      out.samplers.push_back(sampler);
    }
    for (const AnimationChannel& c : a.channels) {
      tinygltf::AnimationChannel channel;
      channel.sampler = c.sampler;
      channel.target_node = c.node;
      const char* paths[] = {"translation", "rotation", "scale", "weights"};
      channel.target_path = paths[int(c.path)];
      out.channels.push_back(channel);
    }
    model.animations.push_back(out);
  }

  tinygltf::Scene root;
  root.nodes = scene.roots;
  model.scenes.push_back(root);
  model.defaultScene = 0;
  model.extensionsUsed = used;
  model.buffers[0].name = "snell";

  // Everything is written into a folder beside the target and renamed into
  // place, so a failure leaves neither a half file nor a .gltf without its .bin.
  std::filesystem::path target(path);
  std::filesystem::path dir = target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  std::filesystem::path staging = dir / ("." + target.filename().string() + ".partial");
  std::error_code error;
  std::filesystem::remove_all(staging, error);
  std::filesystem::create_directory(staging, error);
  if (error) throw SceneError(path + ": could not write the file: " + error.message());
  std::vector<std::string> written = {target.filename().string()};
  if (!binary) {
    // The buffer goes beside the JSON, named after it; the .gltf refers to it by name.
    model.buffers[0].uri = target.stem().string() + ".bin";
    written.push_back(model.buffers[0].uri);
  }
  tinygltf::TinyGLTF writer;
  bool wrote = writer.WriteGltfSceneToFile(&model, (staging / target.filename()).string(), binary, binary, !binary, binary);
  // The .bin first: a .gltf never appears before the buffer it names.
  for (auto name = written.rbegin(); wrote && name != written.rend(); ++name) {
    std::filesystem::rename(staging / *name, dir / *name, error);
    if (error) break;
  }
  std::error_code ignored;
  std::filesystem::remove_all(staging, ignored);
  if (!wrote) throw SceneError(path + ": could not write the file");
  if (error) throw SceneError(path + ": could not write the file: " + error.message());
}

}  // namespace snell::scene
