// glTF 2.0 (.gltf with external or embedded buffers, .glb) into a Scene,
// through tinygltf. Every reference and range is checked: a malformed file is
// a SceneError that names the file and the problem, never a crash.
#pragma once

#include "scene/scene.h"

#include <string>
#include <vector>

namespace snell::scene {

struct LoadOptions {
  /// The glTF scene to use: an index or a name; empty means the file's default
  /// scene (or its first).
  std::string scene;
  /// Required extensions to drop knowingly instead of refusing the file.
  std::vector<std::string> ignoredExtensions;
  /// GPU memory the textures may take with their mips, in bytes (0: no
  /// budget): beyond it the largest are loaded at a lower mip level, each
  /// with a note in Scene::warnings (scene::fitTextureBudget).
  uint64_t textureBudget = 0;
};

/// Loads a .gltf or .glb file (told apart by content, not by name).
Scene loadGltf(const std::string& path, const LoadOptions& options = {});

}  // namespace snell::scene
