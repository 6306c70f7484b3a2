// None
#include "module_support.h"

namespace snell_python {

void bindMaterials(py::module_& m) {
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
             mat.alphaMode = kAlphaModes.parse(alpha, "alpha_mode");
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
          "alpha_mode", [](const snell::Material& mat) { return kAlphaModes.name(mat.alphaMode); },
          [](snell::Material& mat, const std::string& alpha) { mat.alphaMode = kAlphaModes.parse(alpha, "alpha_mode"); })
      .def_readwrite("alpha_cutoff", &snell::Material::alphaCutoff)
      .def_readwrite("base_color_transform", &snell::Material::baseColorTransform)
      .def_readwrite("emissive_transform", &snell::Material::emissiveTransform)
      .def_readwrite("normal_transform", &snell::Material::normalTransform);

  py::class_<snell::Light>(m, "Light", "A punctual light: candela for point and spot lights, lux for directional.")
      .def(py::init([](const std::string& type, const std::vector<float>& color, float intensity,
                       const std::vector<float>& position, const std::vector<float>& direction, float inner,
                       float outer) {
             snell::Light light;
             light.type = kLightTypes.parse(type, "light type");
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
      .def_property("type", [](const snell::Light& l) { return kLightTypes.name(l.type); },
                    [](snell::Light& l, const std::string& t) { l.type = kLightTypes.parse(t, "light type"); })
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
}

void bindGeometry(py::module_& m) {
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
                       const std::string& name, std::optional<snell::Subdivision> subdivision, py::object faceMaterials) {
             return PyMesh{std::move(positions), std::move(normals), std::move(indices), std::move(uvs), material, name,
                           std::move(subdivision), std::move(faceMaterials)};
           }),
           "positions"_a, "normals"_a, "indices"_a, "uvs"_a = py::none(), "material"_a = -1, "name"_a = "",
           "subdivision"_a = py::none(), "face_materials"_a = py::none(),
           "positions and normals: (n, 3) float32; indices: (m, 3) uint32, counted from 0;\n"
           "uvs: (n, 2) float32 or None; material: an index into the scene's materials (-1: grey).\n"
           "subdivision: a Subdivision, making the mesh a cage: indices are then its faces' corners (1-D\n"
           "uint32, subdivision.face_vertex_counts says how many each face has), normals may be None,\n"
           "and uvs are per vertex or, with subdivision.uv_indices, face-varying values.\n"
           "face_materials: a material per face (a cage's faces, else its triangles; -1: grey), or None:\n"
           "`material` for every face. Each material's faces draw from the mesh's one set of vertices, and\n"
           "a cage is refined once for all of them.")
      .def_readonly("subdivision", &PyMesh::subdivision)
      .def_readonly("positions", &PyMesh::positions)
      .def_readonly("normals", &PyMesh::normals)
      .def_readonly("indices", &PyMesh::indices)
      .def_readonly("uvs", &PyMesh::uvs)
      .def_readonly("face_materials", &PyMesh::faceMaterials)
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
             return PyTexture{std::move(rgba), name, kWraps.parse(wrapS, "texture wrap"), kWraps.parse(wrapT, "texture wrap"), nearest};
           }),
           "rgba"_a, "name"_a = "", "wrap_s"_a = "repeat", "wrap_t"_a = "repeat", "nearest"_a = false,
           "rgba: (height, width, 4) uint8. wrap_s, wrap_t: repeat, clamp or mirror across u and v;\n"
           "nearest: read the nearest texel, unfiltered.")
      .def_readonly("rgba", &PyTexture::rgba)
      .def_readwrite("name", &PyTexture::name)
      .def_property(
          "wrap_s", [](const PyTexture& t) { return kWraps.name(t.wrapS); },
          [](PyTexture& t, const std::string& wrap) { t.wrapS = kWraps.parse(wrap, "texture wrap"); })
      .def_property(
          "wrap_t", [](const PyTexture& t) { return kWraps.name(t.wrapT); },
          [](PyTexture& t, const std::string& wrap) { t.wrapT = kWraps.parse(wrap, "texture wrap"); })
      .def_readwrite("nearest", &PyTexture::nearest);
}

void bindScene(py::module_& m) {
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
}

}  // namespace snell_python
