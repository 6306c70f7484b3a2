// snell._snell: the public C++ API (include/snell/snell.h) for Python, and
// nothing below it. Arrays cross as numpy arrays, checked here so a wrong
// shape, dtype or index is a snell.Error naming the array and what is wrong.
// The GIL is released while snell waits for the GPU, so the host's other
// Python threads (a DCC's UI, a farm's heartbeat) keep running.
#include <snell/snell.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <unistd.h>
#include <vector>

namespace py = pybind11;
using namespace pybind11::literals;

namespace {

// ------------------------------------------------------------ arrays

// The dtype's name as numpy prints it ("float64").
std::string dtypeName(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

// `value` as a C-contiguous numpy array of `T` with `columns` columns (0: one
// dimension), or a snell.Error naming `what`: its dtype must be T's already
// (a silent float64 -> float32 cast would hide a host's mistake).
template <typename T>
py::array_t<T, py::array::c_style> checked(const py::handle& value, const std::string& what, size_t columns,
                                           const char* dtype) {
  if (!py::isinstance<py::array>(value)) {
    throw snell::Error(what + " must be a numpy array of " + dtype + ", got " +
                       py::str(py::type::of(value).attr("__name__")).cast<std::string>());
  }
  py::array a = py::reinterpret_borrow<py::array>(value);
  if (!py::isinstance<py::array_t<T>>(a)) {
    throw snell::Error(what + " must be " + dtype + ", got " + dtypeName(a) + " (convert with .astype(numpy." + dtype +
                       "))");
  }
  bool shaped = columns == 0 ? a.ndim() == 1 : a.ndim() == 2 && size_t(a.shape(1)) == columns;
  if (!shaped) {
    std::string shape = "(";
    for (py::ssize_t d = 0; d < a.ndim(); ++d) shape += (d ? ", " : "") + std::to_string(a.shape(d));
    shape += a.ndim() == 1 ? ",)" : ")";
    throw snell::Error(what + " must have shape " + (columns == 0 ? "(n,)" : "(n, " + std::to_string(columns) + ")") +
                       ", got " + shape);
  }
  return py::array_t<T, py::array::c_style>::ensure(a);
}

template <typename T>
std::vector<T> flat(const py::array_t<T, py::array::c_style>& a) {
  return std::vector<T>(a.data(), a.data() + a.size());
}

// A 4x4 matrix in numpy's (row, column) order, as printed and as Blender's
// mathutils.Matrix gives it, to snell's column-major Mat4.
snell::Mat4 toMat4(const py::handle& value, const std::string& what) {
  py::array_t<double, py::array::c_style | py::array::forcecast> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(py::array::ensure(value));
  } catch (const py::error_already_set&) {
  }
  if (!a || a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4) throw snell::Error(what + " must be a 4x4 matrix");
  snell::Mat4 m{};
  for (int row = 0; row < 4; ++row) {
    for (int column = 0; column < 4; ++column) {
      double v = a.at(row, column);
      if (!std::isfinite(v)) throw snell::Error(what + " is not finite");
      m[size_t(column * 4 + row)] = float(v);
    }
  }
  return m;
}

py::array_t<double> fromMat4(const snell::Mat4& m) {
  py::array_t<double> a({4, 4});
  for (int row = 0; row < 4; ++row) {
    for (int column = 0; column < 4; ++column) a.mutable_at(row, column) = m[size_t(column * 4 + row)];
  }
  return a;
}

// "  NAME  summary" per method, for View's docstring.
std::string methodList() {
  std::string list;
  for (const snell::MethodDescription& d : snell::methods()) list += "  " + d.name + "  " + d.summary + "\n";
  return list;
}

// The API's own default, so the module's keyword default cannot drift from it.
const snell::Vec3 kDefaultBackground = snell::View{}.background;

snell::Vec3 toVec3(const std::vector<float>& v, const std::string& what) {
  if (v.size() != 3) throw snell::Error(what + " needs 3 numbers, got " + std::to_string(v.size()));
  return {v[0], v[1], v[2]};
}

// ------------------------------------------------------------ the objects

// What Python holds: shared, so a renderer keeps its device and scene alive,
// and a numpy view of kept vertices keeps its renderer alive, whatever order
// Python drops or closes them in.
struct PyDevice {
  std::shared_ptr<snell::Device> device;
  snell::Device& get() const {
    if (!device) throw snell::Error("the device is closed");
    return *device;
  }
};

struct PyScene {
  std::shared_ptr<snell::Scene> scene;
  snell::Scene& get() const {
    if (!scene) throw snell::Error("the scene is closed");
    return *scene;
  }
};

struct RendererState {
  std::shared_ptr<snell::Device> device;
  std::shared_ptr<snell::Scene> scene;
  snell::Renderer renderer;
};

struct PyRenderer {
  std::shared_ptr<RendererState> state;
  RendererState& get() const {
    if (!state) throw snell::Error("the renderer is closed");
    return *state;
  }
};

struct PySharedImage {
  std::shared_ptr<snell::Device> device;
  std::unique_ptr<snell::SharedImage> image;
  snell::SharedImage& get() const {
    if (!image) throw snell::Error("the shared image is closed");
    return *image;
  }
};

// One mesh of Scene.from_arrays, kept as the caller's arrays until the scene is made.
struct PyMesh {
  py::object positions, normals, indices, uvs;
  int material = -1;
  std::string name;
  std::optional<snell::Subdivision> subdivision;  ///< a subdivision cage's scheme and tags
};

// Names as USD spells the UsdGeomMesh tokens, for Subdivision's string properties.
template <typename E>
struct TokenNames {
  std::vector<std::pair<E, const char*>> names;
  E parse(const std::string& name, const char* what) const {
    std::string known;
    for (const auto& [value, token] : names) {
      if (name == token) return value;
      known += (known.empty() ? "" : ", ") + std::string(token);
    }
    throw snell::Error(std::string(what) + " '" + name + "' is not one of " + known);
  }
  std::string name(E value) const {
    for (const auto& [v, token] : names) {
      if (v == value) return token;
    }
    return "";
  }
};
const TokenNames<snell::Subdivision::Scheme> kSchemes{{{snell::Subdivision::Scheme::None, "none"},
                                                       {snell::Subdivision::Scheme::CatmullClark, "catmullClark"},
                                                       {snell::Subdivision::Scheme::Loop, "loop"},
                                                       {snell::Subdivision::Scheme::Bilinear, "bilinear"}}};
const TokenNames<snell::Subdivision::Boundary> kBoundaries{{{snell::Subdivision::Boundary::None, "none"},
                                                            {snell::Subdivision::Boundary::EdgeOnly, "edgeOnly"},
                                                            {snell::Subdivision::Boundary::EdgeAndCorner, "edgeAndCorner"}}};
const TokenNames<snell::Subdivision::FaceVarying> kFaceVarying{{{snell::Subdivision::FaceVarying::None, "none"},
                                                                {snell::Subdivision::FaceVarying::CornersOnly, "cornersOnly"},
                                                                {snell::Subdivision::FaceVarying::CornersPlus1, "cornersPlus1"},
                                                                {snell::Subdivision::FaceVarying::CornersPlus2, "cornersPlus2"},
                                                                {snell::Subdivision::FaceVarying::Boundaries, "boundaries"},
                                                                {snell::Subdivision::FaceVarying::All, "all"}}};
const TokenNames<snell::Subdivision::Normals> kNormals{{{snell::Subdivision::Normals::Limit, "limit"},
                                                        {snell::Subdivision::Normals::Mesh, "mesh"}}};

// A 1-D array of uint32 (or a sequence of ints) for Subdivision's index lists.
std::vector<uint32_t> indexList(const py::handle& value, const char* what) {
  auto a = py::array_t<int64_t, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a || a.ndim() != 1) throw snell::Error(std::string("Subdivision.") + what + " must be a 1-D list of indices");
  std::vector<uint32_t> out;
  for (py::ssize_t i = 0; i < a.size(); ++i) {
    if (a.data()[i] < 0 || a.data()[i] > int64_t(UINT32_MAX)) {
      throw snell::Error(std::string("Subdivision.") + what + "[" + std::to_string(i) + "] is not an index");
    }
    out.push_back(uint32_t(a.data()[i]));
  }
  return out;
}
std::vector<float> floatList(const py::handle& value, const char* what) {
  auto a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
  if (!a || a.ndim() != 1) throw snell::Error(std::string("Subdivision.") + what + " must be a 1-D list of numbers");
  return std::vector<float>(a.data(), a.data() + a.size());
}

struct PyInstance {
  int mesh = 0;
  py::object transform;
};

struct PyTexture {
  py::object rgba;
  std::string name;
  snell::Texture::Wrap wrapS = snell::Texture::Wrap::Repeat, wrapT = snell::Texture::Wrap::Repeat;
  bool nearest = false;
};

snell::Texture::Wrap wrapMode(const std::string& name) {
  if (name == "repeat") return snell::Texture::Wrap::Repeat;
  if (name == "clamp") return snell::Texture::Wrap::Clamp;
  if (name == "mirror") return snell::Texture::Wrap::Mirror;
  throw snell::Error("texture wrap '" + name + "' is not repeat, clamp or mirror");
}

const char* wrapName(snell::Texture::Wrap wrap) {
  switch (wrap) {
    case snell::Texture::Wrap::Clamp: return "clamp";
    case snell::Texture::Wrap::Mirror: return "mirror";
    default: return "repeat";
  }
}

snell::Material::Alpha alphaMode(const std::string& name) {
  if (name == "opaque") return snell::Material::Alpha::Opaque;
  if (name == "mask") return snell::Material::Alpha::Mask;
  if (name == "blend") return snell::Material::Alpha::Blend;
  throw snell::Error("alpha_mode '" + name + "' is not opaque, mask or blend");
}

const char* alphaName(snell::Material::Alpha alpha) {
  switch (alpha) {
    case snell::Material::Alpha::Mask: return "mask";
    case snell::Material::Alpha::Blend: return "blend";
    default: return "opaque";
  }
}

snell::Light::Type lightType(const std::string& name) {
  if (name == "point") return snell::Light::Type::Point;
  if (name == "directional" || name == "sun") return snell::Light::Type::Directional;
  if (name == "spot") return snell::Light::Type::Spot;
  throw snell::Error("light type '" + name + "' is not point, directional or spot");
}

const char* lightTypeName(snell::Light::Type type) {
  switch (type) {
    case snell::Light::Type::Directional: return "directional";
    case snell::Light::Type::Spot: return "spot";
    default: return "point";
  }
}

snell::Scene sceneFromArrays(const std::vector<PyMesh>& meshes, const std::vector<snell::Material>& materials,
                             const std::vector<PyTexture>& textures, const std::optional<std::vector<PyInstance>>& instances,
                             const std::vector<snell::Light>& lights, const std::vector<snell::SceneCamera>& cameras,
                             const std::string& name) {
  snell::HostScene host;
  host.name = name;
  host.materials = materials;
  host.lights = lights;
  host.cameras = cameras;
  for (size_t i = 0; i < textures.size(); ++i) {
    std::string what = name + ": texture " + std::to_string(i) + " rgba";
    if (!py::isinstance<py::array>(textures[i].rgba)) throw snell::Error(what + " must be a numpy array of uint8");
    py::array a = py::reinterpret_borrow<py::array>(textures[i].rgba);
    if (!py::isinstance<py::array_t<uint8_t>>(a)) throw snell::Error(what + " must be uint8, got " + dtypeName(a));
    if (a.ndim() != 3 || a.shape(2) != 4 || a.shape(0) == 0 || a.shape(1) == 0) {
      throw snell::Error(what + " must have shape (height, width, 4)");
    }
    auto pixels = py::array_t<uint8_t, py::array::c_style>::ensure(a);
    snell::Texture& texture =
        host.textures.emplace_back(snell::Texture{textures[i].name, uint32_t(a.shape(1)), uint32_t(a.shape(0)),
                                                  std::vector<uint8_t>(pixels.data(), pixels.data() + pixels.size())});
    texture.wrapS = textures[i].wrapS;
    texture.wrapT = textures[i].wrapT;
    texture.nearest = textures[i].nearest;
  }
  for (size_t i = 0; i < meshes.size(); ++i) {
    const PyMesh& m = meshes[i];
    std::string what = name + ": mesh " + std::to_string(i) + (m.name.empty() ? "" : " ('" + m.name + "')");
    // A subdivision cage's indices are its faces' corners (1-D), its normals snell's to make.
    const bool cage = m.subdivision && m.subdivision->scheme != snell::Subdivision::Scheme::None;
    auto positions = checked<float>(m.positions, what + " positions", 3, "float32");
    std::optional<py::array_t<float, py::array::c_style>> normals;
    if (!(cage && m.normals.is_none())) normals = checked<float>(m.normals, what + " normals", 3, "float32");
    auto indices = checked<uint32_t>(m.indices, what + " indices", cage ? 0 : 3, "uint32");
    size_t n = size_t(positions.shape(0));
    if (normals && size_t(normals->shape(0)) != n) {
      throw snell::Error(what + ": " + std::to_string(normals->shape(0)) + " normals for " + std::to_string(n) +
                         " positions");
    }
    if (n == 0 || indices.shape(0) == 0) throw snell::Error(what + " has no vertices or no " + (cage ? "faces" : "triangles"));
    snell::Mesh mesh;
    mesh.name = m.name;
    mesh.vertexCount = uint32_t(n);
    mesh.material = m.material;
    mesh.indices = flat(indices);
    if (m.subdivision) mesh.subdivision = *m.subdivision;
    for (size_t k = 0; k < mesh.indices.size(); ++k) {
      if (mesh.indices[k] >= n) {
        throw snell::Error(what + " indices: " + (cage ? "corner " + std::to_string(k) : "triangle " + std::to_string(k / 3)) +
                           " names vertex " + std::to_string(mesh.indices[k]) + " of " + std::to_string(n));
      }
    }
    if (!m.uvs.is_none()) {
      auto uvs = checked<float>(m.uvs, what + " uvs", 2, "float32");
      const bool faceVarying = cage && !mesh.subdivision.uvIndices.empty();
      if (!faceVarying && size_t(uvs.shape(0)) != n) {
        throw snell::Error(what + ": " + std::to_string(uvs.shape(0)) + " uvs for " + std::to_string(n) + " positions");
      }
      mesh.texcoords = flat(uvs);
    }
    host.meshes.push_back(std::move(mesh));
    host.vertices.push_back(snell::MeshVertices{flat(positions), normals ? flat(*normals) : std::vector<float>{}});
  }
  if (instances) {
    for (size_t i = 0; i < instances->size(); ++i) {
      const PyInstance& in = (*instances)[i];
      snell::Mat4 transform = in.transform.is_none()
                                  ? snell::kIdentity
                                  : toMat4(in.transform, name + ": instance " + std::to_string(i) + " transform");
      host.instances.push_back(snell::Instance{in.mesh, transform});
    }
  } else {
    for (size_t i = 0; i < meshes.size(); ++i) host.instances.push_back(snell::Instance{int(i), snell::kIdentity});
  }
  return snell::Scene::fromHost(host);
}

// The view's pixels as the frame's (h, w, 4) float32 array.
void checkOutput(const py::array_t<float, py::array::c_style>& out, const snell::View& view) {
  if (out.ndim() != 3 || out.shape(0) != py::ssize_t(view.height) || out.shape(1) != py::ssize_t(view.width) ||
      out.shape(2) != 4) {
    throw snell::Error("render_into: out must have shape (" + std::to_string(view.height) + ", " +
                       std::to_string(view.width) + ", 4), the view's size");
  }
}

py::dict frameDict(const snell::FrameInfo& f) {
  py::dict passes;
  double total = 0.0;
  for (const snell::PassTime& p : f.passes) {
    passes[py::str(p.name)] = p.milliseconds;
    total += p.milliseconds;
  }
  return py::dict("frame"_a = f.frame, "method"_a = f.method, "skipped"_a = f.skipped,
                  "items_deformed"_a = f.itemsDeformed, "meshes_uploaded"_a = f.meshesUploaded,
                  "meshes_refined"_a = f.meshesRefined, "vertices_refined"_a = f.verticesRefined,
                  "trees_built"_a = f.treesBuilt, "trees_refit"_a = f.treesRefit, "trees_skipped"_a = f.treesSkipped,
                  "top_level_built"_a = f.topLevelBuilt, "top_level_refit"_a = f.topLevelRefit,
                  "pixels_traced"_a = f.pixelsTraced, "dispatches"_a = f.dispatches, "draws"_a = f.draws,
                  "pass_ms"_a = passes, "gpu_ms"_a = total);
}

// A writable (count, 3) float32 view of kept vertices whose base keeps the renderer alive.
py::array vertexView(const std::shared_ptr<RendererState>& state, float* data, uint32_t count) {
  auto* owner = new std::shared_ptr<RendererState>(state);
  py::capsule base(owner, [](void* p) { delete static_cast<std::shared_ptr<RendererState>*>(p); });
  return py::array_t<float>({py::ssize_t(count), py::ssize_t(3)}, data, base);
}

}  // namespace

PYBIND11_MODULE(_snell, m) {
  // pybind11 keeps the pointer it is given: the text lives as long as the module.
  static const std::string kViewDoc =
      "The camera: the scene's camera `camera` (an index), else view_matrix (world to camera)\n"
      "with projection (OpenGL: perspective or orthographic, off-centre for lens shift; its\n"
      "aspect must be width/height), else a look-at from eye to target with yfov radians.\n"
      "viewport=True draws the viewport composite: rasterised, with only the glass traced.\n"
      "environment: a snell.Environment the glass reflects (None: snell's studio gradient).\n"
      "method: auto (trace, or driver-rt where it times faster) or one of snell.methods():\n" +
      methodList();
  m.doc() = "snell: refraction through deforming meshes, ray traced by Vulkan compute.";
  m.attr("DEFAULT_YFOV") = snell::kDefaultYfov;  // radians: framed views' and View(yfov=)'s default
  py::register_exception<snell::Error>(m, "Error", PyExc_RuntimeError);
  m.def("version", &snell::version, "snell's version, 'major.minor.patch'.");
  m.def(
      "methods",
      [] {
        std::vector<std::pair<std::string, std::string>> all;
        for (const snell::MethodDescription& d : snell::methods()) all.emplace_back(d.name, d.summary);
        return all;
      },
      "The ways of drawing glass View(method=...) takes: (name, one-line summary) pairs.");
  m.def(
      "read_image_file",
      [](const std::string& path) -> py::array {
        snell::ImageFile image;
        {
          py::gil_scoped_release release;
          image = snell::readImageFile(path);
        }
        // array_t<T> takes its strides from sizeof(T): a py::array made from a py::dtype takes them from
        // the dtype's itemsize, which Debian's pybind11 (2.10) reads wrongly under numpy 2 (a plain venv's),
        // giving every sample the first one's bytes.
        auto samples = [&image](auto zero) -> py::array {
          py::array_t<decltype(zero)> out({py::ssize_t(image.height), py::ssize_t(image.width),
                                           py::ssize_t(image.channels)});
          std::memcpy(out.mutable_data(), image.data.data(), image.data.size());
          return out;
        };
        return image.bits == 32 ? samples(float{}) : image.bits == 16 ? samples(uint16_t{}) : samples(uint8_t{});
      },
      "path"_a,
      "An image file's samples as stored, (height, width, channels) with row 0 at the top: uint8, uint16 "
      "(16-bit PNG) or float32 (Radiance HDR). Decoded by stb_image, as snell's glTF loader decodes textures: "
      "PNG, JPEG, TGA, BMP, PSD, GIF, HDR, PIC, PNM; anything else raises snell.Error naming the file.");
  m.def(
      "write_png",
      [](const std::string& path, const py::array_t<float, py::array::c_style | py::array::forcecast>& rgba,
         bool alpha) {
        if (rgba.ndim() != 3 || rgba.shape(2) != 4) {
          throw snell::Error(path + ": the picture must be (height, width, 4) RGBA");
        }
        const float* data = rgba.data();
        auto width = uint32_t(rgba.shape(1)), height = uint32_t(rgba.shape(0));
        py::gil_scoped_release release;
        snell::writePng(path, width, height, data, alpha);
      },
      "path"_a, "rgba"_a, "alpha"_a = false,
      "Writes a (height, width, 4) scene-linear picture as an 8-bit sRGB PNG, as `snell render` does: complete "
      "or not at all (a temporary file renamed). Alpha is kept with alpha=True, else the PNG is opaque.");

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

  py::class_<snell::TextureTransform>(m, "TextureTransform",
                                      "How a material's texture reads its UVs (glTF's KHR_texture_transform).")
      .def(py::init([](const std::vector<float>& offset, float rotation, const std::vector<float>& scale) {
             if (offset.size() != 2 || scale.size() != 2) throw snell::Error("offset and scale need 2 numbers each");
             return snell::TextureTransform{{offset[0], offset[1]}, rotation, {scale[0], scale[1]}};
           }),
           "offset"_a = std::vector<float>{0, 0}, "rotation"_a = 0.0f, "scale"_a = std::vector<float>{1, 1},
           "uv' = translate(offset) * rotate(rotation, radians) * scale(scale) * uv.")
      .def_readwrite("offset", &snell::TextureTransform::offset)
      .def_readwrite("rotation", &snell::TextureTransform::rotation)
      .def_readwrite("scale", &snell::TextureTransform::scale)
      .def("__repr__", [](const snell::TextureTransform& t) {
        return "snell.TextureTransform(offset=(" + std::to_string(t.offset[0]) + ", " + std::to_string(t.offset[1]) +
               "), rotation=" + std::to_string(t.rotation) + ", scale=(" + std::to_string(t.scale[0]) + ", " +
               std::to_string(t.scale[1]) + "))";
      });

  py::class_<snell::Material>(m, "Material", "A glTF metallic-roughness material with transmission, IOR and volume.")
      .def(py::init([](const std::string& name, const std::vector<float>& baseColor, int baseColorTexture,
                       float transmission, float ior, float roughness, float thickness,
                       const std::vector<float>& attenuationColor, float attenuationDistance, bool doubleSided,
                       const std::vector<float>& emissive, float dispersion, int emissiveTexture, int normalTexture,
                       float normalScale, const std::string& alpha, float alphaCutoff,
                       const snell::TextureTransform& baseColorTransform, const snell::TextureTransform& emissiveTransform,
                       const snell::TextureTransform& normalTransform) {
             snell::Material mat;
             mat.name = name;
             if (baseColor.size() != 3 && baseColor.size() != 4) throw snell::Error("base_color needs 3 or 4 numbers");
             for (size_t c = 0; c < baseColor.size(); ++c) mat.baseColor[c] = baseColor[c];
             mat.baseColorTexture = baseColorTexture;
             mat.transmission = transmission;
             mat.ior = ior;
             mat.roughness = roughness;
             mat.thickness = thickness;
             mat.attenuationColor = toVec3(attenuationColor, "attenuation_color");
             mat.attenuationDistance = attenuationDistance;
             mat.doubleSided = doubleSided;
             mat.emissive = toVec3(emissive, "emissive");
             mat.dispersion = dispersion;
             mat.emissiveTexture = emissiveTexture;
             mat.normalTexture = normalTexture;
             mat.normalScale = normalScale;
             mat.alphaMode = alphaMode(alpha);
             mat.alphaCutoff = alphaCutoff;
             mat.baseColorTransform = baseColorTransform;
             mat.emissiveTransform = emissiveTransform;
             mat.normalTransform = normalTransform;
             return mat;
           }),
           "name"_a = "", "base_color"_a = std::vector<float>{1, 1, 1, 1}, "base_color_texture"_a = -1,
           "transmission"_a = 0.0f, "ior"_a = 1.5f, "roughness"_a = 1.0f, "thickness"_a = 0.0f,
           "attenuation_color"_a = std::vector<float>{1, 1, 1}, "attenuation_distance"_a = INFINITY,
           "double_sided"_a = false, "emissive"_a = std::vector<float>{0, 0, 0}, "dispersion"_a = 0.0f,
           "emissive_texture"_a = -1, "normal_texture"_a = -1, "normal_scale"_a = 1.0f, "alpha_mode"_a = "opaque",
           "alpha_cutoff"_a = 0.5f, "base_color_transform"_a = snell::TextureTransform{},
           "emissive_transform"_a = snell::TextureTransform{}, "normal_transform"_a = snell::TextureTransform{},
           "Colours are linear RGB(A). transmission > 0 makes the faces refract; thickness > 0 with\n"
           "a finite attenuation_distance gives the glass a volume; the *_texture arguments index\n"
           "Scene.from_arrays' textures (a normal map is glTF's: tangent space, +Y up the image).\n"
           "alpha_mode 'mask' or 'blend' lets base_color's alpha (times the texture's) show what is behind.")
      .def_readwrite("name", &snell::Material::name)
      .def_readwrite("base_color", &snell::Material::baseColor)
      .def_readwrite("base_color_texture", &snell::Material::baseColorTexture)
      .def_readwrite("transmission", &snell::Material::transmission)
      .def_readwrite("ior", &snell::Material::ior)
      .def_readwrite("roughness", &snell::Material::roughness)
      .def_readwrite("thickness", &snell::Material::thickness)
      .def_readwrite("attenuation_color", &snell::Material::attenuationColor)
      .def_readwrite("attenuation_distance", &snell::Material::attenuationDistance)
      .def_readwrite("double_sided", &snell::Material::doubleSided)
      .def_readwrite("emissive", &snell::Material::emissive)
      .def_readwrite("dispersion", &snell::Material::dispersion)
      .def_readwrite("emissive_texture", &snell::Material::emissiveTexture)
      .def_readwrite("normal_texture", &snell::Material::normalTexture)
      .def_readwrite("normal_scale", &snell::Material::normalScale)
      .def_property(
          "alpha_mode", [](const snell::Material& mat) { return std::string(alphaName(mat.alphaMode)); },
          [](snell::Material& mat, const std::string& alpha) { mat.alphaMode = alphaMode(alpha); })
      .def_readwrite("alpha_cutoff", &snell::Material::alphaCutoff)
      .def_readwrite("base_color_transform", &snell::Material::baseColorTransform)
      .def_readwrite("emissive_transform", &snell::Material::emissiveTransform)
      .def_readwrite("normal_transform", &snell::Material::normalTransform);

  py::class_<snell::Light>(m, "Light", "A punctual light: candela for point and spot lights, lux for directional.")
      .def(py::init([](const std::string& type, const std::vector<float>& color, float intensity,
                       const std::vector<float>& position, const std::vector<float>& direction, float inner,
                       float outer) {
             snell::Light light;
             light.type = lightType(type);
             light.color = toVec3(color, "color");
             light.intensity = intensity;
             light.position = toVec3(position, "position");
             light.direction = toVec3(direction, "direction");
             light.innerConeAngle = inner;
             light.outerConeAngle = outer;
             return light;
           }),
           "type"_a = "point", "color"_a = std::vector<float>{1, 1, 1}, "intensity"_a = 1.0f,
           "position"_a = std::vector<float>{0, 0, 0}, "direction"_a = std::vector<float>{0, 0, -1},
           "inner_cone_angle"_a = 0.0f, "outer_cone_angle"_a = 0.7853982f,
           "type: 'point', 'directional' or 'spot'; direction: where it shines (directional, spot);\n"
           "cone angles in radians (spot).")
      .def_property("type", [](const snell::Light& l) { return lightTypeName(l.type); },
                    [](snell::Light& l, const std::string& t) { l.type = lightType(t); })
      .def_readwrite("color", &snell::Light::color)
      .def_readwrite("intensity", &snell::Light::intensity)
      .def_readwrite("position", &snell::Light::position)
      .def_readwrite("direction", &snell::Light::direction)
      .def_readwrite("inner_cone_angle", &snell::Light::innerConeAngle)
      .def_readwrite("outer_cone_angle", &snell::Light::outerConeAngle);

  py::class_<snell::SceneCamera>(m, "Camera", "A camera of a scene made from arrays (View(camera=index) picks it).")
      .def(py::init([](const py::object& transform, bool orthographic, float yfov, float ymag, const std::string& name) {
             snell::SceneCamera c;
             if (!transform.is_none()) c.transform = toMat4(transform, "camera transform");
             c.orthographic = orthographic;
             c.yfov = yfov;
             c.ymag = ymag;
             c.name = name;
             return c;
           }),
           "transform"_a = py::none(), "orthographic"_a = false, "yfov"_a = float(snell::kDefaultYfov), "ymag"_a = 1.0f,
           "name"_a = "",
           "transform: camera to world (4x4, it looks down its -Z, +Y up); yfov in radians\n"
           "(perspective); ymag: half the view's height (orthographic).")
      .def_property_readonly("transform", [](const snell::SceneCamera& c) { return fromMat4(c.transform); })
      .def_readwrite("orthographic", &snell::SceneCamera::orthographic)
      .def_readwrite("yfov", &snell::SceneCamera::yfov)
      .def_readwrite("ymag", &snell::SceneCamera::ymag)
      .def_readwrite("name", &snell::SceneCamera::name);

  py::class_<snell::Subdivision>(
      m, "Subdivision",
      "How a Mesh is a subdivision surface, with USD's UsdGeomMesh tags: its indices are a cage's\n"
      "faces, which snell refines on the GPU whenever the vertices change (set_vertices).")
      .def(py::init([](const std::string& scheme, uint32_t level, const py::object& faceVertexCounts,
                       const std::string& boundary, const std::string& faceVarying, bool limitSurface,
                       const std::string& normals) {
             snell::Subdivision s;
             s.scheme = kSchemes.parse(scheme, "scheme");
             s.level = level;
             if (!faceVertexCounts.is_none()) s.faceVertexCounts = indexList(faceVertexCounts, "face_vertex_counts");
             s.interpolateBoundary = kBoundaries.parse(boundary, "interpolate_boundary");
             s.faceVarying = kFaceVarying.parse(faceVarying, "face_varying_linear_interpolation");
             s.limitSurface = limitSurface;
             s.normals = kNormals.parse(normals, "normals");
             return s;
           }),
           "scheme"_a = "catmullClark", "level"_a = 2, "face_vertex_counts"_a = py::none(),
           "interpolate_boundary"_a = "edgeAndCorner", "face_varying_linear_interpolation"_a = "cornersPlus1",
           "limit_surface"_a = false, "normals"_a = "mesh",
           "scheme: catmullClark, loop, bilinear or none; level: refinement levels (1 to 8);\n"
           "face_vertex_counts: vertices of each face (the Mesh's indices hold them, face after face);\n"
           "limit_surface: vertices on the limit surface (Blender's 'Use Limit Surface'), else refined;\n"
           "normals: mesh (the refined triangles', as Blender and usdview shade) or limit (the limit\n"
           "surface's tangents').")
      .def_property(
          "scheme", [](const snell::Subdivision& s) { return kSchemes.name(s.scheme); },
          [](snell::Subdivision& s, const std::string& v) { s.scheme = kSchemes.parse(v, "scheme"); })
      .def_readwrite("level", &snell::Subdivision::level)
      .def_property(
          "face_vertex_counts", [](const snell::Subdivision& s) { return s.faceVertexCounts; },
          [](snell::Subdivision& s, const py::object& v) { s.faceVertexCounts = indexList(v, "face_vertex_counts"); })
      .def_readwrite("left_handed", &snell::Subdivision::leftHanded)
      .def_property(
          "hole_indices", [](const snell::Subdivision& s) { return s.holeIndices; },
          [](snell::Subdivision& s, const py::object& v) { s.holeIndices = indexList(v, "hole_indices"); })
      .def_property(
          "crease_indices", [](const snell::Subdivision& s) { return s.creaseIndices; },
          [](snell::Subdivision& s, const py::object& v) { s.creaseIndices = indexList(v, "crease_indices"); })
      .def_property(
          "crease_lengths", [](const snell::Subdivision& s) { return s.creaseLengths; },
          [](snell::Subdivision& s, const py::object& v) { s.creaseLengths = indexList(v, "crease_lengths"); })
      .def_property(
          "crease_sharpnesses", [](const snell::Subdivision& s) { return s.creaseSharpnesses; },
          [](snell::Subdivision& s, const py::object& v) { s.creaseSharpnesses = floatList(v, "crease_sharpnesses"); },
          "One per crease, or one per edge of every crease; 10 or more: infinitely sharp.")
      .def_property(
          "corner_indices", [](const snell::Subdivision& s) { return s.cornerIndices; },
          [](snell::Subdivision& s, const py::object& v) { s.cornerIndices = indexList(v, "corner_indices"); })
      .def_property(
          "corner_sharpnesses", [](const snell::Subdivision& s) { return s.cornerSharpnesses; },
          [](snell::Subdivision& s, const py::object& v) { s.cornerSharpnesses = floatList(v, "corner_sharpnesses"); })
      .def_property(
          "interpolate_boundary", [](const snell::Subdivision& s) { return kBoundaries.name(s.interpolateBoundary); },
          [](snell::Subdivision& s, const std::string& v) {
            s.interpolateBoundary = kBoundaries.parse(v, "interpolate_boundary");
          })
      .def_property(
          "face_varying_linear_interpolation", [](const snell::Subdivision& s) { return kFaceVarying.name(s.faceVarying); },
          [](snell::Subdivision& s, const std::string& v) {
            s.faceVarying = kFaceVarying.parse(v, "face_varying_linear_interpolation");
          })
      .def_readwrite("smooth_triangles", &snell::Subdivision::smoothTriangles,
                     "triangleSubdivisionRule 'smooth' (Catmull-Clark only).")
      .def_readwrite("limit_surface", &snell::Subdivision::limitSurface)
      .def_property(
          "normals", [](const snell::Subdivision& s) { return kNormals.name(s.normals); },
          [](snell::Subdivision& s, const std::string& v) { s.normals = kNormals.parse(v, "normals"); })
      .def_property(
          "uv_indices", [](const snell::Subdivision& s) { return s.uvIndices; },
          [](snell::Subdivision& s, const py::object& v) { s.uvIndices = indexList(v, "uv_indices"); },
          "Face-varying uvs: one index per face corner into the Mesh's uvs (empty: uvs per vertex).")
      .def("__repr__", [](const snell::Subdivision& s) {
        return "<snell.Subdivision " + kSchemes.name(s.scheme) + " level " + std::to_string(s.level) + ", " +
               std::to_string(s.faceVertexCounts.size()) + " faces>";
      });

  py::class_<PyMesh>(m, "Mesh", "A triangle mesh from numpy arrays, for Scene.from_arrays.")
      .def(py::init([](py::object positions, py::object normals, py::object indices, py::object uvs, int material,
                       const std::string& name, std::optional<snell::Subdivision> subdivision) {
             return PyMesh{std::move(positions), std::move(normals), std::move(indices), std::move(uvs), material, name,
                           std::move(subdivision)};
           }),
           "positions"_a, "normals"_a, "indices"_a, "uvs"_a = py::none(), "material"_a = -1, "name"_a = "",
           "subdivision"_a = py::none(),
           "positions and normals: (n, 3) float32; indices: (m, 3) uint32, counted from 0;\n"
           "uvs: (n, 2) float32 or None; material: an index into the scene's materials (-1: grey).\n"
           "subdivision: a Subdivision, making the mesh a cage: indices are then its faces' corners (1-D\n"
           "uint32, subdivision.face_vertex_counts says how many each face has), normals may be None,\n"
           "and uvs are per vertex or, with subdivision.uv_indices, face-varying values.")
      .def_readonly("subdivision", &PyMesh::subdivision)
      .def_readonly("positions", &PyMesh::positions)
      .def_readonly("normals", &PyMesh::normals)
      .def_readonly("indices", &PyMesh::indices)
      .def_readonly("uvs", &PyMesh::uvs)
      .def_readwrite("material", &PyMesh::material)
      .def_readwrite("name", &PyMesh::name);

  py::class_<PyInstance>(m, "Instance", "A mesh placed in the world.")
      .def(py::init([](int mesh, py::object transform) { return PyInstance{mesh, std::move(transform)}; }), "mesh"_a,
           "transform"_a = py::none(), "transform: mesh space to world (4x4; None: the identity).")
      .def_readwrite("mesh", &PyInstance::mesh)
      .def_readonly("transform", &PyInstance::transform);

  py::class_<PyTexture>(m, "Texture",
                        "An 8-bit RGBA texture, row 0 at the top: sRGB colour, or data for a normal map.")
      .def(py::init([](py::object rgba, const std::string& name, const std::string& wrapS, const std::string& wrapT,
                       bool nearest) {
             return PyTexture{std::move(rgba), name, wrapMode(wrapS), wrapMode(wrapT), nearest};
           }),
           "rgba"_a, "name"_a = "", "wrap_s"_a = "repeat", "wrap_t"_a = "repeat", "nearest"_a = false,
           "rgba: (height, width, 4) uint8. wrap_s, wrap_t: repeat, clamp or mirror across u and v;\n"
           "nearest: read the nearest texel, unfiltered.")
      .def_readonly("rgba", &PyTexture::rgba)
      .def_readwrite("name", &PyTexture::name)
      .def_property(
          "wrap_s", [](const PyTexture& t) { return std::string(wrapName(t.wrapS)); },
          [](PyTexture& t, const std::string& wrap) { t.wrapS = wrapMode(wrap); })
      .def_property(
          "wrap_t", [](const PyTexture& t) { return std::string(wrapName(t.wrapT)); },
          [](PyTexture& t, const std::string& wrap) { t.wrapT = wrapMode(wrap); })
      .def_readwrite("nearest", &PyTexture::nearest);

  py::class_<PyScene>(m, "Scene", "What is drawn: a glTF file, or meshes from numpy arrays.")
      .def_static(
          "load",
          [](const std::string& path) {
            py::gil_scoped_release release;
            return PyScene{std::make_shared<snell::Scene>(snell::Scene::load(path))};
          },
          "path"_a, "Loads a glTF 2.0 file (.gltf or .glb); raises snell.Error naming the file and the problem.")
      .def_static(
          "from_arrays",
          [](const std::vector<PyMesh>& meshes, const std::vector<snell::Material>& materials,
             const std::vector<PyTexture>& textures, const std::optional<std::vector<PyInstance>>& instances,
             const std::vector<snell::Light>& lights, const std::vector<snell::SceneCamera>& cameras,
             const std::string& name) {
            return PyScene{std::make_shared<snell::Scene>(
                sceneFromArrays(meshes, materials, textures, instances, lights, cameras, name))};
          },
          "meshes"_a, "materials"_a = std::vector<snell::Material>{}, "textures"_a = std::vector<PyTexture>{},
          "instances"_a = py::none(), "lights"_a = std::vector<snell::Light>{},
          "cameras"_a = std::vector<snell::SceneCamera>{}, "name"_a = "arrays",
          "A scene of Mesh arrays (copied). instances: Instance list (None: each mesh once, in place).\n"
          "No lights: a headlight. Each Renderer keeps the vertices, and takes new ones each frame\n"
          "(Renderer.set_vertices, or writes into Renderer.positions/normals then mark_dirty).")
      .def_property_readonly("name", [](const PyScene& s) { return s.get().name(); })
      .def_property_readonly("mesh_count", [](const PyScene& s) { return s.get().meshCount(); })
      .def_property_readonly("camera_count", [](const PyScene& s) { return s.get().cameraCount(); })
      .def_property_readonly("duration", [](const PyScene& s) { return s.get().duration(); },
                             "The longest animation in seconds (0: static).")
      .def("vertex_count", [](const PyScene& s, int mesh) { return s.get().vertexCount(mesh); }, "mesh"_a,
           "The vertices the mesh's arrays hold (a subdivision cage's).")
      .def("drawn_vertex_count", [](const PyScene& s, int mesh) { return s.get().drawnVertexCount(mesh); }, "mesh"_a,
           "The vertices it is drawn with (a subdivision surface's refined ones).")
      .def("drawn_triangle_count", [](const PyScene& s, int mesh) { return s.get().drawnTriangleCount(mesh); },
           "mesh"_a)
      .def_property_readonly("warnings", [](const PyScene& s) { return s.get().warnings(); },
                             "What loading repaired or left out, each naming its file or mesh.")
      .def("close", [](PyScene& s) { s.scene.reset(); })
      .def("__enter__", [](PyScene& s) -> PyScene& { return s; })
      .def("__exit__", [](PyScene& s, const py::args&) { s.scene.reset(); })
      .def("__repr__", [](const PyScene& s) {
        return s.scene ? "<snell.Scene '" + s.scene->name() + "', " + std::to_string(s.scene->meshCount()) + " meshes>"
                       : std::string("<snell.Scene (closed)>");
      });

  py::class_<snell::Environment>(m, "Environment",
                                 "What glass reflects: an equirectangular (lat-long) map of linear RGB radiance,\n"
                                 "row 0 looking up (+Y), the middle column looking down -Z, +X right of it.")
      .def(py::init([](const py::array_t<float, py::array::c_style | py::array::forcecast>& rgb,
                       const std::string& name) {
             if (rgb.ndim() != 3 || rgb.shape(2) != 3) {
               throw snell::Error(name + ": an environment must be (height, width, 3) RGB");
             }
             const float* data = rgb.data();
             auto width = uint32_t(rgb.shape(1)), height = uint32_t(rgb.shape(0));
             py::gil_scoped_release release;
             return snell::Environment::fromPixels(width, height, data, name);
           }),
           "rgb"_a, "name"_a = "environment",
           "rgb: (height, width, 3) float32, row 0 at the top, each value finite and 0 or more (copied;\n"
           "one wider than 4096 texels is halved until it fits). A View takes it as environment=.")
      .def_property_readonly("width", &snell::Environment::width)
      .def_property_readonly("height", &snell::Environment::height)
      .def_property_readonly("name", &snell::Environment::name)
      .def("__repr__", [](const snell::Environment& e) {
        return "<snell.Environment '" + e.name() + "', " + std::to_string(e.width()) + "x" +
               std::to_string(e.height()) + ">";
      });

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
      .def(py::init([](const PyDevice& device, const PyScene& scene, uint32_t framesInFlight) {
             snell::RendererOptions options;
             options.framesInFlight = framesInFlight;
             std::shared_ptr<snell::Device> d = device.device;
             std::shared_ptr<snell::Scene> s = scene.scene;
             if (!d) throw snell::Error("the device is closed");
             if (!s) throw snell::Error("the scene is closed");
             py::gil_scoped_release release;
             snell::Renderer r(*d, *s, options);
             return PyRenderer{std::make_shared<RendererState>(RendererState{d, s, std::move(r)})};
           }),
           "device"_a, "scene"_a, "frames_in_flight"_a = 2, "Uploads the scene to the device.")
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
