// None
#include "module_support.h"

namespace snell_python {

void bindDevice(py::module_& m) {
  py::class_<PyDevice>(m, "Device", "The GPU snell runs on (a Vulkan device of its own).")
      .def(py::init([](const std::string& device, bool validation, bool interop, bool driverRayTracing) {
             snell::DeviceOptions options;
             options.device = device;
             options.validation = validation;
             options.interop = interop;
             options.driverRayTracing = driverRayTracing;
             py::gil_scoped_release release;
             return PyDevice{std::make_shared<snell::Device>(snell::Device::create(options))};
           }),
           "device"_a = "", "validation"_a = false, "interop"_a = false, "driver_ray_tracing"_a = false,
           "Picks a device: `device` is an index or a substring of its name (empty: the SNELL_DEVICE\n"
           "environment variable, else the first that meets snell's needs). `validation` turns on the\n"
           "Khronos validation layer; `interop` lets SharedImage hand images to OpenGL;\n"
           "`driver_ray_tracing` allows the 'driver-rt' method.")
      .def_property_readonly("name", [](const PyDevice& d) { return d.get().name(); }, "The device's name.")
      .def_property_readonly("validation_messages", [](const PyDevice& d) { return d.get().validationMessages(); },
                             "Messages the validation layer reported so far.")
      .def_property_readonly("exports_semaphores", [](const PyDevice& d) { return d.get().exportsSemaphores(); })
      .def("close", [](PyDevice& d) { d.device.reset(); },
           "Lets go of the device; it is destroyed once its renderers are.")
      .def("__enter__", [](PyDevice& d) -> PyDevice& { return d; })
      .def("__exit__", [](PyDevice& d, const py::args&) { d.device.reset(); })
      .def("__repr__", [](const PyDevice& d) {
        return d.device ? "<snell.Device '" + d.device->name() + "'>" : std::string("<snell.Device (closed)>");
      });
}

void bindView(py::module_& m) {
  // pybind11 keeps the pointer it is given: the text lives as long as the module.
  // pybind11 keeps the pointer it is given: the text lives as long as the module.
  static const std::string kViewDoc =
      "The camera: the scene's camera `camera` (an index), else view_matrix (world to camera)\n"
      "with projection (OpenGL: perspective or orthographic, off-centre for lens shift; its\n"
      "aspect must be width/height), else a look-at from eye to target with yfov radians.\n"
      "viewport=True draws the viewport composite: rasterised, with only the glass traced.\n"
      "environment: a snell.Environment the glass reflects (None: snell's studio gradient).\n"
      "method: auto (trace, or driver-rt where it times faster) or one of snell.methods():\n" +
      methodList();
  py::class_<snell::View>(m, "View", "One picture of the scene: its size, camera, method and optics.")
      .def(py::init([](uint32_t width, uint32_t height, int camera, const py::object& viewMatrix,
                       const py::object& projection, const std::vector<float>& eye, const std::vector<float>& target,
                       const std::vector<float>& up, float yfov, bool viewport, const std::string& method,
                       uint32_t maxInterfaces, bool fresnel, bool dispersion, bool volume,
                       const std::vector<float>& background, bool transparentBackground,
                       std::optional<snell::Environment> environment) {
             snell::View v;
             if (width == 0 || height == 0) throw snell::Error("a view needs a size, got " + std::to_string(width) + "x" + std::to_string(height));
             v.width = width;
             v.height = height;
             v.sceneCamera = camera;
             if (viewMatrix.is_none() != projection.is_none()) throw snell::Error("give view_matrix and projection together");
             if (!viewMatrix.is_none()) {
               v.matrices = snell::CameraMatrices{toMat4(viewMatrix, "view_matrix"), toMat4(projection, "projection")};
             }
             v.camera.eye = toVec3(eye, "eye");
             v.camera.target = toVec3(target, "target");
             v.camera.up = toVec3(up, "up");
             v.camera.yfov = yfov;
             v.output = viewport ? snell::View::Output::Viewport : snell::View::Output::Trace;
             v.method = method;
             v.maxInterfaces = maxInterfaces;
             v.fresnel = fresnel;
             v.dispersion = dispersion;
             v.volume = volume;
             v.background = toVec3(background, "background");
             v.transparentBackground = transparentBackground;
             v.environment = std::move(environment);
             return v;
           }),
           "width"_a = 640, "height"_a = 480, "camera"_a = -1, "view_matrix"_a = py::none(), "projection"_a = py::none(),
           "eye"_a = std::vector<float>{0, 0, 3}, "target"_a = std::vector<float>{0, 0, 0},
           "up"_a = std::vector<float>{0, 1, 0}, "yfov"_a = float(snell::kDefaultYfov), "viewport"_a = false, "method"_a = "auto",
           "max_interfaces"_a = 8, "fresnel"_a = true, "dispersion"_a = true, "volume"_a = true,
           "background"_a = std::vector<float>(kDefaultBackground.begin(), kDefaultBackground.end()),
           "transparent_background"_a = false, "environment"_a = py::none(), kViewDoc.c_str())
      .def_readwrite("width", &snell::View::width)
      .def_readwrite("height", &snell::View::height)
      .def_readwrite("camera", &snell::View::sceneCamera)
      .def_property(
          "viewport", [](const snell::View& v) { return v.output == snell::View::Output::Viewport; },
          [](snell::View& v, bool on) { v.output = on ? snell::View::Output::Viewport : snell::View::Output::Trace; })
      .def_readwrite("method", &snell::View::method)
      .def_readwrite("max_interfaces", &snell::View::maxInterfaces)
      .def_readwrite("fresnel", &snell::View::fresnel)
      .def_readwrite("dispersion", &snell::View::dispersion)
      .def_readwrite("volume", &snell::View::volume)
      .def_readwrite("background", &snell::View::background)
      .def_readwrite("transparent_background", &snell::View::transparentBackground)
      .def_readwrite("environment", &snell::View::environment,
                     "What glass reflects (a snell.Environment); None: snell's studio gradient.")
      .def(
          "set_matrices",
          [](snell::View& v, const py::object& viewMatrix, const py::object& projection) {
            v.matrices = snell::CameraMatrices{toMat4(viewMatrix, "view_matrix"), toMat4(projection, "projection")};
            v.sceneCamera = -1;
          },
          "view_matrix"_a, "projection"_a, "Points the view by the host's matrices (a DCC viewport's).");
  m.def(
      "framing",
      [](const std::vector<float>& lo, const std::vector<float>& hi, float yfov) {
        const snell::Camera c = snell::Camera::framing(toVec3(lo, "lo"), toVec3(hi, "hi"), yfov);
        auto tuple = [](const snell::Vec3& v) { return py::make_tuple(v[0], v[1], v[2]); };
        return py::dict("eye"_a = tuple(c.eye), "target"_a = tuple(c.target), "up"_a = tuple(c.up), "yfov"_a = c.yfov);
      },
      "lo"_a, "hi"_a, "yfov"_a = float(snell::kDefaultYfov),
      "The look-at snell render frames a scene without a camera with, for View(width, height, **framing(lo, hi)):\n"
      "looking down -Z at the centre of the world box [lo, hi], far enough back to see its whole bounding\n"
      "sphere (an empty box, lo > hi: the origin). Returns eye, target, up and yfov.");
}

void bindRenderer(py::module_& m) {
  py::class_<PySharedImage>(m, "SharedImage",
                            "A Vulkan image OpenGL imports (GL_EXT_memory_object_fd): a zero-copy viewport.")
      .def(py::init([](const PyDevice& device, uint32_t width, uint32_t height) {
             py::gil_scoped_release release;
             return PySharedImage{device.device,
                                  std::make_unique<snell::SharedImage>(device.get(), width, height,
                                                                       VK_FORMAT_R16G16B16A16_SFLOAT)};
           }),
           "device"_a, "width"_a, "height"_a,
           "An RGBA16F image (GL_RGBA16F, optimal tiling) on a Device made with interop=True.")
      .def("export_memory", [](const PySharedImage& s) { return s.get().exportMemory(); },
           "A new file descriptor of the image's memory, for glImportMemoryFdEXT (which owns it after).")
      .def_property_readonly("memory_size", [](const PySharedImage& s) { return s.get().memorySize(); })
      .def_property_readonly("dedicated", [](const PySharedImage& s) { return s.get().dedicated(); })
      .def("close", [](PySharedImage& s) { s.image.reset(); });

  py::class_<PyRenderer>(m, "Renderer", "Draws views of one scene, updating only what changed between frames.")
      .def(py::init([](const PyDevice& device, const PyScene& scene, uint32_t framesInFlight, bool compactTrees) {
             snell::RendererOptions options;
             options.framesInFlight = framesInFlight;
             options.compactTrees = compactTrees;
             std::shared_ptr<snell::Device> d = device.device;
             std::shared_ptr<snell::Scene> s = scene.scene;
             if (!d) throw snell::Error("the device is closed");
             if (!s) throw snell::Error("the scene is closed");
             py::gil_scoped_release release;
             snell::Renderer r(*d, *s, options);
             return PyRenderer{std::make_shared<RendererState>(RendererState{d, s, std::move(r)})};
           }),
           "device"_a, "scene"_a, "frames_in_flight"_a = 2, "compact_trees"_a = false,
           "Uploads the scene to the device. compact_trees: trees of 40 bytes a triangle (216 by default), whose "
           "walk is slower and draws the same pictures.")
      .def("set_time", [](PyRenderer& r, double seconds) { r.get().renderer.setTime(seconds); }, "seconds"_a,
           "Poses a glTF scene at `seconds` (animations, morphs, skins).")
      .def_property_readonly("instance_count", [](const PyRenderer& r) { return r.get().renderer.instanceCount(); })
      .def(
          "set_transform",
          [](PyRenderer& r, size_t instance, const py::object& matrix) {
            r.get().renderer.setTransform(instance, toMat4(matrix, "transform"));
          },
          "instance"_a, "transform"_a, "Moves an instance (4x4, mesh space to world): only the top-level tree is refit.")
      .def("mark_dirty", [](PyRenderer& r, int mesh) { r.get().renderer.markDirty(mesh); }, "mesh"_a,
           "Says mesh `mesh`'s vertices were rewritten (positions()/normals() views): the next frame\n"
           "copies them to the GPU and refits that mesh's tree alone.")
      .def(
          "positions",
          [](PyRenderer& r, int mesh) {
            snell::Vertices v = r.get().renderer.vertices(mesh);
            return vertexView(r.state, v.positions, v.count);
          },
          "mesh"_a,
          "A writable (n, 3) float32 view of a kept mesh's positions in snell's mapped memory:\n"
          "write them in place (numpy.take(..., out=) included), then mark_dirty(mesh).")
      .def(
          "normals",
          [](PyRenderer& r, int mesh) {
            snell::Vertices v = r.get().renderer.vertices(mesh);
            return vertexView(r.state, v.normals, v.count);
          },
          "mesh"_a, "The same for the normals (unit length).")
      .def(
          "set_vertices",
          [](PyRenderer& r, int mesh, const py::object& positions, const py::object& normals) {
            RendererState& state = r.get();
            snell::Vertices v = state.renderer.vertices(mesh);
            std::string what = "set_vertices: mesh " + std::to_string(mesh);
            auto p = checked<float>(positions, what + " positions", 3, "float32");
            if (size_t(p.shape(0)) != v.count) {
              throw snell::Error(what + " positions: " + std::to_string(p.shape(0)) + " rows for the mesh's " +
                                 std::to_string(v.count) + " vertices");
            }
            std::optional<py::array_t<float, py::array::c_style>> n;
            if (!normals.is_none()) {
              n = checked<float>(normals, what + " normals", 3, "float32");
              if (size_t(n->shape(0)) != v.count) {
                throw snell::Error(what + " normals: " + std::to_string(n->shape(0)) + " rows for the mesh's " +
                                   std::to_string(v.count) + " vertices");
              }
            }
            {
              py::gil_scoped_release release;
              std::memcpy(v.positions, p.data(), size_t(v.count) * 12);
              if (n) std::memcpy(v.normals, n->data(), size_t(v.count) * 12);
            }
            state.renderer.markDirty(mesh);
          },
          "mesh"_a, "positions"_a, "normals"_a = py::none(),
          "Copies new (n, 3) float32 positions (and normals) of a kept mesh into snell and marks it dirty.")
      .def(
          "render",
          [](PyRenderer& r, const snell::View& view) {
            RendererState& state = r.get();
            py::array_t<float> out({py::ssize_t(view.height), py::ssize_t(view.width), py::ssize_t(4)});
            float* data = out.mutable_data();
            py::gil_scoped_release release;
            state.renderer.read(view, data);
            return out;
          },
          "view"_a,
          "Renders `view` and returns it as a (height, width, 4) float32 array: scene-linear Rec.709\n"
          "RGBA, row 0 at the top.")
      .def(
          "render_into",
          [](PyRenderer& r, const snell::View& view, const py::object& out) {
            RendererState& state = r.get();
            if (!py::isinstance<py::array_t<float>>(out)) {
              throw snell::Error("render_into: out must be a numpy float32 array");
            }
            py::array a = py::reinterpret_borrow<py::array>(out);
            if (!a.writeable() || !(a.flags() & py::array::c_style)) {
              throw snell::Error("render_into: out must be writable and C-contiguous");
            }
            auto target = py::reinterpret_borrow<py::array_t<float, py::array::c_style>>(out);
            checkOutput(target, view);
            float* data = target.mutable_data();
            py::gil_scoped_release release;
            state.renderer.read(view, data);
          },
          "view"_a, "out"_a, "Renders `view` into a preallocated (height, width, 4) float32 array.")
      .def(
          "render_to",
          [](PyRenderer& r, const snell::View& view, const PySharedImage& image) {
            RendererState& state = r.get();
            snell::SharedImage& shared = image.get();
            snell::Target target = shared.target(VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
            py::gil_scoped_release release;
            state.renderer.wait(state.renderer.render(view, target));
          },
          "view"_a, "image"_a,
          "Renders `view` into a SharedImage and waits for the GPU: the pixels never visit the host.")
      .def(
          "render_aovs",
          [](PyRenderer& r, const snell::View& view) {
            RendererState& state = r.get();
            snell::Aovs aovs;
            {
              py::gil_scoped_release release;
              aovs = state.renderer.readAovs(view);
            }
            const py::ssize_t h = aovs.height, w = aovs.width;
            auto planes = [&](auto& values, std::vector<py::ssize_t> shape) {
              using T = typename std::decay_t<decltype(values)>::value_type;
              py::array_t<T> a(shape);
              std::copy(values.begin(), values.end(), a.mutable_data());
              return a;
            };
            py::dict out;
            out["rgba"] = planes(aovs.rgba, {h, w, 4});
            out["depth"] = planes(aovs.depth, {h, w});
            out["normal"] = planes(aovs.normal, {h, w, 3});
            out["instance"] = planes(aovs.instance, {h, w});
            out["primitive"] = planes(aovs.primitive, {h, w});
            out["interfaces"] = planes(aovs.interfaces, {h, w});
            out["cost"] = planes(aovs.cost, {h, w});
            return out;
          },
          "view"_a,
          "Traces every pixel of `view` and returns what each pixel's ray found, as numpy arrays:\n"
          "rgba (h, w, 4) float32 with alpha = coverage; depth (h, w) float32, camera-space, inf where\n"
          "nothing was hit; normal (h, w, 3) float32, world-space face normals; instance, primitive\n"
          "(h, w) uint32, 0xffffffff where nothing was hit; interfaces, cost (h, w) uint32. The method\n"
          "must trace (auto, trace or trace-1).")
      .def("last_frame", [](const PyRenderer& r) { return frameDict(r.get().renderer.lastFrame()); },
           "What the last frame did: counters and per-pass GPU milliseconds (pass_ms, gpu_ms).")
      .def("close", [](PyRenderer& r) { r.state.reset(); },
           "Lets go of the renderer's GPU memory (once no vertex view holds it).")
      .def("__enter__", [](PyRenderer& r) -> PyRenderer& { return r; })
      .def("__exit__", [](PyRenderer& r, const py::args&) { r.state.reset(); });
}

}  // namespace snell_python
