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
