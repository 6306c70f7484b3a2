// Scene to glTF 2.0 binary (.glb): what `snell eye` writes, and later bakes.
#pragma once

#include "scene/scene.h"

#include <cstdint>
#include <string>
#include <vector>

namespace snell::scene {

/// Writes the scene as one self-contained .glb: geometry, morph targets,
/// skins, materials (with the transmission/IOR/volume extensions), textures as
/// PNG, cameras, punctual lights and animations. Writes to a temporary file and
/// renames it, so a failure never leaves a half-written file; throws SceneError.
void saveGlb(const Scene& scene, const std::string& path);

/// An RGBA8 image as a PNG file's bytes (stb's encoder: filtered and deflated).
std::vector<uint8_t> encodePng(uint32_t width, uint32_t height, const std::vector<uint8_t>& rgba);
/// A 16-bit RGBA image as a PNG file's bytes (stored deflate: exact; no
/// Debian-packaged encoder at hand compresses 16-bit samples).
std::vector<uint8_t> encodePng16(uint32_t width, uint32_t height, const std::vector<uint16_t>& rgba);

}  // namespace snell::scene
