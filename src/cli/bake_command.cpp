// `snell bake SCENE -o MAP`: a refraction map baked by the GPU trace, the
// Sky paper's "refraction reference map" without a DCC in the loop.
#include "cli/commands.h"

#include "bake/map_file.h"
#include "bake/refraction_bake.h"
#include "io/image_file.h"
#include "render/one_view.h"
#include "render/renderer.h"
#include "scene/evaluate.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <stdexcept>

namespace snell::cli {

namespace {

struct Options {
  ShotOptions shot;
  std::string output;
  std::optional<bake::Encoding> encoding;  ///< unset: from -o's extension
  std::string material;
  bool dcc = false;
  uint32_t gradientSize = 4096;
};

int runBake(const Options& o) {
  io::checkWritable(o.output);
  BakeSetup setup = prepareBake("bake", o.shot, o.material);
  const auto& [scene, material, start, pose, view, context, settings] = setup;
  bake::DecodedMap map;
  std::string summary;
  {
    render::Renderer renderer(*context, scene, pose);
    bake::RefractionBake baked = render::bakeRefraction(renderer, pose, settings);  // files only: nothing kept on the GPU
    if (material) baked.behindMaterial = *material;
    summary = bake::describe(baked, scene);
    if (baked.count(bake::Coverage::Lands) == 0) {
      throw std::runtime_error("bake: " + (o.shot.eye ? std::string("the eye") : o.shot.input) + ", " +
                               view.description + ": " + summary + "; there is no map to write");
    }
    map = o.dcc ? bake::bakeThroughGradient(*context, scene, pose, settings, baked, o.gradientSize, true)
                : bake::storedMap(baked, scene);
  }
  bake::writeMapFile(o.output, bake::encodeMap(map, *o.encoding), *o.encoding);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("wrote %s: %ux%u %s map (%s route), %s at %g s, %s, %.2f s\n  %s\n", o.output.c_str(), o.shot.width,
              o.shot.height, bake::encodingName(*o.encoding), o.dcc ? "dcc" : "direct", view.description.c_str(),
              o.shot.time, context->facts().name.c_str(), seconds, summary.c_str());
  return validationExitCode(*context);
}

}  // namespace

void addBake(CLI::App& parent, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* sub =
      parent.add_subcommand("bake", "bake a refraction map: the UV behind the glass per pixel (rg16, exr, sky8)");
  describe(*sub,
      "Bakes a refraction map (the Sky paper's refraction reference map) with the\n"
      "GPU trace: for every pixel whose visible face is glass, the UV in the texture\n"
      "behind the glass (the iris, or any textured surface) where the pixel's\n"
      "refracted path lands. One ray per pixel through its centre: no filtering and\n"
      "no anti-aliasing, which would crack the map. The file appears only once it\n"
      "is complete.\n"
      "\n"
      "The file is RGBA:\n"
      "  rg16  16-bit PNG: R, G = U, V x 65535\n"
      "  exr   float EXR: R, G = U, V\n"
      "  sky8  8-bit PNG, the seed's pseudo high colour depth: a UV gradient tiled\n"
      "        16 x 16 times, B the tile (high nibble U's, low nibble V's), R, G the\n"
      "        place in the tile; the seed's GLSL decodes it (docs/refraction-maps.md)\n"
      "  A     1 where the UV holds; 1/2 where the pixel is glass but its path lands\n"
      "        on no texel of the texture behind (another surface, nothing, or past\n"
      "        --max-interfaces): marked, not guessed; 0 where it is not glass.\n"
      "UVs are those of the material's base colour texture (its texture transform\n"
      "applied), wrapped into [0, 1] as its sampler wraps them.");
  sub->footer(kHelpFooter);
  o->shot.addTo(*sub);
  sub->add_option("-o,--output", o->output, "the map (required): .png for rg16 and sky8, .exr for exr")
      ->required()
      ->type_name("FILE");
  sub->add_option_function<std::string>(
          "--encoding", [o](const std::string& name) { o->encoding = bake::encodingFromName(name); },
          "rg16, exr or sky8 (default: sky8 for .png, exr for .exr)")
      ->type_name("E")
      ->check(CLI::IsMember({"rg16", "exr", "sky8"}));
  sub->add_option("--material", o->material,
                  "the surface behind, whose texture the UVs address\n(default: the one most glass pixels land on)")
      ->type_name("NAME|INDEX");
  sub->add_option_function<std::string>(
          "--route", [o](const std::string& route) { o->dcc = route == "dcc"; },
          "direct (default): the UVs the trace reports; dcc: as a\n"
          "DCC bakes, the texture behind replaced by a UV gradient tiled\n"
          "16 x 16 (sky8's codes), rendered without Fresnel or filtering\n"
          "and the colours read back")
      ->type_name("ROUTE")
      ->check(CLI::IsMember({"direct", "dcc"}));
  CLI::Option* gradient =
      sub->add_option("--gradient-size", o->gradientSize, "the dcc route's gradient, N x N texels (default 4096)")
          ->type_name("N")
          ->check(CLI::Range(16u, 8192u));
  sub->callback([o, gradient, &run] {
    o->shot.require("bake");
    if (gradient->count() > 0 && !o->dcc) throw UsageError{"bake: --gradient-size is for --route dcc"};
    // The encoding follows from -o's extension unless --encoding names it; either way the two must agree.
    std::string ext = std::filesystem::path(o->output).extension().string();
    bool exr = ext == ".exr" || ext == ".EXR", png = ext == ".png" || ext == ".PNG";
    if (!exr && !png) throw UsageError{"bake: -o must end in .png or .exr, got '" + o->output + "'"};
    if (!o->encoding) o->encoding = exr ? bake::Encoding::Exr : bake::Encoding::Sky8;
    bool exrEncoding = *o->encoding == bake::Encoding::Exr;
    if (exrEncoding != exr) {
      throw UsageError{std::string("bake: -o: a ") + bake::encodingName(*o->encoding) + " map is written as " +
                       (exrEncoding ? ".exr" : ".png") + ", not '" + o->output + "'"};
    }
    run = [o] { return runBake(*o); };
  });
}

}  // namespace snell::cli
