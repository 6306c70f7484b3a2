// Refraction map encodings (issue 16): each round-trips a known UV field
// within its stated bound, sky8 holds about 16 times the depth of plain
// 8 bits, and the seed's GLSL decoder runs the same in C++ and on the GPU.
#include "gpu_test.h"

#include "golden_support.h"

#include "bake/refraction_map.h"
#include "ref/reference_tracer.h"
#include "render/one_view.h"
#include "render/renderer.h"
#include "vk/buffer.h"
#include "vk/commands.h"
#include "vk/compute_program.h"
#include "sky8_decode.spv.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

namespace snell::test {
namespace {

using bake::Sky8;

// A known UV field: a 513 x 513 grid over [0, 1]^2 (its edges included) and
// 100000 random points.
std::vector<glm::dvec2> uvField() {
  std::vector<glm::dvec2> field;
  for (int y = 0; y <= 512; ++y) {
    for (int x = 0; x <= 512; ++x) field.push_back({x / 512.0, y / 512.0});
  }
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int i = 0; i < 100000; ++i) field.push_back({unit(rng), unit(rng)});
  return field;
}

template <typename RoundTrip>
double largestError(RoundTrip roundTrip) {
  double worst = 0.0;
  for (const glm::dvec2& uv : uvField()) {
    glm::dvec2 back = roundTrip(uv);
    worst = std::max({worst, std::abs(back.x - uv.x), std::abs(back.y - uv.y)});
  }
  return worst;
}

TEST(RefractionMap, Sky8RoundTripsWithinHalfItsStep) {
  double worst = largestError([](glm::dvec2 uv) { return bake::decodeSky8(bake::encodeSky8(uv)); });
  const double halfStep = 8.0 / (255.0 * 255.0);  // the grid steps by 16 / 255^2
  std::printf("sky8: largest error %.3g in UV = %.3f texels of 1024, %.3f of 4096\n", worst, worst * 1024, worst * 4096);
  EXPECT_LE(worst, halfStep * (1 + 1e-12));
}

TEST(RefractionMap, Rg16RoundTripsWithinHalfItsStep) {
  double worst = largestError([](glm::dvec2 uv) {
    return glm::dvec2(bake::decodeUnorm16(bake::encodeUnorm16(uv.x)), bake::decodeUnorm16(bake::encodeUnorm16(uv.y)));
  });
  std::printf("rg16: largest error %.3g in UV = %.4f texels of 1024, %.4f of 4096\n", worst, worst * 1024, worst * 4096);
  EXPECT_LE(worst, 0.5 / 65535.0 * (1 + 1e-12));
}

TEST(RefractionMap, FloatRoundTripsWithinFloatRounding) {
  double worst = largestError([](glm::dvec2 uv) { return glm::dvec2(glm::vec2(uv)); });
  std::printf("exr (float): largest error %.3g in UV = %.2g texels of 4096\n", worst, worst * 4096);
  EXPECT_LE(worst, std::ldexp(1.0, -25));  // half an ulp of floats in [0.5, 1)
}

TEST(RefractionMap, DecodingThenEncodingKeepsEveryCodesValue) {
  // The exact decoder inverts the encoder: every code's UV encodes to a code
  // of the same UV (red or green 255 and 0 on the next tile are one value).
  size_t moved = 0;
  for (uint32_t c = 0; c < (1u << 24); ++c) {
    Sky8 code{uint8_t(c), uint8_t(c >> 8), uint8_t(c >> 16)};
    glm::dvec2 uv = bake::decodeSky8(code);
    if (uv.x > 1.0 || uv.y > 1.0) continue;  // past the UV square: the encoder clamps
    glm::dvec2 back = bake::decodeSky8(bake::encodeSky8(uv));
    moved += std::abs(back.x - uv.x) > 1e-12 || std::abs(back.y - uv.y) > 1e-12;
  }
  EXPECT_EQ(moved, 0u);
}

TEST(RefractionMap, Sky8BandsFarLessThanPlainEightBit) {
  // A 4096-pixel ramp of u: the longest run of pixels sharing one value.
  auto longestRun = [](auto code) {
    int run = 1, longest = 1;
    for (int i = 1; i < 4096; ++i) {
      run = code((i + 0.5) / 4096.0) == code((i - 0.5) / 4096.0) ? run + 1 : 1;
      longest = std::max(longest, run);
    }
    return longest;
  };
  int plain = longestRun([](double u) { return int(bake::encodeUnorm8(u)); });
  int sky8 = longestRun([](double u) {
    Sky8 c = bake::encodeSky8({u, 0.0});
    return int(c.r) | int(c.b) << 8;
  });
  std::printf("longest run of equal values over a 4096-pixel ramp: plain 8-bit %d, sky8 %d\n", plain, sky8);
  EXPECT_GE(plain, 16);
  EXPECT_LE(sky8, 2);
}

TEST(RefractionMap, TheSeedDecoderDiffersFromTheExactOneOnlyWhereItsQuirksSay) {
  // Over all 2^24 codes: away from blue 255 (u's tile read as 16), the seed's
  // float decoder is the exact inverse within float rounding. Its
  // mod(b * 255, 16) would misread a b * 255 that rounds under a whole
  // number; in float none does.
  size_t blue255 = 0, modQuirk = 0, other = 0;
  double worstElsewhere = 0.0;
  for (uint32_t c = 0; c < (1u << 24); ++c) {
    Sky8 code{uint8_t(c), uint8_t(c >> 8), uint8_t(c >> 16)};
    glm::dvec2 exact = bake::decodeSky8(code);
    glm::dvec2 seed(bake::decodeSky8Seed(code));
    glm::dvec2 d = glm::abs(seed - exact);
    if (d.x <= 1e-6 && d.y <= 1e-6) {
      continue;
    }
    if (code.b == 255 && d.x > 1e-6) {
      ++blue255;
      if (d.y <= 1e-6) continue;
    }
    if (d.y > 1e-6) {
      ++modQuirk;
      continue;
    }
    ++other;
    worstElsewhere = std::max({worstElsewhere, d.x, d.y});
  }
  std::printf("seed against exact over 2^24 codes: %zu differ in u (blue 255), %zu in v (mod), %zu otherwise (worst %.3g)\n",
              blue255, modQuirk, other, worstElsewhere);
  EXPECT_EQ(blue255, 1u << 16);
  EXPECT_EQ(modQuirk, 0u);
  EXPECT_EQ(other, 0u);
}

// The GPU tests of what the trace tells the refraction map.
class RefractionMapTrace : public GpuTest {};

TEST_F(RefractionMapTrace, TheSeedDecoderRunsBitForBitTheSameInGlslAndCpp) {
  const uint32_t chunk = 1u << 22;
  vk::ComputeProgram program(context(), vk::ComputeProgramDesc{"sky8 decode", kSpvSky8Decode, {}, false});
  vk::Buffer decoded(context(), {VkDeviceSize(chunk) * 8, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                 vk::MemoryDomain::Device, "sky8 decoded"});
  std::vector<float> unorm8(256);
  for (int v = 0; v < 256; ++v) unorm8[size_t(v)] = float(v) / 255.0f;
  vk::Buffer table(context(), {256 * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                               vk::MemoryDomain::Device, "unorm8"});
  vk::upload(context(), table, unorm8.data(), 256 * sizeof(float));
  std::vector<glm::vec2> gpu(chunk);
  size_t mismatches = 0;
  std::string first;
  for (uint32_t start = 0; start < (1u << 24); start += chunk) {
    struct {
      uint32_t first, count;
    } push{start, chunk};
    vk::Commands commands(context(), "sky8 decode");
    commands.begin();
    program.dispatchThreads(commands, {{0, &decoded}, {1, &table}}, push, chunk);
    commands.submitAndWait();
    vk::download(context(), decoded, gpu.data(), VkDeviceSize(chunk) * 8);
    for (uint32_t i = 0; i < chunk; ++i) {
      uint32_t c = start + i;
      glm::vec2 cpu = bake::decodeSky8Seed({uint8_t(c), uint8_t(c >> 8), uint8_t(c >> 16)});
      if (std::memcmp(&cpu, &gpu[i], sizeof cpu) != 0 && mismatches++ < 5) {
        char line[160];
        std::snprintf(line, sizeof line, "code %06x: CPU (%.9g, %.9g), GPU (%.9g, %.9g)\n", c, cpu.x, cpu.y, gpu[i].x, gpu[i].y);
        first += line;
      }
    }
  }
  EXPECT_EQ(mismatches, 0u) << first;
}

// What a refraction map is baked from: where each pixel's refracted ray
// lands, in the texture space of the surface behind the glass.
TEST_F(RefractionMapTrace, TheTraceReportsWhereRefractedRaysLandInTextureSpace) {
  scene::Scene s = eyeWith(1.376f);
  scene::Pose pose = scene::evaluate(s, 0.0);
  scene::View view = scene::resolveView(s, pose, {});
  const uint32_t width = 128, height = 96;
  render::Renderer renderer(context(), s, pose);
  render::RenderedFrame frame =
      render::renderFrame(renderer, pose, {width, height, view, glm::vec3(scene::kDefaultBackground), 8}, true);
  ref::ReferenceSettings settings;
  settings.width = width;
  settings.height = height;
  settings.view = view;
  ref::ReferenceImage reference = ref::renderReference(s, pose, settings);
  size_t landed = 0, agreeing = 0, sameMark = 0, worstAt = 0;
  double worst = 0.0;
  for (size_t i = 0; i < frame.aov.size(); ++i) {
    const gpu::TraceAov& a = frame.aov[i];
    glm::dvec2 want = reference.landing[i];
    bool gpuLanded = !std::isnan(a.landingU), refLanded = !std::isnan(want.x);
    sameMark += gpuLanded == refLanded;
    if (a.interfaces == 0) {
      EXPECT_FALSE(gpuLanded) << "pixel " << i << " crossed no glass but reports a landing";
    }
    if (!gpuLanded || !refLanded) continue;
    ++landed;
    double d = std::max(std::abs(a.landingU - want.x), std::abs(a.landingV - want.y));
    agreeing += d <= 1e-3;
    if (d > worst) worst = d, worstAt = i;
  }
  std::printf("%zu pixels land on the iris; %zu within 1e-3 in UV of the reference (worst %.3g at pixel %zu); "
              "landed or not agrees on %zu of %zu\n", landed, agreeing, worst, worstAt, sameMark, frame.aov.size());
  EXPECT_GT(landed, 500u);
  EXPECT_GE(double(agreeing), 0.995 * double(landed));
  EXPECT_GE(double(sameMark), 0.999 * double(frame.aov.size()));
}

}  // namespace
}  // namespace snell::test
