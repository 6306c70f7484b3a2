// None
#include "module_support.h"

namespace snell_python {

void bindShots(py::module_& m) {
  py::class_<snell::ShotFrame>(m, "ShotFrame",
                               "One frame of a shot (render_frames): a time, and what the host changes at it.\n\n"
                               "Each device keeps the vertices the frames it drew gave: a mesh one frame rewrites\n"
                               "should come in every frame, or a frame's pixels would depend on its device.")
      .def(py::init([](long number, double seconds, const py::object& viewMatrix, const py::object& projection,
                       const py::dict& transforms, const py::dict& vertices) {
             snell::ShotFrame f;
             f.number = number;
             f.seconds = seconds;
             const std::string what = "frame " + std::to_string(number);
             if (viewMatrix.is_none() != projection.is_none()) {
               throw snell::Error(what + ": give view_matrix and projection together");
             }
             if (!viewMatrix.is_none()) {
               f.camera = snell::CameraMatrices{toMat4(viewMatrix, what + " view_matrix"),
                                                toMat4(projection, what + " projection")};
             }
             for (const auto& [instance, matrix] : transforms) {
               const size_t i = instance.cast<size_t>();
               f.transforms.emplace_back(i, toMat4(matrix, what + ": instance " + std::to_string(i) + " transform"));
             }
             for (const auto& [mesh, arrays] : vertices) {
               const int k = mesh.cast<int>();
               const std::string where = what + ": mesh " + std::to_string(k);
               auto pair = arrays.cast<py::tuple>();
               if (pair.size() != 2) throw snell::Error(where + ": give (positions, normals)");
               auto p = checked<float>(pair[0], where + " positions", 3, "float32");
               auto n = checked<float>(pair[1], where + " normals", 3, "float32");
               f.vertices.emplace_back(k, snell::MeshVertices{flat(p), flat(n)});
             }
             return f;
           }),
           "number"_a, "seconds"_a = 0.0, "view_matrix"_a = py::none(), "projection"_a = py::none(),
           "transforms"_a = py::dict(), "vertices"_a = py::dict(),
           "`number` comes back with the picture; `seconds` poses a glTF scene's animation. The host's\n"
           "own animation at this frame: view_matrix and projection (the camera, as View.set_matrices\n"
           "takes them), transforms {instance: 4x4} and vertices {mesh: (positions, normals)}, (n, 3)\n"
           "float32 each, for a scene made from arrays.")
      .def_readonly("number", &snell::ShotFrame::number)
      .def_readonly("seconds", &snell::ShotFrame::seconds);

  m.def(
      "render_frames",
      [](const PyScene& scene, const snell::View& view, const py::iterable& frames, const py::function& onFrame,
         const std::string& devices, const std::string& device, bool validation, bool driverRayTracing) {
        std::shared_ptr<snell::Scene> s = scene.scene;
        if (!s) throw snell::Error("the scene is closed");
        snell::DeviceOptions options;
        options.device = device;
        options.validation = validation;
        options.driverRayTracing = driverRayTracing;
        py::iterator it = py::iter(frames);
        long position = 0;
        // A Python exception in the frames or the callback stops the shot and is raised as itself.
        std::optional<py::error_already_set> raised;
        auto callPython = [&](auto&& body) {
          py::gil_scoped_acquire acquire;
          try {
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
            return body();
          } catch (py::error_already_set& e) {
            raised.emplace(std::move(e));
            throw snell::Error("render_frames: stopped by a Python exception");
          }
        };
        auto next = [&]() -> std::optional<snell::ShotFrame> {
          return callPython([&]() -> std::optional<snell::ShotFrame> {
            if (it == py::iterator::sentinel()) return std::nullopt;
            py::handle item = *it;
            std::optional<snell::ShotFrame> frame;
            if (py::isinstance<snell::ShotFrame>(item)) {
              frame = item.cast<snell::ShotFrame>();
            } else if (py::isinstance<py::int_>(item) || py::isinstance<py::float_>(item)) {
              frame = snell::ShotFrame{position, item.cast<double>(), std::nullopt, {}, {}};
            } else {
              throw snell::Error("render_frames: frame " + std::to_string(position) +
                                 " must be a snell.ShotFrame or a time in seconds");
            }
            ++position;
            ++it;
            return frame;
          });
        };
        auto done = [&](snell::ShotPicture&& p) {
          callPython([&] {
            py::array_t<float> rgba({py::ssize_t(p.height), py::ssize_t(p.width), py::ssize_t(4)});
            std::copy(p.rgba.begin(), p.rgba.end(), rgba.mutable_data());
            onFrame(py::dict("number"_a = p.number, "seconds"_a = p.seconds, "rgba"_a = rgba, "worker"_a = p.worker,
                             "device"_a = p.device, "method"_a = p.method));
          });
        };
        snell::ShotSummary summary;
        try {
          py::gil_scoped_release release;
          summary = snell::renderFrames(devices, *s, view, next, done, options);
        } catch (const snell::Error&) {
          if (raised) throw std::move(*raised);
          throw;
        }
        py::list workers;
        for (const snell::ShotSummary::Worker& w : summary.workers) {
          workers.append(py::dict("device"_a = w.device, "frames"_a = w.frames, "load_seconds"_a = w.loadSeconds,
                                  "gpu_wait_seconds"_a = w.gpuWaitSeconds, "lost"_a = w.lost,
                                  "validation_messages"_a = w.validationMessages));
        }
        return py::dict("frames"_a = summary.frames, "seconds"_a = summary.seconds, "workers"_a = workers);
      },
      "scene"_a, "view"_a, "frames"_a, "on_frame"_a, "devices"_a = "all", "device"_a = "", "validation"_a = false,
      "driver_ray_tracing"_a = false,
      "Renders a shot on several GPUs: each of `frames` (snell.ShotFrame, or times in seconds,\n"
      "numbered from 0) as `view` sets it up, one worker per device of `devices` ('all', or indices\n"
      "'0,1'; one twice gives two workers on it; '': the one `device` names, as snell.Device takes\n"
      "it), each with its own device, upload and trees.\n"
      "on_frame(picture) gets each frame as it finishes, on this thread: a dict of number, seconds,\n"
      "rgba ((height, width, 4) float32, row 0 at the top), worker, device and method. The frames\n"
      "are read a few ahead of the GPUs, so a generator may pose a DCC's scene for each. A frame's\n"
      "pixels do not depend on the device that drew it. Returns what each worker did (device, frames,\n"
      "load_seconds, gpu_wait_seconds, lost, validation_messages).");
}

}  // namespace snell_python
