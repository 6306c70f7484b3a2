// The public API as a host application uses it (include/snell/snell.h): a
// scene from the host's own vertex buffers that follows the host's
// deformation, and an adopted device rendering into the host's image.
#include "hand_made_device.h"

#include "io/image_compare.h"
#include "io/image_file.h"
#include "scene/evaluate.h"
#include "scene/gltf_writer.h"
#include "scene/procedural_eye.h"
#include "scene/view.h"

#include <snell/snell.h>

#include <gtest/gtest.h>

#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

namespace snell::test {
namespace {

// A host's buffer in mapped, coherent memory: the host writes its deformed
// vertices into it with the CPU (an engine would run its skinning shader).
struct HostBuffer {
  VkDevice device = VK_NULL_HANDLE;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  float* mapped = nullptr;

  HostBuffer(const snell::Device& d, size_t floats, VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT)
      : device(d.device()) {
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = floats * sizeof(float);
    info.usage = usage;
    VK_CHECK(vkCreateBuffer(device, &info, nullptr, &buffer));
    VkMemoryRequirements needs;
    vkGetBufferMemoryRequirements(device, buffer, &needs);
    VkPhysicalDeviceMemoryProperties memoryProperties;
    vkGetPhysicalDeviceMemoryProperties(d.physicalDevice(), &memoryProperties);
    const VkMemoryPropertyFlags wanted = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
    VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    allocate.allocationSize = needs.size;
    for (uint32_t t = 0; t < memoryProperties.memoryTypeCount; ++t) {
      if ((needs.memoryTypeBits >> t & 1) && (memoryProperties.memoryTypes[t].propertyFlags & wanted) == wanted) {
        allocate.memoryTypeIndex = t;
        break;
      }
    }
    VK_CHECK(vkAllocateMemory(device, &allocate, nullptr, &memory));
    VK_CHECK(vkBindBufferMemory(device, buffer, memory, 0));
    void* p = nullptr;
    VK_CHECK(vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &p));
    mapped = static_cast<float*>(p);
  }
  ~HostBuffer() {
    vkDestroyBuffer(device, buffer, nullptr);
    vkFreeMemory(device, memory, nullptr);
  }
};

snell::Mat4 toMat4(const glm::dmat4& m) {
  snell::Mat4 out;
  for (int c = 0; c < 4; ++c) {
    for (int r = 0; r < 4; ++r) out[size_t(4 * c + r)] = float(m[c][r]);
  }
  return out;
}

snell::Vec3 toVec3(const glm::dvec3& v) { return {float(v.x), float(v.y), float(v.z)}; }

// The eye's camera as a look-at, so both scenes are seen from exactly the same place.
snell::View eyeView(const scene::Scene& eye, snell::View::Output output) {
  scene::View v = scene::resolveView(eye, scene::evaluate(eye, 0.0), {});
  snell::View view;
  view.width = 96;
  view.height = 72;
  view.output = output;
  view.camera.eye = toVec3(v.eye);
  view.camera.target = toVec3(v.eye + v.forward);
  view.camera.up = toVec3(v.up);
  view.camera.yfov = float(2.0 * std::atan(v.halfHeight));
  return view;
}

// The procedural eye as a host would hand it over: every drawn item a mesh
// of its own in the host's buffers, its materials, texture and lights.
struct HostEye {
  scene::Scene eye = scene::makeEye({.resolution = 24});
  std::vector<uint32_t> first;  ///< per item: its first vertex in the host's buffers
  uint32_t vertices = 0;
  std::unique_ptr<HostBuffer> positions, normals;
  snell::HostScene host;

  explicit HostEye(const snell::Device& device) {
    scene::Pose pose = scene::evaluate(eye, 0.0);
    for (const scene::DrawItem& item : pose.items) {
      first.push_back(vertices);
      vertices += uint32_t(eye.shapes[size_t(item.shape)].vertexCount());
    }
    positions = std::make_unique<HostBuffer>(device, size_t(vertices) * 3);
    normals = std::make_unique<HostBuffer>(device, size_t(vertices) * 3);
    host.name = "host eye";
    host.positions = positions->buffer;
    host.normals = normals->buffer;
    host.vertexCapacity = vertices;
    for (const scene::Texture& t : eye.textures) host.textures.push_back({t.name, t.width, t.height, t.rgba});
    for (const scene::Material& m : eye.materials) {
      snell::Material out;
      out.name = m.name;
      out.baseColor = {m.baseColorFactor.r, m.baseColorFactor.g, m.baseColorFactor.b, m.baseColorFactor.a};
      out.baseColorTexture = m.baseColorTexture.texture;
      out.transmission = m.transmission;
      out.ior = m.ior;
      out.roughness = m.roughness;
      out.doubleSided = m.doubleSided;
      host.materials.push_back(out);
    }
    for (size_t i = 0; i < pose.items.size(); ++i) {
      const scene::Shape& shape = eye.shapes[size_t(pose.items[i].shape)];
      snell::Mesh mesh;
      mesh.name = shape.name;
      mesh.firstVertex = first[i];
      mesh.vertexCount = uint32_t(shape.vertexCount());
      mesh.indices = shape.indices;
      for (const glm::vec2& uv : shape.texcoords0) mesh.texcoords.insert(mesh.texcoords.end(), {uv.x, uv.y});
      mesh.material = shape.material;
      host.meshes.push_back(mesh);
      host.instances.push_back({int(i), toMat4(pose.items[i].world)});
    }
    for (size_t n = 0; n < eye.nodes.size(); ++n) {
      if (eye.nodes[n].light < 0) continue;
      const scene::Light& l = eye.lights[size_t(eye.nodes[n].light)];
      snell::Light light;
      light.type = l.type == scene::LightType::Directional ? snell::Light::Type::Directional
                   : l.type == scene::LightType::Point     ? snell::Light::Type::Point
                                                           : snell::Light::Type::Spot;
      light.color = {l.color.r, l.color.g, l.color.b};
      light.intensity = l.intensity;
      light.position = toVec3(glm::dvec3(pose.world[n][3]));
      light.direction = toVec3(-glm::dvec3(pose.world[n][2]));
      light.innerConeAngle = l.innerConeAngle;
      light.outerConeAngle = l.outerConeAngle;
      host.lights.push_back(light);
    }
  }

  // What the host does each frame: deform every item on its own and write the
  // vertices into its buffers; then it tells the renderer what moved.
  void deformTo(double time, snell::Renderer& renderer) {
    scene::Pose pose = scene::evaluate(eye, time);
    for (size_t i = 0; i < pose.items.size(); ++i) {
      std::vector<glm::dvec3> p, n;
      scene::deformOnCpu(pose.items[i], p, n);
      for (size_t v = 0; v < p.size(); ++v) {
        glm::dvec3 unit = glm::length(n[v]) > 0.0 ? glm::normalize(n[v]) : n[v];
        for (int c = 0; c < 3; ++c) {
          positions->mapped[3 * (first[i] + v) + size_t(c)] = float(p[v][c]);
          normals->mapped[3 * (first[i] + v) + size_t(c)] = float(unit[c]);
        }
      }
      renderer.setTransform(i, toMat4(pose.items[i].world));
      renderer.markDirty(int(i));
    }
  }
};

// Two of the API's RGBA float images of `view` compared as PNGs would hold
// them, by the comparator every image test uses (io/image_compare.h).
io::ImageDifference compare(const snell::View& view, const std::vector<float>& want, const std::vector<float>& got) {
  auto srgb = [&](const std::vector<float>& rgba) {
    io::LinearImage image{view.width, view.height, {}, {}};
    for (size_t p = 0; p + 3 < rgba.size(); p += 4) image.rgba.emplace_back(rgba[p], rgba[p + 1], rgba[p + 2], rgba[p + 3]);
    return io::toSrgb8(image);
  };
  return io::compareImages(srgb(got), srgb(want));
}

TEST(Embedding, HostBufferMeshesFollowTheHostsDeformationLikeTheGltfMorphAndSkin) {
  snell::Device device = snell::Device::create({.validation = true, .synchronizationValidation = true});
  HostEye hostEye(device);
  std::filesystem::path glb = std::filesystem::temp_directory_path() / "snell-embedding-eye.glb";
  scene::saveGltf(hostEye.eye, glb.string());

  snell::Scene fromFile = snell::Scene::load(glb.string());
  snell::Scene fromHost = snell::Scene::fromHost(hostEye.host);
  snell::Renderer fileRenderer(device, fromFile);
  snell::Renderer hostRenderer(device, fromHost);
  ASSERT_EQ(hostRenderer.instanceCount(), fileRenderer.instanceCount());
  // The clip squashes (a morph) and turns the eye (a skin) over these times.
  std::vector<float> first;
  for (double time : {0.0, 0.9, 1.7}) {
    for (snell::View::Output output : {snell::View::Output::Trace, snell::View::Output::Viewport}) {
      snell::View view = eyeView(hostEye.eye, output);
      fileRenderer.setTime(time);
      std::vector<float> expected = fileRenderer.read(view);
      if (first.empty()) first = expected;
      if (time > 0 && output == snell::View::Output::Trace) {
        EXPECT_GT(compare(view, first, expected).over1, 50u) << "the eye hardly moved: the test would not see a host that stands still";
      }
      hostEye.deformTo(time, hostRenderer);
      std::vector<float> got = hostRenderer.read(view);
      if (output == snell::View::Output::Trace) {
        EXPECT_GE(hostRenderer.lastFrame().treesRefit, time > 0 ? 1u : 0u);
      }
      // Float deformation on the host against the deform pass's: the same to
      // rounding, so a few silhouette pixels at most may flip.
      io::ImageDifference d = compare(view, expected, got);
      EXPECT_LE(d.over1, 3u) << "time " << time << (output == snell::View::Output::Trace ? " trace" : " viewport")
                             << ": largest difference " << d.maximum << "/255";
      std::printf("time %.1f %s: %llu of %llu pixels over 1/255, largest %d/255\n", time,
                  output == snell::View::Output::Trace ? "trace" : "viewport", (unsigned long long)d.over1,
                  (unsigned long long)d.pixels, d.maximum);
    }
  }
  EXPECT_EQ(device.validationMessages(), 0u);
  std::filesystem::remove(glb);
}

// A subdivision cage (a cube, Catmull-Clark, level 2) and a plain floor, as
// a host gives them: in its own buffers, or as vertex lists snell keeps.
snell::HostScene cageAndFloor(const float* cage, const float* floor) {
  snell::HostScene host;
  host.name = "cage and floor";
  snell::Material glass;
  glass.transmission = 1.0f;
  glass.ior = 1.5f;
  host.materials = {glass, snell::Material{}};
  snell::Mesh floorMesh;
  floorMesh.name = "floor";
  floorMesh.vertexCount = 4;
  floorMesh.indices = {0, 1, 2, 0, 2, 3};
  floorMesh.material = 1;
  snell::Mesh cube;
  cube.name = "cube";
  cube.firstVertex = 4;
  cube.vertexCount = 8;
  cube.indices = {0, 4, 6, 2, 1, 3, 7, 5, 0, 1, 5, 4, 2, 6, 7, 3, 0, 2, 3, 1, 4, 5, 7, 6};
  cube.material = 0;
  cube.subdivision.scheme = snell::Subdivision::Scheme::CatmullClark;
  cube.subdivision.faceVertexCounts.assign(6, 4);
  cube.subdivision.normals = snell::Subdivision::Normals::Mesh;
  host.meshes = {floorMesh, cube};
  host.instances = {{0, snell::kIdentity}, {1, snell::kIdentity}};
  if (cage) {  // kept: snell's own copy
    host.vertices = {{std::vector<float>(floor, floor + 12), std::vector<float>(12, 0.0f)},
                     {std::vector<float>(cage, cage + 24), {}}};
    for (size_t v = 0; v < 4; ++v) host.vertices[0].normals[3 * v + 1] = 1.0f;
  }
  return host;
}

// cageAndFloor's vertices, at rest, in buffers of the host's.
struct CageAndFloorBuffers {
  float cage[24], floor[12] = {-2, -0.8f, -2, 2, -0.8f, -2, 2, -0.8f, 2, -2, -0.8f, 2};
  HostBuffer positions, normals;
  snell::HostScene scene = cageAndFloor(nullptr, nullptr);

  explicit CageAndFloorBuffers(const snell::Device& device) : positions(device, 12 * 3), normals(device, 12 * 3) {
    for (int i = 0; i < 8; ++i) {
      for (int c = 0; c < 3; ++c) cage[3 * i + c] = (i >> c & 1) ? 0.5f : -0.5f;
    }
    std::memcpy(positions.mapped, floor, sizeof floor);
    std::memcpy(positions.mapped + 12, cage, sizeof cage);
    for (int v = 0; v < 12; ++v) {
      normals.mapped[3 * v] = 0, normals.mapped[3 * v + 1] = v < 4 ? 1.0f : 0.0f, normals.mapped[3 * v + 2] = 0;
    }
    scene.positions = positions.buffer;
    scene.normals = normals.buffer;
    scene.vertexCapacity = 12;
  }
};

snell::View cageView() {
  snell::View view;
  view.width = 80;
  view.height = 60;
  view.output = snell::View::Output::Trace;
  view.camera.eye = {1.2f, 1.0f, 2.4f};
  return view;
}

TEST(Embedding, ASubdivisionCageInTheHostsBuffersDrawsAsTheSameCageKeptBySnell) {
  snell::Device device = snell::Device::create({.validation = true, .synchronizationValidation = true});
  CageAndFloorBuffers buffers(device);
  HostBuffer& positions = buffers.positions;
  snell::Scene hostScene = snell::Scene::fromHost(buffers.scene);
  snell::Scene keptScene = snell::Scene::fromHost(cageAndFloor(buffers.cage, buffers.floor));
  EXPECT_EQ(hostScene.vertexCount(1), 8u);
  EXPECT_EQ(hostScene.drawnVertexCount(1), 98u);
  snell::Renderer hostRenderer(device, hostScene), keptRenderer(device, keptScene);
  const snell::View view = cageView();
  std::vector<float> before;
  for (int frame = 0; frame < 2; ++frame) {
    if (frame == 1) {  // the host squashes its cage; snell refines it again
      for (int v = 0; v < 8; ++v) positions.mapped[12 + 3 * v + 1] *= 0.5f;
      hostRenderer.markDirty(1);
      snell::Vertices kept = keptRenderer.vertices(1);
      ASSERT_EQ(kept.count, 8u);
      for (int v = 0; v < 8; ++v) kept.positions[3 * v + 1] *= 0.5f;
      keptRenderer.markDirty(1);
    }
    std::vector<float> fromHost = hostRenderer.read(view), fromKept = keptRenderer.read(view);
    EXPECT_EQ(hostRenderer.lastFrame().meshesRefined, 1u) << "frame " << frame;  // the first: everything the host holds
    io::ImageDifference d = compare(view, fromKept, fromHost);
    EXPECT_LE(d.over1, 2u) << "frame " << frame << ": largest difference " << d.maximum << "/255";
    if (frame == 0) before = fromHost;
    if (frame == 1) {
      EXPECT_GT(compare(view, before, fromHost).over1, 100u) << "the squashed cage drew as before";
    }
  }
  EXPECT_EQ(device.validationMessages(), 0u);
}

// snell.h: the refined cage's vertices are snell's, so the floor beside it is
// copied out of the host's buffers, at the first frame and at markDirty.
TEST(Embedding, AHostSceneWithASubdivisionCageCopiesItsOtherMeshesWhenMarkedDirty) {
  snell::Device device = snell::Device::create({.validation = true, .synchronizationValidation = true});
  CageAndFloorBuffers buffers(device);
  buffers.scene.materials[1].emissive = {0.8f, 0.8f, 0.8f};  // a floor seen without lights, from above
  buffers.scene.materials[1].doubleSided = true;
  snell::Scene scene = snell::Scene::fromHost(buffers.scene);
  snell::Renderer renderer(device, scene);
  const snell::View view = cageView();
  const std::vector<float> atRest = renderer.read(view);
  EXPECT_EQ(renderer.lastFrame().meshesUploaded, 2u);  // the first frame takes every mesh
  for (int v = 0; v < 4; ++v) {  // the floor shrinks to a quarter of its width
    buffers.positions.mapped[3 * v] *= 0.25f;
    buffers.positions.mapped[3 * v + 2] *= 0.25f;
  }
  EXPECT_EQ(compare(view, atRest, renderer.read(view)).over1, 0u) << "the host's floor was read in place";
  EXPECT_EQ(renderer.lastFrame().meshesUploaded, 0u);
  renderer.markDirty(0);
  EXPECT_GT(compare(view, atRest, renderer.read(view)).over1, 100u) << "the marked floor was not copied";
  EXPECT_EQ(renderer.lastFrame().meshesUploaded, 1u);
  EXPECT_EQ(renderer.lastFrame().meshesRefined, 0u) << "the cage did not move";
  EXPECT_EQ(device.validationMessages(), 0u);
}

TEST(Embedding, TheApisDefaultBackgroundIsTheRenderersDefault) {
  const snell::Vec3 api = snell::View{}.background;
  for (int c = 0; c < 3; ++c) EXPECT_EQ(api[size_t(c)], float(snell::scene::kDefaultBackground[c])) << "channel " << c;
}

// A quad of two triangles facing the camera, its left triangle one
// material and its right another (Mesh::faceMaterials), its vertices kept.
snell::HostScene twoColourQuad(std::vector<int> faceMaterials) {
  snell::HostScene host;
  host.name = "two-colour quad";
  snell::Material red, green;
  red.emissive = {1, 0, 0}, green.emissive = {0, 1, 0};
  red.baseColor = green.baseColor = {0, 0, 0, 1};  // their own light only
  host.materials = {red, green};
  snell::Mesh quad;
  quad.name = "quad";
  quad.vertexCount = 4;
  quad.indices = {0, 1, 3, 1, 2, 3};  // lower left to upper left; then the right triangle
  quad.material = 0;
  quad.faceMaterials = std::move(faceMaterials);
  host.meshes = {quad};
  host.instances = {{0, snell::kIdentity}};
  host.vertices = {{{-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0}, {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}}};
  return host;
}

TEST(Embedding, AMeshDrawsEachFaceWithItsOwnMaterial) {
  snell::Device device = snell::Device::create({.validation = true});
  snell::Scene scene = snell::Scene::fromHost(twoColourQuad({0, 1}));
  EXPECT_EQ(scene.meshCount(), 1u);
  EXPECT_EQ(scene.drawnTriangleCount(0), 2u);
  snell::Renderer renderer(device, scene);
  snell::View view;
  view.width = view.height = 32;
  view.output = snell::View::Output::Trace;
  const std::vector<float> rgba = renderer.read(view);
  auto pixel = [&](uint32_t x, uint32_t y) { return &rgba[4 * (size_t(y) * view.width + x)]; };
  // Below the diagonal from lower left to upper right lies the left triangle (0, 1, 3).
  EXPECT_GT(pixel(8, 20)[0], 0.9f) << "left triangle";
  EXPECT_LT(pixel(8, 20)[1], 0.1f) << "left triangle";
  EXPECT_GT(pixel(24, 12)[1], 0.9f) << "right triangle";
  EXPECT_LT(pixel(24, 12)[0], 0.1f) << "right triangle";
  EXPECT_EQ(device.validationMessages(), 0u);
}

TEST(Embedding, FaceMaterialsOfTheWrongCountAreRefusedNamingTheMesh) {
  try {
    snell::Scene::fromHost(twoColourQuad({0, 1, 1}));
    FAIL() << "three face materials for two triangles were accepted";
  } catch (const snell::Error& e) {
    EXPECT_NE(std::string(e.what()).find("two-colour quad: mesh 0: 3 face materials for 2 triangles"), std::string::npos) << e.what();
  }
}

TEST(Embedding, HostSceneRefusesAMeshPastItsBuffers) {
  snell::Device device = snell::Device::create({.validation = true});
  HostBuffer buffer(device, 9);
  snell::HostScene host;
  host.positions = host.normals = buffer.buffer;
  host.vertexCapacity = 3;
  host.meshes.push_back({"past the end", 1, 3, {0, 1, 2}, {}, -1});
  host.instances.push_back({0});
  snell::Scene scene = snell::Scene::fromHost(host);
  try {
    snell::Renderer renderer(device, scene);
    FAIL() << "a mesh past the host's buffers was accepted";
  } catch (const snell::Error& e) {
    EXPECT_NE(std::string(e.what()).find("past the host buffers' 3"), std::string::npos) << e.what();
  }
}

TEST(Embedding, LoadingAMissingFileThrowsAnErrorNamingIt) {
  try {
    snell::Scene::load("/no/such/eye.glb");
    FAIL() << "a missing file loaded";
  } catch (const snell::Error& e) {
    EXPECT_NE(std::string(e.what()).find("/no/such/eye.glb"), std::string::npos) << e.what();
  }
}

// What a host's frame loop does: its own device (validation with
// synchronisation on), snell renders into the host's image with a semaphore
// the host's own command buffer waits for; that command buffer reads the image.
TEST(Embedding, AdoptedDeviceRendersIntoTheHostsImageForAHundredFramesWithoutValidationMessages) {
  HandMadeDevice host(true, true);
  snell::HostDevice handles{host.instance, host.physical, host.device, host.family, host.queue, host.features13};
  scene::Scene eye = scene::makeEye({.resolution = 16});
  std::filesystem::path glb = std::filesystem::temp_directory_path() / "snell-embedding-frames.glb";
  scene::saveGltf(eye, glb.string());
  {
    snell::Device device = snell::Device::adopt(handles);
    snell::Scene scene = snell::Scene::load(glb.string());
    snell::Renderer renderer(device, scene);
    snell::View view = eyeView(eye, snell::View::Output::Viewport);
    view.width = 48, view.height = 36;

    // The host's image, its readback buffer, its command buffer, semaphore and fence.
    VkImageCreateInfo imageInfo{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    imageInfo.imageType = VK_IMAGE_TYPE_2D;
    imageInfo.format = VK_FORMAT_R8G8B8A8_SRGB;
    imageInfo.extent = {view.width, view.height, 1};
    imageInfo.mipLevels = imageInfo.arrayLayers = 1;
    imageInfo.samples = VK_SAMPLE_COUNT_1_BIT;
    imageInfo.usage = VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
    VkImage image;
    VK_CHECK(vkCreateImage(host.device, &imageInfo, nullptr, &image));
    VkMemoryRequirements needs;
    vkGetImageMemoryRequirements(host.device, image, &needs);
    VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    allocate.allocationSize = needs.size;
    while (!(needs.memoryTypeBits >> allocate.memoryTypeIndex & 1)) ++allocate.memoryTypeIndex;
    VkDeviceMemory imageMemory;
    VK_CHECK(vkAllocateMemory(host.device, &allocate, nullptr, &imageMemory));
    VK_CHECK(vkBindImageMemory(host.device, image, imageMemory, 0));
    HostBuffer readback(device, size_t(view.width) * view.height, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    poolInfo.queueFamilyIndex = host.family;
    VkCommandPool pool;
    VK_CHECK(vkCreateCommandPool(host.device, &poolInfo, nullptr, &pool));
    VkCommandBufferAllocateInfo cbInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cbInfo.commandPool = pool;
    cbInfo.commandBufferCount = 1;
    VkCommandBuffer cb;
    VK_CHECK(vkAllocateCommandBuffers(host.device, &cbInfo, &cb));
    VkSemaphoreCreateInfo semaphoreInfo{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore rendered;
    VK_CHECK(vkCreateSemaphore(host.device, &semaphoreInfo, nullptr, &rendered));
    VkFenceCreateInfo fenceInfo{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence;
    VK_CHECK(vkCreateFence(host.device, &fenceInfo, nullptr, &fence));

    size_t changedFrames = 0;
    std::vector<uint8_t> previous;
    for (int frame = 0; frame < 100; ++frame) {
      renderer.setTime(0.04 * frame);
      VkImageLayout before = frame == 0 ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
      snell::Target target{image, imageInfo.format, view.width, view.height, before, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
      renderer.render(view, target, {.signal = rendered});

      VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
      begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
      VK_CHECK(vkBeginCommandBuffer(cb, &begin));
      VkBufferImageCopy region{};
      region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
      region.imageExtent = {view.width, view.height, 1};
      vkCmdCopyImageToBuffer(cb, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.buffer, 1, &region);
      VkMemoryBarrier toHost{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
      toHost.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
      toHost.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
      vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &toHost, 0, nullptr,
                           0, nullptr);
      VK_CHECK(vkEndCommandBuffer(cb));
      VkPipelineStageFlags waitStage = VK_PIPELINE_STAGE_TRANSFER_BIT;
      VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
      submit.waitSemaphoreCount = 1;
      submit.pWaitSemaphores = &rendered;
      submit.pWaitDstStageMask = &waitStage;
      submit.commandBufferCount = 1;
      submit.pCommandBuffers = &cb;
      VK_CHECK(vkQueueSubmit(host.queue, 1, &submit, fence));
      VK_CHECK(vkWaitForFences(host.device, 1, &fence, VK_TRUE, UINT64_MAX));
      VK_CHECK(vkResetFences(host.device, 1, &fence));
      const auto* bytes = reinterpret_cast<const uint8_t*>(readback.mapped);
      std::vector<uint8_t> pixels(bytes, bytes + size_t(view.width) * view.height * 4);
      if (!previous.empty() && pixels != previous) ++changedFrames;
      previous = std::move(pixels);
    }
    device.waitIdle();
    EXPECT_GT(changedFrames, 50u) << "the host's image should follow the animation";
    vkDestroyFence(host.device, fence, nullptr);
    vkDestroySemaphore(host.device, rendered, nullptr);
    vkDestroyCommandPool(host.device, pool, nullptr);
    vkDestroyImage(host.device, image, nullptr);
    vkFreeMemory(host.device, imageMemory, nullptr);
  }
  EXPECT_EQ(host.validationMessages, 0);
  std::filesystem::remove(glb);
}

// What an OpenGL host imports: the image's memory and, where the device can
// export them, semaphores that chain frames without a host wait.
TEST(Embedding, SharedImageAndSemaphoresExportFileDescriptorsAndChainFrames) {
  scene::Scene eye = scene::makeEye({.resolution = 16});
  std::filesystem::path glb = std::filesystem::temp_directory_path() / "snell-embedding-shared.glb";
  scene::saveGltf(eye, glb.string());
  snell::Device device = snell::Device::create({.interop = true});
  snell::Scene scene = snell::Scene::load(glb.string());
  std::filesystem::remove(glb);
  snell::Renderer renderer(device, scene);
  snell::View view = eyeView(eye, snell::View::Output::Viewport);
  snell::SharedImage shared(device, view.width, view.height);
  int memoryFd = shared.exportMemory();
  EXPECT_GE(fcntl(memoryFd, F_GETFD), 0);
  EXPECT_GE(shared.memorySize(), uint64_t(view.width) * view.height * 4);
  close(memoryFd);
  if (!device.exportsSemaphores()) {
    renderer.wait(renderer.render(view, shared.target(VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL)));
    GTEST_SKIP() << device.name() << " cannot export semaphores (VK_KHR_external_semaphore_fd); the image was checked";
  }
  snell::SharedSemaphore chain(device);
  int semaphoreFd = chain.exportFd();
  EXPECT_GE(fcntl(semaphoreFd, F_GETFD), 0);
  close(semaphoreFd);
  // Each frame waits for the one before through the semaphore, then signals it.
  uint64_t last = 0;
  for (int frame = 0; frame < 10; ++frame) {
    renderer.setTime(0.1 * frame);
    VkImageLayout before = frame == 0 ? VK_IMAGE_LAYOUT_UNDEFINED : VK_IMAGE_LAYOUT_GENERAL;
    snell::Sync sync{frame == 0 ? VK_NULL_HANDLE : chain.handle(), VK_PIPELINE_STAGE_TRANSFER_BIT,
                     frame == 9 ? VK_NULL_HANDLE : chain.handle()};
    last = renderer.render(view, shared.target(before, VK_IMAGE_LAYOUT_GENERAL), sync);
  }
  renderer.wait(last);
  EXPECT_EQ(device.validationMessages(), 0u);
}

// Two renderers on one device, each on its own thread, as two viewports of a
// host might: the device's lock makes them take turns, and each thread's
// images are those a lone renderer makes.
TEST(Embedding, TwoRenderersOnOneDeviceRenderFromTwoThreads) {
  scene::Scene eye = scene::makeEye({.resolution = 16});
  std::filesystem::path glb = std::filesystem::temp_directory_path() / "snell-embedding-threads.glb";
  scene::saveGltf(eye, glb.string());
  snell::Device device = snell::Device::create();
  snell::Scene scene = snell::Scene::load(glb.string());
  std::filesystem::remove(glb);
  snell::View view = eyeView(eye, snell::View::Output::Viewport);
  view.width = 48, view.height = 36;
  constexpr int kFrames = 12;
  auto renderAll = [&](std::vector<std::vector<float>>& images) {
    snell::Renderer renderer(device, scene);
    for (int frame = 0; frame < kFrames; ++frame) {
      renderer.setTime(0.1 * frame);
      images.push_back(renderer.read(view));
    }
  };
  std::vector<std::vector<float>> alone, first, second;
  renderAll(alone);
  std::thread a([&] { renderAll(first); }), b([&] { renderAll(second); });
  a.join();
  b.join();
  ASSERT_EQ(first.size(), size_t(kFrames));
  ASSERT_EQ(second.size(), size_t(kFrames));
  for (int frame = 0; frame < kFrames; ++frame) {
    EXPECT_EQ(first[frame], alone[frame]) << "frame " << frame;
    EXPECT_EQ(second[frame], alone[frame]) << "frame " << frame;
  }
  EXPECT_EQ(device.validationMessages(), 0u);
}

}  // namespace
}  // namespace snell::test
