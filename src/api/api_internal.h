// What the public API's files (src/api/) share: the objects behind Device
// and Scene, the turn of every exception from below into snell::Error, and
// the public types' matrices and vectors as glm's.
#pragma once

#include "snell/snell.h"

#include "render/renderer.h"
#include "scene/scene.h"
#include "vk/context.h"

#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cstddef>
#include <exception>
#include <memory>
#include <mutex>

namespace snell {

struct Device::Impl {
  std::unique_ptr<vk::Context> context;
  // Renderers on several threads share the context (its queue, its deferred
  // destruction, its memory count): their GPU calls take turns here.
  std::recursive_mutex mutex;
};

struct Scene::Impl {
  scene::Scene scene;
  render::HostBuffers host;  ///< null handles for a glTF scene or kept vertices
  /// The shapes carry the host's first vertices (HostScene::vertices), and
  /// each Renderer keeps a copy for the host to rewrite.
  bool keep = false;
};

namespace api {

// Runs `body`, turning whatever it throws into snell::Error.
template <typename Body>
auto guarded(Body&& body) -> decltype(body()) {
  try {
    return body();
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {
    throw Error(e.what());
  }
}

inline glm::dmat4 toMatrix(const Mat4& m) { return glm::dmat4(glm::make_mat4(m.data())); }
inline glm::vec3 toVec(const Vec3& v) { return {v[0], v[1], v[2]}; }

/// The public API's meshes: a mesh with several materials is one shape and
/// its parts (scene::splitByMaterial), which follow every mesh's shape, so
/// meshes are the shapes before the first part.
inline size_t meshCount(const scene::Scene& s) {
  return size_t(std::find_if(s.shapes.begin(), s.shapes.end(), [](const scene::Shape& shape) { return shape.part(); }) -
                s.shapes.begin());
}


}  // namespace api
}  // namespace snell
