// Scene evaluation at arbitrary times: the first eight bytes are the time (a
// double, NaN and infinities included), the rest a packed glTF input. Every
// pose must be finite wherever the file's data is, and never crash.
#include "fuzz_input.h"

#include "scene/evaluate.h"
#include "scene/gltf_loader.h"
#include "scene/view.h"

#include <cstring>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  double time = 0.0;
  if (size >= sizeof time) {
    std::memcpy(&time, data, sizeof time);
    data += sizeof time;
    size -= sizeof time;
  }
  snell::fuzz::FileSet files(data, size);
  snell::scene::Scene scene;
  try {
    scene = snell::scene::loadGltf(files.document());
  } catch (const snell::scene::SceneError&) {
    return 0;
  }
  double duration = snell::scene::animationDuration(scene);
  for (double t : {time, -time, duration, time * duration}) {
    snell::scene::Pose pose = snell::scene::evaluate(scene, t);
    glm::dvec3 lo, hi;
    snell::scene::approximateBounds(scene, pose, lo, hi);
    try {
      snell::scene::resolveView(scene, pose, {});
    } catch (const std::invalid_argument&) {  // no view fits (an empty or degenerate scene)
    }
  }
  return 0;
}
