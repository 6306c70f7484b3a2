// Animation sampling and transform composition on the CPU, on scenes small
// enough to check by hand.
#include "scene/evaluate.h"

#include <gtest/gtest.h>

#include <glm/gtc/quaternion.hpp>

namespace snell::test {
namespace {

/// One node, animated by one channel with two keys at t = 0 and t = 1.
scene::Scene oneChannel(scene::AnimationPath path, scene::Interpolation interpolation, std::vector<float> values,
                        int components) {
  scene::Scene s;
  s.nodes.resize(1);
  s.roots = {0};
  scene::Animation a;
  scene::AnimationSampler sampler;
  sampler.interpolation = interpolation;
  sampler.times = {0.0f, 1.0f};
  sampler.values = std::move(values);
  sampler.components = components;
  a.samplers.push_back(sampler);
  a.channels.push_back({0, path, 0});
  a.duration = 1.0f;
  s.animations.push_back(a);
  return s;
}

glm::vec3 translationAt(const scene::Scene& s, double t) { return glm::vec3(scene::evaluate(s, t).world[0][3]); }

TEST(Evaluate, LinearTranslationIsHalfwayAtHalfTime) {
  auto s = oneChannel(scene::AnimationPath::Translation, scene::Interpolation::Linear, {0, 0, 0, 2, 0, 0}, 3);
  EXPECT_FLOAT_EQ(translationAt(s, 0.5).x, 1.0f);
  EXPECT_FLOAT_EQ(translationAt(s, -1.0).x, 0.0f);  // clamped before the first key
  EXPECT_FLOAT_EQ(translationAt(s, 7.0).x, 2.0f);   // and after the last
}

TEST(Evaluate, StepHoldsTheEarlierKey) {
  auto s = oneChannel(scene::AnimationPath::Translation, scene::Interpolation::Step, {0, 0, 0, 2, 0, 0}, 3);
  EXPECT_FLOAT_EQ(translationAt(s, 0.99).x, 0.0f);
  EXPECT_FLOAT_EQ(translationAt(s, 1.0).x, 2.0f);
}

TEST(Evaluate, CubicSplineWithFlatTangentsIsSmoothstep) {
  // Per key: in-tangent, value, out-tangent.
  auto s = oneChannel(scene::AnimationPath::Translation, scene::Interpolation::CubicSpline,
                      {0, 0, 0, 0, 0, 0, 0, 0, 0, /**/ 0, 0, 0, 2, 0, 0, 0, 0, 0}, 3);
  EXPECT_NEAR(translationAt(s, 0.25).x, 2.0 * (3 * 0.0625 - 2 * 0.015625), 1e-6);
  EXPECT_NEAR(translationAt(s, 0.5).x, 1.0, 1e-6);
}

TEST(Evaluate, CubicSplineFollowsItsTangents) {
  // Value 0 to 0 with out-tangent 1 and in-tangent 1: p(u) = u^3 - 2u^2 + u + u^3 - u^2 = 2u^3 - 3u^2 + u.
  auto s = oneChannel(scene::AnimationPath::Translation, scene::Interpolation::CubicSpline,
                      {0, 0, 0, 0, 0, 0, 1, 0, 0, /**/ 1, 0, 0, 0, 0, 0, 0, 0, 0}, 3);
  double u = 0.3;
  EXPECT_NEAR(translationAt(s, u).x, 2 * u * u * u - 3 * u * u + u, 1e-6);
}

TEST(Evaluate, RotationsSlerpAndStayUnit) {
  glm::quat q90 = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 0, 1));
  auto s = oneChannel(scene::AnimationPath::Rotation, scene::Interpolation::Linear,
                      {0, 0, 0, 1, q90.x, q90.y, q90.z, q90.w}, 4);
  glm::mat4 m = scene::evaluate(s, 0.5).world[0];
  glm::vec3 x = glm::vec3(m * glm::vec4(1, 0, 0, 0));
  EXPECT_NEAR(x.x, std::cos(glm::radians(45.0f)), 1e-6);
  EXPECT_NEAR(x.y, std::sin(glm::radians(45.0f)), 1e-6);
  EXPECT_NEAR(glm::length(x), 1.0, 1e-6);
}

TEST(Evaluate, ChildrenComposeWithTheirParents) {
  scene::Scene s;
  s.nodes.resize(2);
  s.nodes[0].translation = {1, 0, 0};
  s.nodes[0].scale = {2, 2, 2};
  s.nodes[0].children = {1};
  s.nodes[1].parent = 0;
  s.nodes[1].translation = {0, 1, 0};
  s.roots = {0};
  glm::vec3 p = glm::vec3(scene::evaluate(s, 0.0).world[1][3]);
  EXPECT_EQ(p, glm::vec3(1, 2, 0));
}

}  // namespace
}  // namespace snell::test
