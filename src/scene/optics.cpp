// The procedural sky of optics.h, an environment that needs no file, and the
// checks and fitting every environment passes before the trace takes it.
#include "scene/optics.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace snell::scene {

Environment proceduralSky(uint32_t width) {
  Environment sky;
  sky.source = "procedural sky";
  sky.width = width;
  sky.height = width / 2;
  sky.texels.reserve(size_t(sky.width) * sky.height);
  const glm::vec3 sun = glm::normalize(glm::vec3(0.4f, 0.5f, 0.77f));
  for (uint32_t y = 0; y < sky.height; ++y) {
    for (uint32_t x = 0; x < sky.width; ++x) {
      // The inverse of trace.h's equirectangular lookup: u = 0.5 + atan(x, -z) / 2pi, v = acos(y) / pi.
      float phi = (float(x) + 0.5f) / float(sky.width) * glm::two_pi<float>() - glm::pi<float>();
      float theta = (float(y) + 0.5f) / float(sky.height) * glm::pi<float>();
      glm::vec3 d(std::sin(theta) * std::sin(phi), std::cos(theta), -std::sin(theta) * std::cos(phi));
      glm::vec3 c = d.y > 0 ? glm::mix(glm::vec3(0.7f, 0.8f, 0.9f), glm::vec3(0.2f, 0.35f, 0.7f), d.y)
                            : glm::vec3(0.25f, 0.23f, 0.2f);
      if (glm::dot(d, sun) > 0.999f) c = glm::vec3(40.0f, 36.0f, 30.0f);
      sky.texels.push_back(c);
    }
  }
  return sky;
}

namespace {

/// Box-filters the environment to half its size in each direction.
void halve(Environment& env) {
  uint32_t w = std::max(1u, env.width / 2), h = std::max(1u, env.height / 2);
  std::vector<glm::vec3> out(size_t(w) * h);
  for (uint32_t y = 0; y < h; ++y) {
    for (uint32_t x = 0; x < w; ++x) {
      glm::vec3 sum(0.0f);
      for (uint32_t dy = 0; dy < 2; ++dy) {
        for (uint32_t dx = 0; dx < 2; ++dx) {
          sum += env.texels[size_t(std::min(2 * y + dy, env.height - 1)) * env.width + std::min(2 * x + dx, env.width - 1)];
        }
      }
      out[size_t(y) * w + x] = 0.25f * sum;
    }
  }
  env.width = w;
  env.height = h;
  env.texels = std::move(out);
}

}  // namespace

void fitEnvironment(Environment& env) {
  if (env.width == 0 || env.height == 0 || env.texels.size() != size_t(env.width) * env.height) {
    throw std::runtime_error(env.source + ": an environment of " + std::to_string(env.width) + "x" +
                             std::to_string(env.height) + " texels needs that many, got " +
                             std::to_string(env.texels.size()));
  }
  for (const glm::vec3& t : env.texels) {
    if (!(std::isfinite(t.r) && std::isfinite(t.g) && std::isfinite(t.b)) || t.r < 0.0f || t.g < 0.0f || t.b < 0.0f) {
      throw std::runtime_error(env.source + ": the environment has a negative or non-finite texel");
    }
  }
  while (env.width > kMaxEnvironmentWidth) halve(env);
}

}  // namespace snell::scene
