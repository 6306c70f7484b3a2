// The trace's per-pixel data as EXR layers, and the EXR header (see exr_layers.h).
#include "cli/exr_layers.h"

#include "io/json.h"
#include "io/version.h"
#include "scene/evaluate.h"

#include <glm/gtc/packing.hpp>

#include <cmath>
#include <limits>
#include <map>

namespace snell::cli {

const std::vector<std::string> kAovNames = {"depth", "normal", "instance", "primitive", "interfaces", "cost"};

namespace {

// Camera-space depth along the view axis from the trace's distance along
// each pixel's unit ray (the reference tracer's ray, in double).
double depthOf(const scene::View& view, uint32_t width, uint32_t height, size_t pixel, double distance) {
  if (view.orthographic) return distance;
  double w = width, h = height;
  double x = double(pixel % width), y = double(pixel / width);
  double sx = (2.0 * (x + 0.5) / w - 1.0) * view.halfHeight * w / h + view.shift.x;
  double sy = (1.0 - 2.0 * (y + 0.5) / h) * view.halfHeight + view.shift.y;
  return distance / std::sqrt(1.0 + sx * sx + sy * sy);
}

// The world-space face normal of each (item, triangle) the pixels hit, from
// the item's deformed positions at this pose (deformed once per item).
class FaceNormals {
 public:
  FaceNormals(const scene::Scene& scene, const scene::Pose& pose) : scene_(scene), pose_(pose) {}
  glm::vec3 of(uint32_t item, uint32_t triangle) {
    if (item >= pose_.items.size()) return glm::vec3(0.0f);
    const scene::DrawItem& drawn = pose_.items[item];
    auto [at, fresh] = items_.try_emplace(item);
    Deformed& d = at->second;
    if (fresh) {
      std::vector<glm::dvec3> normals;
      scene::deformOnCpu(drawn, d.positions, normals);
      d.normalToWorld = glm::transpose(glm::inverse(glm::dmat3(drawn.world)));
    }
    const std::vector<uint32_t>& indices = scene_.shapes[size_t(drawn.shape)].indices;
    if (3 * size_t(triangle) + 2 >= indices.size()) return glm::vec3(0.0f);
    const std::vector<glm::dvec3>& p = d.positions;
    glm::dvec3 a = p[indices[3 * triangle]], b = p[indices[3 * triangle + 1]], c = p[indices[3 * triangle + 2]];
    glm::dvec3 n = d.normalToWorld * glm::cross(b - a, c - a);
    double length = glm::length(n);
    return length > 0.0 ? glm::vec3(n / length) : glm::vec3(0.0f);
  }

 private:
  struct Deformed {
    std::vector<glm::dvec3> positions;
    glm::dmat3 normalToWorld{1.0};
  };
  const scene::Scene& scene_;
  const scene::Pose& pose_;
  std::map<uint32_t, Deformed> items_;
};


}  // namespace

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
        l.values[i] = hits[i].distance >= 0.0 ? float(depthOf(view, image.width, image.height, i, hits[i].distance))
                                              : std::numeric_limits<float>::infinity();
      }
    } else if (name == "normal") {
      FaceNormals normals(scene, pose);
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
