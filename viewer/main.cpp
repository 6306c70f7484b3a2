// `snell-view`: open a glTF scene (or the procedural eye) in a window.
#include "viewer.h"

#include "cli/cli.h"
#include "cli/image_file.h"

#include <cstdio>
#include <exception>
#include <optional>
#include <string>
#include <vector>

namespace {

constexpr const char* kHelp = R"(usage: snell-view [SCENE.glb|SCENE.gltf] [options]

The interactive viewer: the scene rasterized, with every transmissive face
showing the GPU ray trace through the deforming mesh. With no scene it opens
the procedural eye; drop a .gltf/.glb on the window to open another.

options:
  --size WxH          window size (default 1280x720)
  --camera N          start from the scene's glTF camera N (default: camera 0,
                      or a view framing the scene when it has none)
  --time T            start T seconds into the animation
  --play              start playing
  --split             two viewports side by side
  --method M          how glass is drawn (default masked): trace, trace-1,
                      masked, iris-plane, normal-offset, refraction-map (baked
                      when picked; B bakes again), none (the overlay's
                      drop-down switches it)
  --no-vsync          present as fast as the GPU renders
  --frames N          render N frames, then exit (0 when all went well)
  --screenshot FILE   with --frames: write the last frame to FILE (PNG)
  --hide-ui           no overlay, film gate or outlines: the bare composite
                      (what 'snell render --viewport' writes)
  --script FILE       scripted input, one '<frame> <action> [args]' per line
                      (resize, orbit, pan, dolly, filmpan, filmzoom, frame,
                      camera, play, pause, scrub, refraction, method, wireframe,
                      heatmap, gate, split, ui, minimise, restore, load, quit)
  --offscreen         no window: the same frame code into an image (needs
                      --frames; for machines without a display)
  --json FILE         with --frames: write median frame and pass times
  --scene NAME|INDEX  which glTF scene of the file
  --ignore-extension E  load a file that requires extension E anyway
  --texture-budget MIB  textures (with mips) beyond MIB MiB load at a lower mip level

mouse (Maya):  Alt+left tumble, Alt+middle track, Alt+right dolly
trackpad:      left drag tumble, Shift+left track, Ctrl+left or wheel dolly
keys:          F frame, Space play, Left/Right step, \ 2D pan/zoom mode,
               Backspace reset the film back, R refraction, W wireframe,
               H heat map, G film gate, 2 two viewports, Tab overlay, Esc quit

environment:
  SNELL_DEVICE=<index|name>  use this device
  SNELL_VALIDATION=1         Khronos validation layer on; any message makes the
                             exit code 1
)";

snell::viewer::ViewerOptions parse(const std::vector<std::string>& args) {
  using snell::cli::UsageError;
  snell::viewer::ViewerOptions o;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--play") { o.play = true; continue; }
    if (a == "--split") { o.split = true; continue; }
    if (a == "--no-vsync") { o.vsync = false; continue; }
    if (a == "--hide-ui") { o.hideUi = true; continue; }
    if (a == "--offscreen") { o.offscreen = true; continue; }
    if (!a.empty() && a[0] != '-') {
      if (!o.scene.empty()) throw UsageError{"more than one scene given ('" + o.scene + "', '" + a + "')"};
      o.scene = a;
      continue;
    }
    if (i + 1 >= args.size()) throw UsageError{a + " needs a value (or is unknown)"};
    const std::string& v = args[++i];
    if (a == "--size") {
      snell::cli::parseSize(a, v, o.width, o.height);
    } else if (a == "--method") {
      std::optional<snell::render::Method> m = snell::render::methodFromName(v);
      if (!m) throw UsageError{"snell-view: --method takes one of " + snell::render::methodNames() + ", got '" + v + "'"};
      o.method = *m;
    } else if (a == "--camera") {
      o.camera = int(std::min<unsigned long long>(snell::cli::parseCount(a, v), 1u << 20));
    } else if (a == "--time") {
      char* end = nullptr;
      o.time = std::strtod(v.c_str(), &end);
      if (v.empty() || *end || !(o.time >= 0.0)) throw UsageError{"--time expects seconds >= 0, got '" + v + "'"};
    } else if (a == "--frames") {
      o.frames = snell::cli::parseCount(a, v);
    } else if (a == "--screenshot") {
      snell::cli::checkWritable(o.screenshot = v);
    } else if (a == "--script") {
      o.script = v;
    } else if (a == "--json") {
      snell::cli::checkWritable(o.json = v);
    } else if (a == "--scene") {
      o.load.scene = v;
    } else if (a == "--ignore-extension") {
      o.load.ignoredExtensions.push_back(v);
    } else if (a == "--texture-budget") {
      o.load.textureBudget = snell::cli::parseTextureBudget(a, v);
    } else {
      throw UsageError{"unknown option " + a};
    }
  }
  if (!o.screenshot.empty() && o.frames == 0) throw UsageError{"--screenshot needs --frames N (the frame to capture)"};
  if (!o.json.empty() && o.frames == 0) throw UsageError{"--json needs --frames N"};
  if (o.offscreen && o.frames == 0) throw UsageError{"--offscreen needs --frames N: nobody can close it"};
  if (!o.screenshot.empty()) {
    std::string ext = o.screenshot.size() >= 4 ? o.screenshot.substr(o.screenshot.size() - 4) : "";
    if (ext != ".png" && ext != ".PNG") throw UsageError{"--screenshot writes PNG: the name must end in .png"};
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  for (const std::string& a : args) {
    if (a == "--help" || a == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
  }
  try {
    return snell::viewer::runViewer(parse(args));
  } catch (const snell::cli::UsageError& e) {
    std::fprintf(stderr, "snell-view: %s\nRun 'snell-view --help' for usage.\n", e.message.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "snell-view: error: %s\n", e.what());
    return 1;
  }
}
