// What the bindings of snell._snell share: numpy arrays checked into the
// public API's types (a wrong shape, dtype or index is a snell.Error naming
// the array), the objects Python holds, and the names of every enum a
// property takes as a string. Only the public API (include/snell/snell.h)
// is below it.
#pragma once

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
#include <vector>

namespace snell_python {

namespace py = pybind11;
using namespace pybind11::literals;

// ------------------------------------------------------------ arrays

// The dtype's name as numpy prints it ("float64").
inline std::string dtypeName(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

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
inline snell::Mat4 toMat4(const py::handle& value, const std::string& what) {
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

inline py::array_t<double> fromMat4(const snell::Mat4& m) {
  py::array_t<double> a({4, 4});
  for (int row = 0; row < 4; ++row) {
    for (int column = 0; column < 4; ++column) a.mutable_at(row, column) = m[size_t(column * 4 + row)];
  }
  return a;
}

// "  NAME  summary" per method, for View's docstring.
inline std::string methodList() {
  std::string list;
  for (const snell::MethodDescription& d : snell::methods()) list += "  " + d.name + "  " + d.summary + "\n";
  return list;
}

// The API's own default, so the module's keyword default cannot drift from it.
const snell::Vec3 kDefaultBackground = snell::View{}.background;

inline snell::Vec3 toVec3(const std::vector<float>& v, const std::string& what) {
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
  py::object faceMaterials;  ///< None, or a material per face (snell::Mesh::faceMaterials)
};

// The names Python gives an enum (UsdGeomMesh's tokens for Subdivision's), both ways: every enum
// a property takes as a string is named here, once.
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
inline const TokenNames<snell::Subdivision::Scheme> kSchemes{{{snell::Subdivision::Scheme::None, "none"},
                                                       {snell::Subdivision::Scheme::CatmullClark, "catmullClark"},
                                                       {snell::Subdivision::Scheme::Loop, "loop"},
                                                       {snell::Subdivision::Scheme::Bilinear, "bilinear"}}};
inline const TokenNames<snell::Subdivision::Boundary> kBoundaries{{{snell::Subdivision::Boundary::None, "none"},
                                                            {snell::Subdivision::Boundary::EdgeOnly, "edgeOnly"},
                                                            {snell::Subdivision::Boundary::EdgeAndCorner, "edgeAndCorner"}}};
inline const TokenNames<snell::Subdivision::FaceVarying> kFaceVarying{{{snell::Subdivision::FaceVarying::None, "none"},
                                                                {snell::Subdivision::FaceVarying::CornersOnly, "cornersOnly"},
                                                                {snell::Subdivision::FaceVarying::CornersPlus1, "cornersPlus1"},
                                                                {snell::Subdivision::FaceVarying::CornersPlus2, "cornersPlus2"},
                                                                {snell::Subdivision::FaceVarying::Boundaries, "boundaries"},
                                                                {snell::Subdivision::FaceVarying::All, "all"}}};
inline const TokenNames<snell::Subdivision::Normals> kNormals{{{snell::Subdivision::Normals::Limit, "limit"},
                                                        {snell::Subdivision::Normals::Mesh, "mesh"}}};

// A 1-D array of uint32 (or a sequence of ints) for Subdivision's index lists.
inline std::vector<uint32_t> indexList(const py::handle& value, const char* what) {
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
inline std::vector<float> floatList(const py::handle& value, const char* what) {
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

inline const TokenNames<snell::Texture::Wrap> kWraps{{{snell::Texture::Wrap::Repeat, "repeat"},
                                                    {snell::Texture::Wrap::Clamp, "clamp"},
                                                    {snell::Texture::Wrap::Mirror, "mirror"}}};
inline const TokenNames<snell::Material::Alpha> kAlphaModes{{{snell::Material::Alpha::Opaque, "opaque"},
                                                            {snell::Material::Alpha::Mask, "mask"},
                                                            {snell::Material::Alpha::Blend, "blend"}}};
// "sun" is Blender's name for a directional light; the first name is the one read back.
inline const TokenNames<snell::Light::Type> kLightTypes{{{snell::Light::Type::Point, "point"},
                                                        {snell::Light::Type::Directional, "directional"},
                                                        {snell::Light::Type::Directional, "sun"},
                                                        {snell::Light::Type::Spot, "spot"}}};

inline snell::Scene sceneFromArrays(const std::vector<PyMesh>& meshes, const std::vector<snell::Material>& materials,
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
    if (!m.faceMaterials.is_none()) {
      auto faceMaterials = py::array_t<int32_t, py::array::c_style | py::array::forcecast>::ensure(m.faceMaterials);
      if (!faceMaterials || faceMaterials.ndim() != 1) {
        throw snell::Error(what + " face_materials must be a 1-D sequence of material indices");
      }
      mesh.faceMaterials.assign(faceMaterials.data(), faceMaterials.data() + faceMaterials.size());
    }
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
inline void checkOutput(const py::array_t<float, py::array::c_style>& out, const snell::View& view) {
  if (out.ndim() != 3 || out.shape(0) != py::ssize_t(view.height) || out.shape(1) != py::ssize_t(view.width) ||
      out.shape(2) != 4) {
    throw snell::Error("render_into: out must have shape (" + std::to_string(view.height) + ", " +
                       std::to_string(view.width) + ", 4), the view's size");
  }
}

inline py::dict frameDict(const snell::FrameInfo& f) {
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
inline py::array vertexView(const std::shared_ptr<RendererState>& state, float* data, uint32_t count) {
  auto* owner = new std::shared_ptr<RendererState>(state);
  py::capsule base(owner, [](void* p) { delete static_cast<std::shared_ptr<RendererState>*>(p); });
  return py::array_t<float>({py::ssize_t(count), py::ssize_t(3)}, data, base);
}

// Each binds one part of the module (bind_*.cpp), in the order snell_module.cpp calls them.
void bindImages(py::module_& m);
void bindDevice(py::module_& m);
void bindMaterials(py::module_& m);
void bindGeometry(py::module_& m);
void bindScene(py::module_& m);
void bindView(py::module_& m);
void bindRenderer(py::module_& m);
void bindShots(py::module_& m);

}  // namespace snell_python
