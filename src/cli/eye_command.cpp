// `snell eye -o eye.glb`: writes the procedural eye (or a crowd of eye pairs).
#include "cli/cli.h"
#include "cli/image_file.h"

#include "scene/gltf_writer.h"
#include "scene/procedural_eye.h"
#include "scene/scene_summary.h"

#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace snell::cli {

namespace {

constexpr const char* kHelp = R"(usage: snell eye -o FILE.glb [options]

Writes the procedural eye as a self-contained glTF binary: sclera; a cornea
mesh whose tip is transmissive (KHR_materials_transmission, KHR_materials_ior)
and whose other faces are not; an iris cone with a procedural texture; a pupil;
morph targets "squash" and "dilate"; a joint per eye; a 4-second clip that
looks around, squashes and dilates; a camera and two lights.

options:
  -o, --output FILE     where to write (required; .glb)
  --ior X               cornea index of refraction (default 1.376)
  --iris-depth M        metres from the limbus back to the iris (default 0.0006)
  --cornea-bulge M      metres the cornea stands in front of the limbus (default 0.0025)
  --resolution N        segments around each part, 8-2048 (default 64; 256 gives
                        about 200 000 triangles)
  --crowd N             N characters' eye pairs in a grid, animation staggered
  --aqueous             add the aqueous humour (IOR 1.336) behind the cornea: a
                        closed volume the cornea hands over to (nested media)
)";

float parseNumber(const std::string& option, const std::string& value) {
  char* end = nullptr;
  float result = std::strtof(value.c_str(), &end);
  if (value.empty() || *end != '\0' || !std::isfinite(result)) {
    throw UsageError{option + " expects a number, got '" + value + "'"};
  }
  return result;
}

}  // namespace

int runEye(const Args& args) {
  scene::EyeOptions options;
  std::string output;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
    if (a == "--aqueous") {
      options.aqueous = true;
      continue;
    }
    if (i + 1 >= args.size()) throw UsageError{"eye: " + a + " needs a value (or is unknown)"};
    const std::string& v = args[++i];
    if (a == "-o" || a == "--output") output = v;
    else if (a == "--ior") options.ior = parseNumber(a, v);
    else if (a == "--iris-depth") options.irisDepth = parseNumber(a, v);
    else if (a == "--cornea-bulge") options.corneaBulge = parseNumber(a, v);
    else if (a == "--resolution") options.resolution = static_cast<uint32_t>(parseCount(a, v));
    else if (a == "--crowd") options.crowd = static_cast<uint32_t>(parseCount(a, v));
    else throw UsageError{"eye: unknown option " + a};
  }
  if (output.empty()) throw UsageError{"eye: give the output file with -o FILE.glb"};
  checkWritable(output);
  try {
    scene::checkEyeOptions(options);
  } catch (const std::invalid_argument& e) {
    throw UsageError{std::string("eye: ") + e.what()};
  }
  scene::Scene eye = scene::makeEye(options);
  scene::saveGlb(eye, output);
  scene::SceneSummary summary = scene::summarize(eye);
  std::printf("wrote %s: %llu triangles, %zu eyes, cornea IOR %.3f, %.1f s animation\n", output.c_str(),
              static_cast<unsigned long long>(summary.triangles), eye.skins.size(), static_cast<double>(options.ior),
              static_cast<double>(eye.animations.empty() ? 0.0f : eye.animations[0].duration));
  return 0;
}

}  // namespace snell::cli
