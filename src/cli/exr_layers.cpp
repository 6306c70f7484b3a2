// The trace's per-pixel data as EXR layers, and the EXR header (see exr_layers.h).
#include "cli/exr_layers.h"

#include "io/json.h"
#include "io/version.h"
#include "render/pixel_aovs.h"
#include "scene/evaluate.h"

#include <glm/gtc/packing.hpp>

#include <cmath>
#include <limits>

namespace snell::cli {

const std::vector<std::string> kAovNames = {"depth", "normal", "instance", "primitive", "interfaces", "cost"};

// Alpha = coverage written into the image, and the layers --aov asked for.
std::vector<io::AovLayer> aovLayers(const RenderOptions& o, const scene::Scene& scene, const scene::Pose& pose,
                                    const scene::View& view, io::LinearImage& image, const std::vector<PixelHit>& hits) {
  const size_t pixels = image.pixels();
  const uint16_t one = glm::packHalf1x16(1.0f), zero = glm::packHalf1x16(0.0f);
  for (size_t i = 0; i < pixels; ++i) {
    bool covered = hits[i].distance >= 0.0;
    if (image.rgba.empty()) image.rgbaHalf[4 * i + 3] = covered ? one : zero;
    else image.rgba[i].a = covered ? 1.0f : 0.0f;
  }
  std::vector<io::AovLayer> layers;
  for (const std::string& name : kAovNames) {
    if (!o.wants(name)) continue;
    io::AovLayer& l = layers.emplace_back();
    l.layer = name;
    if (name == "depth") {
      l.channels = {"Z"};
      l.values.resize(pixels);
      for (size_t i = 0; i < pixels; ++i) {
        l.values[i] = hits[i].distance >= 0.0 ? float(render::cameraDepth(view, image.width, image.height, i, hits[i].distance))
                                              : std::numeric_limits<float>::infinity();
      }
    } else if (name == "normal") {
      render::FaceNormals normals(scene, pose);
      l.channels = {"X", "Y", "Z"};
      l.values.resize(3 * pixels);
      for (size_t i = 0; i < pixels; ++i) {
        glm::vec3 n = hits[i].distance >= 0.0 ? normals.of(hits[i].instance, hits[i].primitive) : glm::vec3(0.0f);
        for (int c = 0; c < 3; ++c) l.values[3 * i + size_t(c)] = n[c];
      }
    } else {
      uint32_t PixelHit::*field = name == "instance"   ? &PixelHit::instance
                                  : name == "primitive"  ? &PixelHit::primitive
                                  : name == "interfaces" ? &PixelHit::interfaces
                                                         : &PixelHit::cost;
      l.channels = {name == "interfaces" ? "count" : name == "cost" ? "nodes" : "id"};
      l.integer = true;
      l.ids.resize(pixels);
      for (size_t i = 0; i < pixels; ++i) l.ids[i] = hits[i].*field;
    }
  }
  return layers;
}

// The EXR header: what a compositor or a pipeline wants to know about the frame.
io::ImageExtras exrExtras(const RenderOptions& o, const scene::Scene& scene, const scene::View& view, double time,
                          const std::string& method, const std::string& device) {
  io::ImageExtras extras;
  extras.floatPixels = o.floatPixels;
  extras.text = {{"snell:scene", scene.source},
                 {"snell:camera", view.description},
                 {"snell:method", method},
                 {"snell:device", device},
                 {"snell:version", io::version()},
                 {"snell:command_line", io::commandLine()}};
  extras.numbers = {{"snell:time", float(time)},
                    {"snell:vertical_fov_degrees",
                     view.orthographic ? 0.0f : float(2.0 * std::atan(view.halfHeight) * 180.0 / 3.14159265358979)}};
  // Camera space as OpenGL has it: x right, y up, looking down -z.
  glm::dmat4 cameraToWorld(glm::dvec4(view.right, 0.0), glm::dvec4(view.up, 0.0), glm::dvec4(-view.forward, 0.0),
                           glm::dvec4(view.eye, 1.0));
  extras.worldToCamera = glm::mat4(glm::inverse(cameraToWorld));
  extras.hasWorldToCamera = true;
  return extras;
}

}  // namespace snell::cli
