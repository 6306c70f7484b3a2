// `snell eye -o eye.glb|eye.gltf`: writes the procedural eye (or a crowd of eye pairs).
#include "cli/commands.h"

#include "io/image_file.h"
#include "scene/gltf_writer.h"
#include "scene/procedural_eye.h"
#include "scene/scene_summary.h"

#include <cstdio>
#include <stdexcept>

namespace snell::cli {

namespace {

struct Options {
  scene::EyeOptions eye;
  std::string output;
};

int run(const Options& o) {
  io::checkWritable(o.output);
  scene::Scene eye = scene::makeEye(o.eye);
  scene::saveGltf(eye, o.output);
  scene::SceneSummary summary = scene::summarize(eye);
  std::printf("wrote %s: %llu triangles, %zu eyes, cornea IOR %.3f, %.1f s animation\n", o.output.c_str(),
              static_cast<unsigned long long>(summary.triangles), eye.skins.size(), static_cast<double>(o.eye.ior),
              static_cast<double>(eye.animations.empty() ? 0.0f : eye.animations[0].duration));
  return kExitOk;
}

}  // namespace

void addEye(CLI::App& parent, Runner& run) {
  auto o = std::make_shared<Options>();
  CLI::App* eye = parent.add_subcommand("eye", "write the procedural eye as glTF (.glb, or .gltf with a .bin)");
  describe(*eye,
      "Writes the procedural eye as glTF: sclera; a cornea mesh whose tip is\n"
      "transmissive (KHR_materials_transmission, KHR_materials_ior) and whose other\n"
      "faces are not; an iris cone with a procedural texture; a pupil; morph targets\n"
      "\"squash\" and \"dilate\"; a joint per eye; a 4-second clip that looks around,\n"
      "squashes and dilates; a camera and two lights. FILE.glb is one binary file;\n"
      "FILE.gltf is JSON with FILE.bin beside it.");
  eye->footer(kHelpFooter);
  eye->add_option("-o,--output", o->output, "where to write: FILE.glb or FILE.gltf")
      ->required()
      ->type_name("FILE")
      ->check([](const std::string& path) -> std::string {
        std::string ext = path.size() >= 5 ? path.substr(path.size() - 5) : path;
        for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
        return ext == ".gltf" || ext.substr(1) == ".glb" ? "" : "must end in .glb or .gltf, got '" + path + "'";
      });
  eye->add_option("--ior", o->eye.ior, "cornea index of refraction (default 1.376)")->type_name("X");
  eye->add_option("--iris-depth", o->eye.irisDepth, "metres from the limbus back to the iris (default 0.0006)")
      ->type_name("M");
  eye->add_option("--cornea-bulge", o->eye.corneaBulge, "metres the cornea stands in front of the limbus (default 0.0025)")
      ->type_name("M");
  eye->add_option("--resolution", o->eye.resolution,
                  "segments around each part, 8-2048 (default 64; 256 gives\nabout 200 000 triangles)")
      ->type_name("N");
  eye->add_option("--crowd", o->eye.crowd, "N characters' eye pairs in a grid, animation staggered")->type_name("N");
  eye->add_flag("--aqueous", o->eye.aqueous,
                "add the aqueous humour (IOR 1.336) behind the cornea: a\nclosed volume the cornea hands over to (nested media)");
  eye->callback([o, &run] {
    try {
      scene::checkEyeOptions(o->eye);
    } catch (const std::invalid_argument& e) {
      throw UsageError{std::string("eye: ") + e.what()};
    }
    run = [o] { return cli::run(*o); };
  });
}

}  // namespace snell::cli
