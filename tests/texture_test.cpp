// Textures on the GPU: texel pages hold more than one storage buffer can, and
// each mip level is the one trace.h and the reference state.
#include "golden_support.h"
#include "gpu_test.h"

#include "cli/image_file.h"
#include "render/renderer.h"
#include "render/scene_gpu.h"
#include "scene/evaluate.h"
#include "scene/view.h"
#include "vk/commands.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace snell::test {
namespace {

// A self-lit checker of 64-texel cells, its two colours set by `seed`.
scene::Texture checker(uint32_t size, uint32_t seed) {
  scene::Texture t;
  t.name = "checker " + std::to_string(seed);
  t.width = t.height = size;
  t.rgba.resize(size_t(size) * size * 4);
  for (uint32_t y = 0; y < size; ++y) {
    for (uint32_t x = 0; x < size; ++x) {
      bool dark = ((x / 64) + (y / 64)) % 2;
      uint8_t* p = &t.rgba[(size_t(y) * size + x) * 4];
      p[0] = uint8_t(dark ? 20 + 23 * seed : 240 - 11 * seed);
      p[1] = uint8_t(dark ? 200 - 17 * seed : 30 + 19 * seed);
      p[2] = uint8_t(dark ? 90 : 160);
      p[3] = 255;
    }
  }
  return t;
}

// `count` quads side by side facing +Z, quad i self-lit by texture i.
scene::Scene texturedQuads(uint32_t count, uint32_t size) {
  scene::Scene s;
  s.source = "textured quads";
  for (uint32_t i = 0; i < count; ++i) {
    s.textures.push_back(checker(size, i));
    scene::Material m;
    m.name = "quad " + std::to_string(i);
    m.baseColorFactor = {0, 0, 0, 1};
    m.emissiveFactor = glm::vec3(1.0f);
    m.emissiveTexture.texture = int(i);
    s.materials.push_back(m);
    float x = 2.2f * (float(i) - 0.5f * float(count - 1));
    // addFlatShape's uv is (x / 2 + 0.5, y / 2 + 0.5): the quad spans [-1, 1] before it moves.
    addFlatShape(s, {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}}, {0, 1, 2, 0, 2, 3}, int(i),
                 glm::translate(glm::mat4(1.0f), glm::vec3(x, 0.0f, 0.0f)));
  }
  return s;
}

TEST_F(GpuTest, TexturesLargerTogetherThanOneStorageBufferRenderAsTheReferenceDoes) {
  // Enough 2048^2 textures to pass the device's largest storage buffer (128 MiB on lavapipe).
  uint64_t limit = context().caps().maxStorageBufferRange;
  uint32_t count = uint32_t(limit / (2048ull * 2048 * 4)) + 2;
  if (count > 24) GTEST_SKIP() << "this device binds " << (limit >> 20) << " MiB in one buffer: too many textures to pass it";
  scene::Scene s = texturedQuads(count, 2048);
  uint64_t bytes = 0;
  for (const scene::Texture& t : s.textures) bytes += t.rgba.size();
  ASSERT_GT(bytes, limit) << "the scene does not test what it should";
  scene::Pose pose = scene::evaluate(s, 0.0);
  scene::ViewRequest request;
  request.lookAt = scene::LookAt{{0.0, 0.0, 1.6 * count}, {0.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  request.yfov = 0.8;
  scene::View view = scene::resolveView(s, pose, request);
  const uint32_t width = 256, height = 32;
  render::Renderer renderer(context(), s, pose);
  render::RenderedFrame frame = render::renderFrame(context(), renderer, pose, {width, height, view, {0.02f, 0.02f, 0.025f}, 8});
  Comparison result = compare(cli::toSrgb8({width, height, frame.rgba}), referenceImage(s, pose, view, width, height));
  std::printf("%u textures, %.0f MiB: %zu of %zu pixels within 1/255, max difference %d/255\n", count,
              double(bytes) / 1048576.0, result.withinOne, result.pixels, result.maxDifference);
  EXPECT_EQ(result.withinOne, result.pixels) << result.firstMismatches;
}

// The linear value of an sRGB byte and back, in double, as trace.h states.
double decode(uint8_t v) { return scene::srgbToLinear(v); }
int encode(double c) {
  double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
  return int(std::lround(std::clamp(s, 0.0, 1.0) * 255.0));
}

TEST_F(GpuTest, EachMipLevelIsTheMeanOfTheTwoByTwoTexelsAboveInLinearLight) {
  scene::Scene s = texturedQuads(1, 4);
  scene::Texture& t = s.textures[0];
  t.width = 7, t.height = 5;  // odd: the last column and row are clamped, level 1 is 3x2
  t.rgba.resize(7 * 5 * 4);
  std::mt19937 rng(3);
  for (uint8_t& b : t.rgba) b = uint8_t(rng());
  scene::Pose pose = scene::evaluate(s, 0.0);
  render::SceneGpu gpu = render::uploadScene(context(), s, pose);
  ASSERT_EQ(render::mipLevels(7, 5), 3u);
  ASSERT_EQ(render::mipChainTexels(7, 5), 35u + 6u + 1u);
  std::vector<uint32_t> page(42);
  vk::download(context(), gpu.texelPages[0], page.data(), page.size() * 4);
  // Level 0 as the file holds it, then each level from the one above.
  std::vector<uint8_t> above(t.rgba);
  uint32_t w = 7, h = 5, first = 0;
  for (uint32_t x = 0; x < w * h; ++x) {
    for (int c = 0; c < 4; ++c) ASSERT_EQ(int((page[x] >> (8 * c)) & 0xff), int(above[x * 4 + c]));
  }
  int worst = 0;
  for (uint32_t level = 1; level < 3; ++level) {
    uint32_t tw = std::max(w / 2, 1u), th = std::max(h / 2, 1u);
    std::vector<uint8_t> below(size_t(tw) * th * 4);
    for (uint32_t y = 0; y < th; ++y) {
      for (uint32_t x = 0; x < tw; ++x) {
        for (int c = 0; c < 4; ++c) {
          double sum = 0;
          for (uint32_t j = 0; j < 2; ++j) {
            for (uint32_t i = 0; i < 2; ++i) {
              uint32_t sx = std::min(2 * x + i, w - 1), sy = std::min(2 * y + j, h - 1);
              uint8_t v = above[(size_t(sy) * w + sx) * 4 + c];
              sum += c < 3 ? decode(v) : v / 255.0;
            }
          }
          int want = c < 3 ? encode(sum / 4) : int(std::lround(sum / 4 * 255.0));
          int got = int((page[first + w * h + y * tw + x] >> (8 * c)) & 0xff);
          worst = std::max(worst, std::abs(got - want));
          below[(size_t(y) * tw + x) * 4 + c] = uint8_t(got);  // the next level is made from what the GPU made
        }
      }
    }
    first += w * h;
    w = tw, h = th;
    above = below;
  }
  // Float against double: a mean that lands on a half byte may round either way.
  EXPECT_LE(worst, 1);
}

TEST_F(GpuTest, TexturesBeyondEveryPageAreAClearErrorNamingTheNumbers) {
  uint64_t limit = context().caps().maxStorageBufferRange;
  if (limit > (256ull << 20)) GTEST_SKIP() << "pages of " << (limit >> 20) << " MiB: too large to fill in a test";
  // One chain per page at most, and one more than there are pages.
  uint32_t size = 4096;
  while (render::mipChainTexels(size, size) * 4 <= limit / 2) size *= 2;
  scene::Scene s;
  s.source = "too many textures";
  for (uint32_t i = 0; i <= gpu::kTexelPages; ++i) {
    scene::Texture t;
    t.name = "huge " + std::to_string(i);
    t.width = t.height = size;
    s.textures.push_back(t);  // no texels: the placement refuses before anything is read
  }
  scene::Pose pose = scene::evaluate(s, 0.0);
  try {
    render::uploadScene(context(), s, pose);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    std::string message = e.what();
    EXPECT_NE(message.find("too many textures"), std::string::npos) << message;
    EXPECT_NE(message.find("MiB"), std::string::npos) << message;
    EXPECT_NE(message.find("huge " + std::to_string(gpu::kTexelPages)), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace snell::test
