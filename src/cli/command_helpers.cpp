// Small helpers the subcommands share (commands.h).
#include "cli/commands.h"

#include <algorithm>

namespace snell::cli {

uint32_t findTexturedMaterial(const std::string& command, const scene::Scene& scene, const std::string& wanted) {
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    if (scene.materials[i].name != wanted && std::to_string(i) != wanted) continue;
    if (!scene.materials[i].baseColorTexture.present()) {
      throw UsageError{command + ": --material " + wanted + " has no base colour texture for the UVs to address"};
    }
    return uint32_t(i);
  }
  throw UsageError{command + ": --material " + wanted + ": the scene has no such material (" +
                   std::to_string(scene.materials.size()) + " materials)"};
}

BakeSetup prepareBake(const std::string& command, const ShotOptions& shot, const std::string& material) {
  BakeSetup b;
  b.scene = shot.loadScene();
  if (!material.empty()) b.material = findTexturedMaterial(command, b.scene, material);
  b.start = std::chrono::steady_clock::now();
  b.pose = scene::evaluate(b.scene, shot.time);
  b.view = shot.resolveView(command, b.scene, b.pose);
  b.context = shot.openContext(command);
  b.settings = {shot.width, shot.height, b.view, shot.background, shot.maxInterfaces};
  return b;
}

std::string xmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    if (c == '&') out += "&amp;";
    else if (c == '<') out += "&lt;";
    else if (c == '>') out += "&gt;";
    else if (c == '"') out += "&quot;";
    else out += c;
  }
  return out;
}

}  // namespace snell::cli
