// `snell bake SCENE -o MAP`: a refraction map baked by the GPU trace, the
// Sky paper's "refraction reference map" without a DCC in the loop.
#include "cli/cli.h"

#include "bake/refraction_bake.h"
#include "cli/image_file.h"
#include "render/renderer.h"
#include "scene/evaluate.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>

namespace snell::cli {

namespace {

constexpr const char* kHelp = R"(usage: snell bake SCENE.glb|SCENE.gltf|--eye -o MAP.png|MAP.exr [options]

Bakes a refraction map (the Sky paper's refraction reference map) with the
GPU trace: for every pixel whose visible face is glass, the UV in the texture
behind the glass (the iris, or any textured surface) where the pixel's
refracted path lands. One ray per pixel through its centre: no filtering and
no anti-aliasing, which would crack the map. The file appears only once it
is complete.

The file is RGBA:
  rg16  16-bit PNG: R, G = U, V x 65535
  exr   float EXR: R, G = U, V
  sky8  8-bit PNG, the seed's pseudo high colour depth: a UV gradient tiled
        16 x 16 times, B the tile (high nibble U's, low nibble V's), R, G the
        place in the tile; the seed's GLSL decodes it (docs/refraction-maps.md)
  A     1 where the UV holds; 1/2 where the pixel is glass but its path lands
        on no texel of the texture behind (another surface, nothing, or past
        --max-interfaces): marked, not guessed; 0 where it is not glass.
UVs are those of the material's base colour texture (its texture transform
applied), wrapped into [0, 1] as its sampler wraps them.

options:
  -o, --output FILE      the map (required): .png for rg16 and sky8, .exr for exr
  --encoding E           rg16, exr or sky8 (default: sky8 for .png, exr for .exr)
  --material NAME|INDEX  the surface behind, whose texture the UVs address
                         (default: the one most glass pixels land on)
  --route direct|dcc     direct (default): the UVs the trace reports; dcc: as a
                         DCC bakes, the texture behind replaced by a UV
                         gradient tiled 16 x 16 (sky8's codes), rendered
                         without Fresnel or filtering and the colours read back
  --gradient-size N      the dcc route's gradient, N x N texels (default 4096)
  --eye                  bake the procedural eye instead of a file
  --size WxH             map size in pixels (default 640x480)
  --camera N             the scene's glTF camera N (default: camera 0, or a view
                         framing the whole scene when it has none)
  --look-at EX,EY,EZ,TX,TY,TZ   camera at E looking at T, +Y up
  --fov DEGREES          vertical field of view for --look-at and framed views (40)
  --time T               seconds into the animation: the pose baked (default 0)
  --max-interfaces N     refractive faces a ray may cross (default 8)
  --scene NAME|INDEX     which glTF scene of the file
  --ignore-extension E   load a file that requires extension E anyway
  --texture-budget MIB   textures beyond MIB MiB load at a lower mip level
)";

struct Options {
  ShotOptions shot;
  std::string output;
  std::optional<bake::Encoding> encoding;
  std::string material;
  bool dcc = false;
  uint32_t gradientSize = 4096;
};

Options parse(const Args& args) {
  Options o;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (o.shot.take("bake", args, i)) continue;
    if (i + 1 >= args.size()) throw UsageError{"bake: " + a + " needs a value (or is unknown)"};
    const std::string& v = args[++i];
    if (a == "-o" || a == "--output") {
      o.output = v;
    } else if (a == "--encoding") {
      o.encoding = bake::encodingFromName(v);
      if (!o.encoding) throw UsageError{"bake: --encoding takes rg16, exr or sky8, got '" + v + "'"};
    } else if (a == "--material") {
      o.material = v;
    } else if (a == "--route") {
      if (v != "direct" && v != "dcc") throw UsageError{"bake: --route takes direct or dcc, got '" + v + "'"};
      o.dcc = v == "dcc";
    } else if (a == "--gradient-size") {
      unsigned long long n = parseCount(a, v);
      if (n < 16 || n > 8192) throw UsageError{"bake: --gradient-size " + v + " is out of range (16 to 8192)"};
      o.gradientSize = uint32_t(n);
    } else {
      throw UsageError{"bake: unknown option " + a};
    }
  }
  o.shot.require("bake");
  if (o.output.empty()) throw UsageError{"bake: give the map with -o MAP.png or MAP.exr"};
  std::string ext = std::filesystem::path(o.output).extension().string();
  if (!o.encoding) {
    if (ext == ".png" || ext == ".PNG") o.encoding = bake::Encoding::Sky8;
    if (ext == ".exr" || ext == ".EXR") o.encoding = bake::Encoding::Exr;
  }
  if (!o.encoding) throw UsageError{"bake: the map must end in .png or .exr, got '" + o.output + "'"};
  bool exr = ext == ".exr" || ext == ".EXR", png = ext == ".png" || ext == ".PNG";
  if ((*o.encoding == bake::Encoding::Exr && !exr) || (*o.encoding != bake::Encoding::Exr && !png)) {
    throw UsageError{std::string("bake: a ") + bake::encodingName(*o.encoding) + " map is written as " +
                     (*o.encoding == bake::Encoding::Exr ? ".exr" : ".png") + ", not '" + o.output + "'"};
  }
  return o;
}

}  // namespace

void parseBakeOptions(const Args& args) { (void)parse(args); }

int runBake(const Args& args) {
  for (const std::string& a : args) {
    if (a == "--help" || a == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
  }
  Options o = parse(args);
  checkWritable(o.output);
  scene::Scene scene = o.shot.loadScene();
  std::optional<uint32_t> material;
  if (!o.material.empty()) material = findTexturedMaterial("bake", scene, o.material);
  auto start = std::chrono::steady_clock::now();
  scene::Pose pose = scene::evaluate(scene, o.shot.time);
  scene::View view = o.shot.resolveView("bake", scene, pose);
  std::unique_ptr<vk::Context> context = o.shot.openContext("bake");
  render::FrameSettings settings{o.shot.width, o.shot.height, view, o.shot.background, o.shot.maxInterfaces};
  bake::DecodedMap map;
  std::string summary;
  {
    render::Renderer renderer(*context, scene, pose);
    bake::RefractionBake baked = bake::bakeRefraction(*context, renderer, pose, settings);
    if (material) baked.behindMaterial = *material;
    summary = bake::describe(baked, scene);
    if (baked.count(bake::Coverage::Lands) == 0) {
      throw std::runtime_error("bake: " + (o.shot.eye ? std::string("the eye") : o.shot.input) + ", " +
                               view.description + ": " + summary + "; there is no map to write");
    }
    map = o.dcc ? bake::bakeThroughGradient(*context, scene, pose, settings, baked, o.gradientSize, true)
                : bake::storedMap(baked, scene);
  }
  writeMapFile(o.output, bake::encodeMap(map, *o.encoding), *o.encoding);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("wrote %s: %ux%u %s map (%s route), %s at %g s, %s, %.2f s\n  %s\n", o.output.c_str(), o.shot.width,
              o.shot.height, bake::encodingName(*o.encoding), o.dcc ? "dcc" : "direct", view.description.c_str(),
              o.shot.time, context->facts().name.c_str(), seconds, summary.c_str());
  return validationExitCode(*context);
}

}  // namespace snell::cli
