// The reference tracer's entry: a ray from the view through every pixel, one
// std::thread per share of the rows; the scene and each pixel's path are in
// prepared_scene and path, named after the GPU shader code they mirror.
#include "ref/reference_tracer.h"

#include "ref/path.h"
#include "ref/prepared_scene.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>

namespace snell::ref {

ReferenceImage renderReference(const scene::Scene& scene, const scene::Pose& pose, const ReferenceSettings& settings) {
  ReferenceImage image;
  image.width = settings.width;
  image.height = settings.height;
  const size_t pixels = size_t(settings.width) * settings.height;
  image.color.assign(pixels, glm::dvec3(0.0));
  image.distance.assign(pixels, detail::kInfinity);
  image.instance.assign(pixels, -1);
  image.primitive.assign(pixels, -1);
  image.interfaces.assign(pixels, 0);
  image.outcome.assign(pixels, gpu::kOutcomeMiss);
  image.energyError.assign(pixels, 0.0);
  image.landing.assign(pixels, glm::dvec2(std::numeric_limits<double>::quiet_NaN()));
  image.shortestSegment.assign(pixels, detail::kInfinity);
  if (pixels == 0) return image;
  if (!settings.rays.empty() && settings.rays.size() != pixels) {
    throw std::invalid_argument("reference: " + std::to_string(settings.rays.size()) + " rays for " +
                                std::to_string(pixels) + " pixels");
  }

  const detail::PreparedScene prepared(scene, pose, settings.view);
  const scene::View& view = settings.view;
  const double w = settings.width, h = settings.height;
  const glm::dvec3 forward = glm::normalize(view.forward);

  std::atomic<uint32_t> nextRow{0};
  auto work = [&] {
    for (uint32_t y = nextRow++; y < settings.height; y = nextRow++) {
      for (uint32_t x = 0; x < settings.width; ++x) {
        double sx = (2.0 * (double(x) + 0.5) / w - 1.0) * view.halfHeight * w / h + view.shift.x;
        double sy = (1.0 - 2.0 * (double(y) + 0.5) / h) * view.halfHeight + view.shift.y;
        glm::dvec3 origin = view.eye, direction = forward;
        double width = 0.0, spread = 0.0;  // listed rays have no footprint: level 0
        if (!settings.rays.empty()) {
          origin = settings.rays[image.index(x, y)].origin;
          direction = glm::normalize(settings.rays[image.index(x, y)].direction);
        } else if (view.orthographic) {
          origin = view.eye + view.right * sx + view.up * sy;
          width = 2.0 * view.halfHeight / h;
        } else {
          direction = glm::normalize(view.forward + sx * view.right + sy * view.up);
          spread = std::atan(2.0 * view.halfHeight / h);
        }
        detail::PixelResult r = detail::trace(prepared, origin, direction, width, spread, settings);
        size_t i = image.index(x, y);
        image.color[i] = r.color;
        image.distance[i] = r.distance;
        image.instance[i] = r.instance;
        image.primitive[i] = r.primitive;
        image.interfaces[i] = r.interfaces;
        image.outcome[i] = r.outcome;
        image.energyError[i] = r.energyError;
        image.landing[i] = r.landing;
        image.shortestSegment[i] = r.shortestSegment;
      }
    }
  };
  unsigned threads = settings.threads ? settings.threads : std::max(1u, std::thread::hardware_concurrency());
  threads = std::min<unsigned>(threads, settings.height);
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < threads; ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
  return image;
}

}  // namespace snell::ref
