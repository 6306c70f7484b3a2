// What an EXR frame carries beside its colour: alpha as coverage and the
// --aov layers (depth, normal, ids, interfaces, cost) from the trace's per-pixel
// data or the reference's, and a header with the camera, time, method and device.
#pragma once

#include "cli/render_shot.h"
#include "io/image_file.h"
#include "render/pixel_aovs.h"
#include "scene/scene.h"
#include "scene/view.h"

#include <cstdint>
#include <string>
#include <vector>

namespace snell::cli {

using render::PixelHit;

/// Writes alpha = coverage into `image` and returns the layers --aov asked for.
std::vector<io::AovLayer> aovLayers(const RenderOptions& o, const scene::Scene& scene, const scene::Pose& pose,
                                    const scene::View& view, io::LinearImage& image, const std::vector<PixelHit>& hits);

/// The EXR header of a frame at `time` drawn by `method` on `device`.
io::ImageExtras exrExtras(const RenderOptions& o, const scene::Scene& scene, const scene::View& view, double time,
                          const std::string& method, const std::string& device);

}  // namespace snell::cli
