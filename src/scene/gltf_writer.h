// Scene to glTF 2.0, binary (.glb) or JSON with its buffer beside it (.gltf): what `snell eye` writes.
#pragma once

#include "scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace snell::scene {

/// Writes the scene as the extension says: one self-contained .glb, or a .gltf
/// (JSON) with NAME.bin beside it. Geometry, morph targets, skins, materials
/// (with the transmission/IOR/volume extensions), textures as PNG inside the
/// buffer, cameras, punctual lights and animations. Writes into a temporary
/// folder and renames, so a failure never leaves a half-written file; throws
/// SceneError (also for any other extension).
void saveGltf(const Scene& scene, const std::string& path);

}  // namespace snell::scene
