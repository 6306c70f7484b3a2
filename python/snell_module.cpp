// snell._snell: the public C++ API (include/snell/snell.h) for Python, and
// nothing below it. Arrays cross as numpy arrays, checked here so a wrong
// shape, dtype or index is a snell.Error naming the array and what is wrong.
// The GIL is released while snell waits for the GPU, so the host's other
// Python threads (a DCC's UI, a farm's heartbeat) keep running. Each part is
// bound in its own file: images (bind_images.cpp), the scene
// (bind_scene.cpp), drawing (bind_renderer.cpp) and shots (bind_shots.cpp).
#include "module_support.h"

PYBIND11_MODULE(_snell, m) {
  using namespace snell_python;
  m.doc() = "snell: refraction through deforming meshes, ray traced by Vulkan compute.";
  m.attr("DEFAULT_YFOV") = snell::kDefaultYfov;  // radians: framed views' and View(yfov=)'s default
  py::register_exception<snell::Error>(m, "Error", PyExc_RuntimeError);
  bindImages(m);
  bindDevice(m);
  bindMaterials(m);
  bindGeometry(m);
  bindScene(m);
  bindView(m);
  bindRenderer(m);
  bindShots(m);
}
