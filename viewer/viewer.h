// snell-view: the interactive viewer. One frame = the renderer's update, then
// per viewport the trace and the raster composite, then the display pass and
// ImGui on the window image, which is copied to the swapchain (or, offscreen,
// kept for a screenshot). The same frame code runs with and without a window.
#pragma once

#include "render/method.h"
#include "scene/gltf_loader.h"

#include <cstdint>
#include <string>

namespace snell::viewer {

struct ViewerOptions {
  std::string scene;               ///< .gltf/.glb; empty: the procedural eye
  scene::LoadOptions load;
  uint32_t width = 1280, height = 720;
  uint64_t frames = 0;             ///< stop after this many frames; 0: when the window closes
  std::string screenshot;          ///< PNG of the last frame's window image
  std::string script;              ///< scripted input (script.h)
  std::string json;                ///< frame times, written at exit
  bool offscreen = false;          ///< no window: the frame code alone (GPU machines without X)
  bool vsync = true;
  bool hideUi = false;             ///< no ImGui, film gate or outlines: the bare composite
  bool split = false;              ///< two viewports side by side
  bool play = false;
  int camera = -1;                 ///< glTF camera; -1: camera 0 if any, else the orbit rig framing the scene
  double time = 0.0;
  render::Method method = render::Method::Masked;  ///< how glass is drawn (render/method.h)
  bool quiet = false;              ///< no load notes on standard error
};

/// An option the scene cannot honour (a --camera it lacks): main() reports it
/// as bad usage, exit 2.
struct OptionError {
  std::string message;
};

/// Runs the viewer; returns the process exit code (non-zero when the
/// validation layer reported anything). A --camera the scene lacks throws
/// OptionError; a scene that fails to load, std::runtime_error.
int runViewer(const ViewerOptions& options);

/// The mouse, trackpad and key bindings, as --help and the overlay list them
/// (input.cpp, beside the code that binds them).
extern const char* const kControlsHelp;

}  // namespace snell::viewer
