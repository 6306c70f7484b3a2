// The procedural sky of optics.h: an environment that needs no file.
#include "scene/optics.h"

#include <glm/gtc/constants.hpp>

#include <cmath>

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

}  // namespace snell::scene
