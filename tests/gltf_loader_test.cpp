// glTF loading: every sample model loads and reads as the file says; every
// malformed file is refused with a message that names it; damaged copies of
// good files never crash the loader.
#include "assets.h"

#include "scene/gltf_loader.h"
#include "scene/scene_summary.h"
#include "scene/texture_mips.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <fstream>
#include <random>
#include <set>
#include <thread>

namespace snell::test {
namespace {

using scene::loadGltf;
using scene::Scene;
using scene::SceneError;

std::vector<std::string> validModels() {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(assetsDir() / "gltf")) {
    std::string ext = entry.path().extension().string();
    if ((ext == ".glb" || ext == ".gltf") && entry.path().string().find("IridescenceSuzanne") == std::string::npos) {
      files.push_back(entry.path().string());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::vector<std::string> invalidModels() {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(assetsDir() / "gltf-invalid")) {
    std::string ext = entry.path().extension().string();
    if (ext == ".glb" || ext == ".gltf") files.push_back(entry.path().string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

std::string testName(const std::string& path) {
  std::string name = std::filesystem::relative(path, assetsDir()).string();
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

class EveryValidModel : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryValidModel, LoadsWithTrianglesAndFiniteGeometry) {
  Scene scene = loadGltf(GetParam());
  scene::SceneSummary summary = scene::summarize(scene);
  EXPECT_GT(summary.triangles, 0u);
  for (const scene::Shape& shape : scene.shapes) {
    EXPECT_EQ(shape.normals.size(), shape.positions.size());
    EXPECT_EQ(shape.indices.size() % 3, 0u);
    for (uint32_t index : shape.indices) ASSERT_LT(index, shape.vertexCount());
    for (const glm::vec3& p : shape.positions) ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  }
}

INSTANTIATE_TEST_SUITE_P(Assets, EveryValidModel, ::testing::ValuesIn(validModels()),
                         [](const auto& info) { return testName(info.param); });

class EveryInvalidModel : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryInvalidModel, IsRefusedWithAMessageThatNamesTheFile) {
  try {
    loadGltf(GetParam());
    FAIL() << "loaded a file the Khronos validator rejects";
  } catch (const SceneError& e) {
    std::string message = e.what();
    EXPECT_EQ(message.rfind(GetParam() + ": ", 0), 0u) << message;
    EXPECT_GT(message.size(), GetParam().size() + 10) << "no reason given: " << message;
  }
}

INSTANTIATE_TEST_SUITE_P(Assets, EveryInvalidModel, ::testing::ValuesIn(invalidModels()),
                         [](const auto& info) { return testName(info.param); });

TEST(GltfLoader, CountsMatchTheSampleModels) {
  EXPECT_EQ(scene::summarize(loadGltf(model("SimpleInstancing/glTF-Binary/SimpleInstancing.glb"))).instances, 125u);
  Scene skeletons = loadGltf(model("RecursiveSkeletons/glTF-Binary/RecursiveSkeletons.glb"));
  EXPECT_EQ(skeletons.nodes.size(), 924u);
  EXPECT_EQ(skeletons.skins.size(), 84u);
  EXPECT_EQ(loadGltf(model("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf")).lights.size(), 5u);
  EXPECT_EQ(loadGltf(model("InterpolationTest/glTF-Binary/InterpolationTest.glb")).animations.size(), 9u);
  Scene triangle = loadGltf(model("TriangleWithoutIndices/glTF/TriangleWithoutIndices.gltf"));
  ASSERT_EQ(triangle.shapes.size(), 1u);
  EXPECT_EQ(triangle.shapes[0].triangleCount(), 1u);
}

TEST(GltfLoader, ReadsPerspectiveAndOrthographicCameras) {
  Scene scene = loadGltf(model("Cameras/glTF/Cameras.gltf"));
  ASSERT_EQ(scene.cameras.size(), 2u);
  EXPECT_FALSE(scene.cameras[0].orthographic);
  EXPECT_TRUE(scene.cameras[1].orthographic);
}

TEST(GltfLoader, UsesTheDefaultSceneUnlessAnotherIsChosen) {
  std::string path = model("MultipleScenes/glTF/MultipleScenes.gltf");
  Scene byDefault = loadGltf(path);
  Scene first = loadGltf(path, {"0", {}});
  EXPECT_NE(byDefault.roots, first.roots);  // the file's default scene is 1
  EXPECT_EQ(byDefault.roots, loadGltf(path, {"1", {}}).roots);
  EXPECT_THROW(loadGltf(path, {"no such scene", {}}), SceneError);
}

TEST(GltfLoader, ReadsTransmissionAndIorOfEveryMaterial) {
  Scene scene = loadGltf(model("TransmissionRoughnessTest/glTF-Binary/TransmissionRoughnessTest.glb"));
  std::set<float> iors;
  for (const scene::Material& m : scene.materials) {
    if (m.refractive()) iors.insert(m.ior);
  }
  for (float expected : {1.0f, 1.33f, 1.76f, 2.42f}) EXPECT_TRUE(iors.count(expected)) << "IOR " << expected;
}

TEST(GltfLoader, ConvertsStripsAndFansAndSkipsPointsAndLinesWithOneNote) {
  Scene scene = loadGltf(model("MeshPrimitiveModes/glTF/MeshPrimitiveModes.gltf"));
  EXPECT_EQ(scene.shapes.size(), 3u);  // triangles, strip, fan
  for (const scene::Shape& shape : scene.shapes) EXPECT_GT(shape.triangleCount(), 0u);
  size_t notes = std::count_if(scene.warnings.begin(), scene.warnings.end(),
                               [](const std::string& w) { return w.find("point or line") != std::string::npos; });
  EXPECT_EQ(notes, 1u);
}

TEST(GltfLoader, AppliesSparseAccessors) {
  // The file's POSITION accessor gives max (6, 4, 0) only once its sparse values are applied.
  Scene scene = loadGltf(model("SimpleSparseAccessor/glTF/SimpleSparseAccessor.gltf"));
  float maxY = 0.0f;
  for (const glm::vec3& p : scene.shapes.at(0).positions) maxY = std::max(maxY, p.y);
  EXPECT_FLOAT_EQ(maxY, 4.0f);
}

TEST(GltfLoader, DecodesTexturesBehindUrisWithSpaces) {
  Scene scene = loadGltf(model("BoxWithSpaces/glTF/Box With Spaces.gltf"));
  ASSERT_FALSE(scene.textures.empty());
  for (const scene::Texture& t : scene.textures) {
    EXPECT_GT(t.width, 0u);
    EXPECT_EQ(t.rgba.size(), size_t(t.width) * t.height * 4);
  }
}

TEST(GltfLoader, DecodesImagesOnEveryCoreAndSaysHowLongItTook) {
  Scene scene = loadGltf(model("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf"));
  ASSERT_FALSE(scene.textures.empty());
  for (const scene::Texture& t : scene.textures) EXPECT_EQ(t.rgba.size(), size_t(t.width) * t.height * 4) << t.name;
  unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  EXPECT_EQ(scene.loadTimes.decodeThreads, std::min<unsigned>(cores, unsigned(scene.textures.size())));
  EXPECT_GT(scene.loadTimes.decodeSeconds, 0.0);
  EXPECT_GT(scene.loadTimes.parseSeconds, 0.0);
}

TEST(GltfLoader, ATextureBudgetLoadsTheLargestTexturesAtALowerMipWithANote) {
  const std::string lamp = model("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf");
  scene::LoadOptions options;
  options.textureBudget = 16ull << 20;
  Scene full = loadGltf(lamp), fitted = loadGltf(lamp, options);
  ASSERT_GT(scene::textureChainBytes(full), options.textureBudget) << "the model no longer tests the budget";
  EXPECT_LE(scene::textureChainBytes(fitted), options.textureBudget);
  size_t smaller = 0;
  for (size_t i = 0; i < full.textures.size(); ++i) {
    const scene::Texture &a = full.textures[i], &b = fitted.textures[i];
    if (a.width == b.width && a.height == b.height) continue;
    ++smaller;
    int level = std::countr_zero(a.width / b.width);
    EXPECT_EQ(b.width, std::max(a.width >> level, 1u)) << a.name;  // a mip level of the original
    EXPECT_EQ(b.height, std::max(a.height >> level, 1u)) << a.name;
  }
  size_t notes = std::count_if(fitted.warnings.begin(), fitted.warnings.end(),
                               [](const std::string& w) { return w.find("texture budget of 16.0 MiB") != std::string::npos; });
  EXPECT_GT(smaller, 0u);
  EXPECT_EQ(notes, smaller);
}

TEST(GltfLoader, ATextureBudgetNoMipLevelMeetsIsAClearError) {
  scene::LoadOptions options;
  options.textureBudget = 1;
  try {
    loadGltf(model("LightsPunctualLamp/glTF/LightsPunctualLamp.gltf"), options);
    FAIL() << "a 1-byte texture budget was met";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("LightsPunctualLamp.gltf"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("even at 1x1; the texture budget is 0.0 MiB"), std::string::npos) << e.what();
  }
}

TEST(GltfLoader, UnknownRequiredExtensionIsAnErrorThatNamesIt) {
  std::string path = model("IridescenceSuzanne/glTF-Binary/IridescenceSuzanne.glb");
  try {
    loadGltf(path);
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("KHR_materials_iridescence"), std::string::npos) << e.what();
  }
  Scene anyway = loadGltf(path, {"", {"KHR_materials_iridescence"}});
  EXPECT_EQ(anyway.lights.size(), 1u);
}

TEST(GltfLoader, UnknownOptionalExtensionIsIgnoredWithANote) {
  Scene scene = loadGltf(model("TransmissionTest/glTF-Binary/TransmissionTest.glb"));
  EXPECT_TRUE(std::any_of(scene.warnings.begin(), scene.warnings.end(),
                          [](const std::string& w) { return w.find("KHR_xmp") != std::string::npos; }));
}

TEST(GltfLoader, MissingTextureFallsBackToTheFactorWithAWarning) {
  auto dir = scratchDir("missing-texture");
  std::filesystem::path source = model("BoxWithSpaces/glTF");
  for (const char* file : {"Box With Spaces.gltf", "Box With Spaces.bin"}) std::filesystem::copy(source / file, dir / file);
  Scene scene = loadGltf((dir / "Box With Spaces.gltf").string());  // no images copied
  EXPECT_FALSE(scene.warnings.empty());
  for (const scene::Material& m : scene.materials) EXPECT_FALSE(m.baseColorTexture.present());
}

std::string base64(const std::vector<float>& floats) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = reinterpret_cast<const unsigned char*>(floats.data());
  size_t n = floats.size() * 4;
  std::string out;
  for (size_t i = 0; i < n; i += 3) {
    uint32_t v = uint32_t(p[i]) << 16;
    if (i + 1 < n) v |= uint32_t(p[i + 1]) << 8;
    if (i + 2 < n) v |= p[i + 2];
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < n ? kAlphabet[(v >> 6) & 63] : '=';
    out += i + 2 < n ? kAlphabet[v & 63] : '=';
  }
  return out;
}

/// Writes a .gltf whose one buffer (standing for @BUFFER@) is embedded as a data URI.
std::string writeGltf(const std::filesystem::path& file, const std::string& json, const std::vector<float>& floats) {
  std::string text = json;
  std::string key = "@BUFFER@";
  text.replace(text.find(key), key.size(),
               "{\"byteLength\": " + std::to_string(floats.size() * 4) +
                   ", \"uri\": \"data:application/octet-stream;base64," + base64(floats) + "\"}");
  std::ofstream(file) << text;
  return file.string();
}

constexpr const char* kTriangle = R"({"asset": {"version": "2.0"}, "buffers": [@BUFFER@],
  "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]})";

TEST(GltfLoader, ALightOfAnUnknownTypeIsLeftOutWithANoteAndTheOthersKeepTheirNodes) {
  auto dir = scratchDir("unknown-light");
  std::string json = kTriangle;
  json.replace(json.find(R"("nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}])"),
               std::string(R"("nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}])").size(),
               R"("extensionsUsed": ["KHR_lights_punctual"],
                  "extensions": {"KHR_lights_punctual": {"lights": [{"type": "area", "name": "panel"},
                                                                     {"type": "point", "intensity": 5}]}},
                  "nodes": [{"mesh": 0}, {"extensions": {"KHR_lights_punctual": {"light": 0}}},
                            {"extensions": {"KHR_lights_punctual": {"light": 1}}}],
                  "scenes": [{"nodes": [0, 1, 2]}])");
  Scene scene = loadGltf(writeGltf(dir / "lights.gltf", json, {0, 0, 0, 1, 0, 0, 0, 1, 0}));
  ASSERT_EQ(scene.lights.size(), 1u) << "the area light is left out";
  EXPECT_EQ(scene.lights[0].type, scene::LightType::Point);
  EXPECT_EQ(scene.nodes[1].light, -1) << "its node carries no light";
  EXPECT_EQ(scene.nodes[2].light, 0) << "the point light's node finds it";
  EXPECT_TRUE(std::any_of(scene.warnings.begin(), scene.warnings.end(), [](const std::string& w) {
    return w.find("light 0 'panel'") != std::string::npos && w.find("'area'") != std::string::npos;
  }));
}

TEST(GltfLoader, ATextureOnAUvSetBeyondTheSecondReadsTheFirstWithANote) {
  auto dir = scratchDir("third-uv-set");
  std::string json = kTriangle;
  json.replace(json.find(R"("meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}])"),
               std::string(R"("meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}])").size(),
               R"("meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "material": 0}]}],
                  "materials": [{"name": "painted", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 2}}}],
                  "textures": [{"source": 0}],
                  "images": [{"uri": "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJggg=="}])");
  Scene scene = loadGltf(writeGltf(dir / "uv2.gltf", json, {0, 0, 0, 1, 0, 0, 0, 1, 0}));
  ASSERT_EQ(scene.materials.size(), 1u);
  EXPECT_TRUE(scene.materials[0].baseColorTexture.present());
  EXPECT_EQ(scene.materials[0].baseColorTexture.texCoord, 0);
  EXPECT_TRUE(std::any_of(scene.warnings.begin(), scene.warnings.end(), [](const std::string& w) {
    return w.find("TEXCOORD_2") != std::string::npos && w.find("reads set 0") != std::string::npos;
  }));
}

TEST(GltfLoader, NanPositionIsAnErrorThatNamesTheAttribute) {
  auto dir = scratchDir("nan");
  std::string path = writeGltf(dir / "nan.gltf", kTriangle, {0, 0, 0, 1, 0, 0, std::nanf(""), 1, 0});
  try {
    loadGltf(path);
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("POSITION has a NaN or infinite value"), std::string::npos) << e.what();
  }
  std::string fine = writeGltf(dir / "fine.gltf", kTriangle, {0, 0, 0, 1, 0, 0, 0, 1, 0});
  EXPECT_EQ(loadGltf(fine).shapes.at(0).triangleCount(), 1u);
}

TEST(GltfLoader, JointIndexBeyondTheSkinIsAnError) {
  // Joint 5 on a skin of one joint.
  constexpr const char* kSkinned = R"({"asset": {"version": "2.0"}, "buffers": [@BUFFER@],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 48},
                    {"buffer": 0, "byteOffset": 84, "byteLength": 48}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                  {"bufferView": 1, "componentType": 5125, "count": 3, "type": "VEC4"},
                  {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC4"}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2}}]}],
    "skins": [{"joints": [1]}],
    "nodes": [{"mesh": 0, "skin": 0}, {}], "scenes": [{"nodes": [0, 1]}]})";
  std::vector<float> data = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  for (int v = 0; v < 3; ++v) {
    uint32_t joints[4] = {5, 0, 0, 0};
    for (uint32_t j : joints) data.push_back(std::bit_cast<float>(j));
  }
  for (int v = 0; v < 3; ++v) data.insert(data.end(), {1, 0, 0, 0});
  std::string path = writeGltf(scratchDir("joints") / "joints.gltf", kSkinned, data);
  try {
    loadGltf(path);
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("joint 5"), std::string::npos) << e.what();
  }
}

std::vector<char> readBytes(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), {}};
}

TEST(GltfLoader, TruncatedCopiesAreRefusedCleanly) {
  auto dir = scratchDir("truncated");
  for (const char* name : {"SimpleMorph/glTF/SimpleMorph.gltf", "RiggedSimple/glTF-Binary/RiggedSimple.glb",
                           "AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb"}) {
    std::vector<char> bytes = readBytes(model(name));
    std::string ext = std::filesystem::path(name).extension().string();
    for (double fraction : {0.0, 0.01, 0.1, 0.5, 0.9}) {
      std::string path = (dir / ("cut" + ext)).string();
      std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(static_cast<double>(bytes.size()) * fraction));
      EXPECT_THROW(loadGltf(path), SceneError) << name << " cut at " << fraction;
    }
  }
}

TEST(GltfLoader, ByteFlippedCopiesLoadOrFailCleanly) {
  // Many flips land in float data and leave a valid file; the rule is only that
  // nothing but a SceneError ever comes out (ASan builds also check the reads).
  auto dir = scratchDir("flipped");
  std::mt19937 random(1234);
  for (const char* name : {"RiggedSimple/glTF-Binary/RiggedSimple.glb", "AnimatedMorphCube/glTF-Binary/AnimatedMorphCube.glb",
                           "SimpleSparseAccessor/glTF-Embedded/SimpleSparseAccessor.gltf", "Cameras/glTF-Embedded/Cameras.gltf"}) {
    std::string source = model(name);
    if (!std::filesystem::exists(source)) continue;
    std::vector<char> original = readBytes(source);
    std::string path = (dir / ("flipped" + std::filesystem::path(name).extension().string())).string();
    int refused = 0;
    for (int trial = 0; trial < 150; ++trial) {
      std::vector<char> bytes = original;
      for (int f = 0; f < 1 + trial % 4; ++f) bytes[random() % bytes.size()] ^= static_cast<char>(1 << (random() % 8));
      std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      try {
        loadGltf(path);
      } catch (const SceneError&) {
        ++refused;
      }
    }
    RecordProperty(std::string("refused_") + std::filesystem::path(name).stem().string(), refused);
  }
}

// Found by the fuzzer (tests/fuzz/regressions): tinygltf passed the image on
// without checking its view, and the loader read past the binary chunk.
TEST(GltfLoader, GlbImageWhoseViewRunsPastItsBufferIsRefusedBeforeItIsRead) {
  std::string json =
      R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":4}],)"
      R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":100000}],)"
      R"("images":[{"bufferView":0,"mimeType":"image/png"}]})";
  while (json.size() % 4) json += ' ';
  auto u32 = [](std::string& out, uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  std::string glb = "glTF";
  u32(glb, 2);
  u32(glb, uint32_t(12 + 8 + json.size() + 8 + 4));
  u32(glb, uint32_t(json.size()));
  glb += "JSON" + json;
  u32(glb, 4);
  glb += std::string("BIN\0", 4) + std::string("\x89PNG", 4);
  std::filesystem::path file = std::filesystem::temp_directory_path() / "snell_image_view_past_buffer.glb";
  std::ofstream(file, std::ios::binary) << glb;
  try {
    loadGltf(file.string());
    ADD_FAILURE() << "the file loaded";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("bufferView lies outside its buffer"), std::string::npos) << e.what();
  }
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace snell::test
