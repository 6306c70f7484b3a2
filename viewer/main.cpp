// `snell-view`: the interactive viewer's command line (CLI11, with the
// conventions of cli/options.h: errors name their option and exit 2). The
// viewer itself starts in viewer.cpp.
#include "viewer.h"

#include "cli/options.h"
#include "io/image_file.h"
#include "io/json.h"
#include "io/version.h"
#include "render/method.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

namespace {

constexpr const char* kDescription =
    R"(snell-view [SCENE.glb|SCENE.gltf] [options]: the interactive viewer. The scene
rasterized, with every transmissive face showing the GPU ray trace through the
deforming mesh. With no scene it opens the procedural eye; drop a .gltf/.glb on
the window to open another.
)";

// Seconds: a finite number >= 0.
std::string checkSeconds(const std::string& value) {
  char* end = nullptr;
  double t = std::strtod(value.c_str(), &end);
  if (value.empty() || *end || !std::isfinite(t) || t < 0.0) return "expects seconds >= 0, got '" + value + "'";
  return "";
}

std::string checkPng(const std::string& path) {
  std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : "";
  if (ext != ".png" && ext != ".PNG") return "writes PNG: the name must end in .png, got '" + path + "'";
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace snell;
  io::recordCommandLine(argc, argv);
  CLI::App app{kDescription, "snell-view"};
  app.set_version_flag("--version", std::string("snell-view ") + io::version());
  app.footer(std::string(viewer::kControlsHelp) + "\n\n" + cli::kHelpFooter);
  app.get_formatter()->column_width(34);
  cli::addGlobalOptions(app);

  viewer::ViewerOptions o;
  app.add_option("scene", o.scene, "the glTF file to open (.gltf or .glb); without one, the\nprocedural eye")
      ->type_name("SCENE");
  cli::addSize(app, "--size", o.width, o.height,
               "window size (default " + std::to_string(o.width) + "x" + std::to_string(o.height) + ")");
  app.add_option("--camera", o.camera,
                 "start from the scene's glTF camera N (default: camera 0,\nor a view framing the scene when it has none)")
      ->type_name("N")
      ->check(CLI::Range(0, 1 << 20));
  app.add_option("--time", o.time, "start T seconds into the animation (default 0)")
      ->type_name("T")
      ->check(CLI::Validator(checkSeconds, "SECONDS"));
  app.add_flag("--play", o.play, "start playing");
  app.add_flag("--split", o.split, "two viewports side by side");
  std::vector<std::string> methods;
  for (const render::MethodInfo& m : render::methods()) methods.emplace_back(m.name);
  app.add_option_function<std::string>(
         "--method", [&o](const std::string& name) { o.method = *render::methodFromName(name); },
         "how glass is drawn (default masked):\n" + render::methodHelp() +
             "refraction-map is baked when picked and B bakes it again;\n"
             "the overlay's drop-down switches it")
      ->type_name("M")
      ->check(CLI::IsMember(methods));
  app.add_flag_callback("--no-vsync", [&o] { o.vsync = false; }, "present as fast as the GPU renders");
  CLI::Option* frames = app.add_option("--frames", o.frames, "render N frames, then exit (exit code 0 when all went well)")
                            ->type_name("N")
                            ->check(CLI::Range(uint64_t(1), uint64_t(1000000000)));
  app.add_option("--screenshot", o.screenshot, "write the last frame to FILE (PNG)")
      ->type_name("FILE")
      ->check(CLI::Validator(checkPng, "PNG"))
      ->needs(frames);
  app.add_flag("--hide-ui", o.hideUi,
               "no overlay, film gate or outlines: the bare composite\n(what 'snell render --viewport' writes)");
  app.add_option("--script", o.script,
                 "scripted input, one '<frame> <action> [args]' per line\n"
                 "(resize, orbit, pan, dolly, filmpan, filmzoom, filmreset,\n"
                 "frame, camera, play, pause, scrub, loop, refraction, method,\n"
                 "wireframe, heatmap, gate, split, ui, minimise, restore, load,\n"
                 "screenshot, quit)")
      ->type_name("FILE");
  app.add_flag("--offscreen", o.offscreen,
               "no window: the same frame code into an image (for machines\nwithout a display)")
      ->needs(frames);
  app.add_option("--json", o.json, "write median frame and pass times to FILE")->type_name("FILE")->needs(frames);
  app.add_option("--scene", o.load.scene, "which glTF scene of the file")->type_name("NAME|INDEX");
  app.add_option("--ignore-extension", o.load.ignoredExtensions,
                 "load a file that requires extension E anyway (repeatable)")
      ->type_name("E")
      ->allow_extra_args(false);
  cli::addTextureBudget(app, o.load.textureBudget);

  cli::Runner run = [&o] {
    // Before any window opens or frame is drawn: files that could not be written at the end.
    if (!o.screenshot.empty()) io::checkWritable(o.screenshot);
    if (!o.json.empty()) io::checkWritable(o.json);
    o.quiet = cli::quiet();
    try {
      return viewer::runViewer(o);
    } catch (const viewer::OptionError& e) {
      throw cli::UsageError{e.message};
    }
  };
  return cli::runCommandLine(app, argc, argv, run);
}
