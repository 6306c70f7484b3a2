"""UsdPreviewSurface materials, their bindings and textures, as snell materials."""

from __future__ import annotations

import numpy as np
import pytest
from pxr import UsdShade

import snell.usd
from stages import bind, connect, mesh, new_stage, preview_material, quad, texture, transform2d, write_rgba_png


def read_quad(tmp_path, build, **read_options):
    """Reads a stage with one quad /World/Quad after build(stage, prim) binds its materials."""
    stage = new_stage(tmp_path / "quad.usda")
    prim = quad(stage, "/World/Quad").GetPrim()
    build(stage, prim)
    stage.GetRootLayer().Save()
    contents = snell.usd.read(tmp_path / "quad.usda", **read_options)
    contents.snell_meshes()
    return contents


def material_of(contents, part: int = 0):
    return contents.materials.records[contents.sources[0].parts[part].material]


def messages(contents) -> str:
    return "\n".join(str(w) for w in contents.problems.items)


def test_the_preview_material_wins_over_the_full_one(tmp_path):
    def build(stage, prim):
        bind(prim, preview_material(stage, "/World/Full", diffuseColor=(1.0, 0.0, 0.0)), UsdShade.Tokens.full)
        bind(prim, preview_material(stage, "/World/Preview", diffuseColor=(0.0, 1.0, 0.0)), UsdShade.Tokens.preview)

    assert material_of(read_quad(tmp_path, build)).path == "/World/Preview"
    assert material_of(read_quad(tmp_path, build, purpose="full")).path == "/World/Full"


def test_without_a_preview_binding_the_all_purpose_material_is_used(tmp_path):
    def build(stage, prim):
        bind(prim, preview_material(stage, "/World/Full", diffuseColor=(1.0, 0.0, 0.0)), UsdShade.Tokens.full)
        bind(prim, preview_material(stage, "/World/Any", diffuseColor=(0.2, 0.4, 0.6)))

    record = material_of(read_quad(tmp_path, build))
    assert record.path == "/World/Any"
    np.testing.assert_allclose(record.fields["base_color"], (0.2, 0.4, 0.6, 1.0), rtol=1e-6)


def test_an_unbound_mesh_takes_the_preview_fallbacks_and_its_display_color(tmp_path):
    def build(stage, prim):
        from pxr import UsdGeom

        UsdGeom.Gprim(prim).CreateDisplayColorPrimvar().Set([(0.5, 0.25, 0.125)])

    record = material_of(read_quad(tmp_path, build))
    assert record.path == ""
    np.testing.assert_allclose(record.fields["base_color"], (0.5, 0.25, 0.125, 1.0), rtol=1e-6)
    assert record.fields["roughness"] == 0.5 and record.fields["ior"] == 1.5 and record.fields["transmission"] == 0
    unbound = material_of(read_quad(tmp_path, lambda stage, prim: None))
    np.testing.assert_allclose(unbound.fields["base_color"], (0.18, 0.18, 0.18, 1.0), rtol=1e-6)


def test_unauthored_inputs_take_the_preview_surface_fallbacks(tmp_path):
    record = material_of(read_quad(tmp_path, lambda stage, prim: bind(prim, preview_material(stage, "/World/M"))))
    fields = record.fields
    np.testing.assert_allclose(fields["base_color"], (0.18, 0.18, 0.18, 1.0), rtol=1e-6)
    assert (fields["roughness"], fields["ior"], fields["transmission"]) == (0.5, 1.5, 0.0)
    assert tuple(fields["emissive"]) == (0.0, 0.0, 0.0)


def test_opacity_below_one_is_glass_with_the_materials_ior(tmp_path):
    def build(stage, prim):
        bind(prim, preview_material(stage, "/World/Glass", opacity=0.25, ior=1.33, diffuseColor=(0.9, 1.0, 0.95)))

    fields = material_of(read_quad(tmp_path, build)).fields
    assert fields["transmission"] == pytest.approx(0.75) and fields["ior"] == pytest.approx(1.33)
    np.testing.assert_allclose(fields["base_color"], (0.9, 1.0, 0.95, 1.0), rtol=1e-6)


def test_an_opacity_threshold_is_a_mask_cut_at_the_threshold(tmp_path):
    def build(stage, prim):
        bind(prim, preview_material(stage, "/World/Leaf", opacity=0.2, opacityThreshold=0.5))

    contents = read_quad(tmp_path, build)
    fields = material_of(contents).fields
    assert (fields["alpha_mode"], fields["alpha_cutoff"], fields["transmission"]) == ("mask", 0.5, 0.0)
    assert fields["base_color"][3] == pytest.approx(0.2)
    assert not contents.problems.items


def test_presence_opacity_is_blended_coverage_not_glass(tmp_path):
    def build(stage, prim):
        bind(prim, preview_material(stage, "/World/Veil", opacity=0.4, opacityMode="presence"))

    fields = material_of(read_quad(tmp_path, build)).fields
    assert (fields["alpha_mode"], fields["transmission"]) == ("blend", 0.0)
    assert fields["base_color"][3] == pytest.approx(0.4)


def test_opacity_from_the_diffuse_textures_alpha_is_the_base_colour_textures_alpha(tmp_path):
    rgba = np.random.default_rng(3).integers(0, 256, (4, 4, 4), dtype=np.uint8)
    write_rgba_png(tmp_path / "leaf.png", rgba)

    def build(stage, prim):
        material = preview_material(stage, "/World/Leaf", opacityThreshold=0.3)
        connect(material, "opacity", texture(stage, material, "./leaf.png", sourceColorSpace="sRGB"), "a")
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    record = material_of(contents)
    assert (record.fields["alpha_mode"], record.fields["alpha_cutoff"]) == ("mask", pytest.approx(0.3))
    assert record.fields["base_color"] == (1.0, 1.0, 1.0, 1.0)
    np.testing.assert_array_equal(contents.materials.textures[record.slots["base_color"].index].rgba, rgba)


def test_opacity_from_another_texture_prim_of_the_diffuse_file_is_its_alpha_with_that_prims_scale(tmp_path):
    rgba = np.random.default_rng(4).integers(0, 256, (4, 4, 4), dtype=np.uint8)
    write_rgba_png(tmp_path / "leaf.png", rgba)

    def build(stage, prim):
        material = preview_material(stage, "/World/Leaf", opacityMode="presence")
        texture(stage, material, "./leaf.png", sourceColorSpace="sRGB")
        texture(stage, material, "./leaf.png", input_name="opacity", output="a", scale=(1.0, 1.0, 1.0, 0.5))
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    assert len(contents.materials.textures) == 1 and material_of(contents).fields["alpha_mode"] == "blend"
    texels = contents.materials.textures[0].rgba
    np.testing.assert_array_equal(texels[..., :3], rgba[..., :3])
    np.testing.assert_allclose(texels[..., 3], rgba[..., 3] * 0.5, atol=0.5)  # rounded to the nearest byte


def test_an_opacity_texture_under_a_constant_diffuse_colour_is_a_white_texture_with_its_alpha(tmp_path):
    grey = np.random.default_rng(5).integers(0, 256, (4, 4, 3), dtype=np.uint8)
    write_rgba_png(tmp_path / "mask.png", grey)

    def build(stage, prim):
        material = preview_material(stage, "/World/Stencil", diffuseColor=(0.9, 0.5, 0.3), opacityThreshold=0.5)
        texture(stage, material, "./mask.png", input_name="opacity", output="r", sourceColorSpace="raw")
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    record = material_of(contents)
    np.testing.assert_allclose(record.fields["base_color"], (0.9, 0.5, 0.3, 1.0), rtol=1e-6)
    texels = contents.materials.textures[record.slots["base_color"].index].rgba
    assert (texels[..., :3] == 255).all()
    np.testing.assert_array_equal(texels[..., 3], grey[..., 0])


def test_opacity_from_another_file_than_the_diffuse_one_is_a_warning_naming_the_prim(tmp_path):
    write_rgba_png(tmp_path / "colour.png", np.zeros((2, 2, 3), np.uint8))
    write_rgba_png(tmp_path / "mask.png", np.zeros((2, 2, 4), np.uint8))

    def build(stage, prim):
        material = preview_material(stage, "/World/Leaf", opacityThreshold=0.5)
        texture(stage, material, "./colour.png")
        texture(stage, material, "./mask.png", input_name="opacity", output="a")
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    assert material_of(contents).fields.get("alpha_mode", "opaque") == "opaque"
    assert ("/World/Leaf/Surface: inputs:opacity reads /World/Leaf/Texture_opacity (./mask.png), another file "
            "than the diffuse texture /World/Leaf/Texture_diffuseColor (./colour.png); snell's alpha is its base "
            "colour texture's alpha") in messages(contents)


def test_a_textured_opacity_without_a_threshold_blends_as_gltfs_blend(tmp_path):
    mask = np.random.default_rng(6).integers(0, 256, (4, 4, 4), dtype=np.uint8)
    write_rgba_png(tmp_path / "mask.png", mask)

    def build(stage, prim):
        material = preview_material(stage, "/World/Pane", diffuseColor=(0.2, 0.4, 0.6))
        texture(stage, material, "./mask.png", input_name="opacity", output="a")
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    record = material_of(contents)
    assert record.fields["transmission"] == 0.0 and record.fields["alpha_mode"] == "blend"
    texels = contents.materials.textures[record.slots["base_color"].index].rgba
    np.testing.assert_array_equal(texels[..., 3], mask[..., 3])
    assert "coverage: opacity blends" in record.summary and not contents.problems.items


def test_glass_whose_diffuse_color_is_unset_transmits_clear_light(tmp_path):
    def build(stage, prim):
        bind(prim, preview_material(stage, "/World/Glass", opacity=0.0, ior=1.5))

    record = material_of(read_quad(tmp_path, build))
    assert record.fields["transmission"] == 1.0 and record.fields["base_color"] == (1.0, 1.0, 1.0, 1.0)
    assert "transmitting (1, 1, 1) (diffuseColor unset: clear)" in record.summary


def test_glass_with_a_diffuse_color_transmits_that_colour(tmp_path):
    def build(stage, prim):
        bind(prim, preview_material(stage, "/World/Glass", opacity=0.0, diffuseColor=(0.18, 0.18, 0.18)))

    record = material_of(read_quad(tmp_path, build))
    np.testing.assert_allclose(record.fields["base_color"], (0.18, 0.18, 0.18, 1.0), rtol=1e-6)
    assert "transmitting (0.18, 0.18, 0.18)," in record.summary


def test_a_pane_of_preview_glass_without_a_diffuse_color_renders_what_is_behind_it_untinted(tmp_path, device):
    """usdview shows such a pane clear; the 0.18 fallback taken as a tint made it near-black."""
    pictures = []
    for tint in ({}, {"diffuseColor": (1.0, 1.0, 1.0)}, {"diffuseColor": (0.18, 0.18, 0.18)}):
        stage = new_stage(tmp_path / "pane.usda")
        card = quad(stage, "/World/Card", size=4.0, z=-1.0).GetPrim()
        bind(card, preview_material(stage, "/World/Lamp", diffuseColor=(0.0, 0.0, 0.0),
                                    emissiveColor=(0.6, 0.6, 0.6)))
        pane = quad(stage, "/World/Pane", size=1.0, z=0.5).GetPrim()
        bind(pane, preview_material(stage, "/World/Glass", opacity=0.0, ior=1.5, **tint))
        stage.GetRootLayer().Save()
        with snell.usd.open(tmp_path / "pane.usda", device=device) as opened:
            pictures.append(opened.render(40, 30, method="trace")[..., :3])
    unset, white, grey = pictures
    np.testing.assert_array_equal(unset, white)
    through, beside = unset[15, 20], unset[15, 14]
    assert (through >= 0.9 * beside).all(), (through, beside)  # clear: less only its reflections, plus highlights
    assert (grey[15, 20] < 0.5 * through).all(), grey[15, 20]  # an authored grey tints it


def test_display_color_read_through_a_primvar_reader_is_each_meshs_colour(tmp_path):
    from pxr import Sdf, UsdGeom

    def build(stage, prim):
        material = preview_material(stage, "/World/ByColour", roughness=0.3)
        reader = UsdShade.Shader.Define(stage, "/World/ByColour/Colour")
        reader.CreateIdAttr("UsdPrimvarReader_float3")
        reader.CreateInput("varname", Sdf.ValueTypeNames.Token).Set("displayColor")
        connect(material, "diffuseColor", reader, "result")
        UsdGeom.Gprim(prim).CreateDisplayColorPrimvar().Set([(0.1, 0.7, 0.3)])
        other = quad(stage, "/World/Other", z=1.0).GetPrim()
        UsdGeom.Gprim(other).CreateDisplayColorPrimvar().Set([(0.9, 0.2, 0.1)])
        bind(prim, material)
        bind(other, material)

    contents = read_quad(tmp_path, build)
    colours = [material_of(contents).fields["base_color"],
               contents.materials.records[contents.sources[1].parts[0].material].fields["base_color"]]
    np.testing.assert_allclose(colours, [(0.1, 0.7, 0.3, 1.0), (0.9, 0.2, 0.1, 1.0)], rtol=1e-6)
    assert material_of(contents).fields["roughness"] == pytest.approx(0.3)


def test_display_opacity_read_through_a_primvar_reader_blends_by_vertex(tmp_path):
    from pxr import Sdf, UsdGeom

    def build(stage, prim):
        material = preview_material(stage, "/World/Fade", diffuseColor=(0.5, 0.5, 0.5))
        reader = UsdShade.Shader.Define(stage, "/World/Fade/Opacity")
        reader.CreateIdAttr("UsdPrimvarReader_float")
        reader.CreateInput("varname", Sdf.ValueTypeNames.Token).Set("displayOpacity")
        connect(material, "opacity", reader, "result")
        UsdGeom.Gprim(prim).CreateDisplayOpacityPrimvar(UsdGeom.Tokens.vertex).Set([0.0, 1.0, 1.0, 0.0])
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    record = material_of(contents)
    assert record.fields["alpha_mode"] == "blend" and record.fields["transmission"] == 0.0
    texels = contents.materials.textures[record.fields["base_color_texture"]].rgba
    uvs = contents.snell_meshes()[0].uvs
    alpha = bilinear(texels, uvs)[:, 3] / 255.0
    points = contents.sources[0].parts[0].vertex_point
    np.testing.assert_allclose(alpha, np.float64([0.0, 1.0, 1.0, 0.0])[points], atol=0.5 / 255)


def bilinear(texels: np.ndarray, uvs: np.ndarray) -> np.ndarray:
    """The texture's bilinear value at each uv (texel centres at (i + 0.5) / size), in bytes, sRGB decoded."""
    decoded = texels.astype(np.float64)
    decoded[..., :3] = srgb_to_linear(decoded[..., :3] / 255.0) * 255.0
    h, w = texels.shape[:2]
    p = np.asarray(uvs, np.float64) * (w, h) - 0.5
    base = np.floor(p).astype(int)
    f = p - base
    x0, y0 = np.clip(base[:, 0], 0, w - 1), np.clip(base[:, 1], 0, h - 1)
    x1, y1 = np.clip(base[:, 0] + 1, 0, w - 1), np.clip(base[:, 1] + 1, 0, h - 1)
    top = decoded[y0, x0] * (1 - f[:, :1]) + decoded[y0, x1] * f[:, :1]
    bottom = decoded[y1, x0] * (1 - f[:, :1]) + decoded[y1, x1] * f[:, :1]
    return top * (1 - f[:, 1:]) + bottom * f[:, 1:]


def srgb_to_linear(c: np.ndarray) -> np.ndarray:
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def test_a_meshs_vertex_display_color_is_interpolated_linearly_across_each_triangle(tmp_path):
    from pxr import UsdGeom

    corners = np.float64([(1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 1.0, 1.0)])

    def build(stage, prim):
        UsdGeom.Gprim(prim).CreateDisplayColorPrimvar(UsdGeom.Tokens.vertex).Set([tuple(c) for c in corners])

    contents = read_quad(tmp_path, build)
    record = material_of(contents)
    meshed = contents.snell_meshes()[0]
    texels = contents.materials.textures[record.fields["base_color_texture"]].rgba
    points = contents.sources[0].parts[0].vertex_point
    assert len(meshed.positions) == 6  # two triangles, each with its own three vertices
    uvs = np.asarray(meshed.uvs, np.float64)
    triangles = np.asarray(meshed.indices)
    weights = np.random.default_rng(7).dirichlet((1, 1, 1), 20)
    for triangle in triangles:
        inside = weights @ uvs[triangle]
        expected = weights @ corners[points[triangle]]
        # Exact but for 8 bits and the clipping past a long edge (_colours.py: 0.02 at most).
        np.testing.assert_allclose(bilinear(texels, inside)[:, :3] / 255.0, expected, atol=0.02)


def test_a_meshs_uniform_display_color_colours_each_face_in_the_picture(tmp_path, device):
    from pxr import UsdGeom

    stage = new_stage(tmp_path / "faces.usda")
    panel = mesh(stage, "/World/Panel", [(-2, -1, 0), (0, -1, 0), (2, -1, 0), (2, 1, 0), (0, 1, 0), (-2, 1, 0)],
                 [4, 4], [0, 1, 4, 5, 1, 2, 3, 4], normals=[(0, 0, 1)] * 6)
    UsdGeom.Gprim(panel).CreateDisplayColorPrimvar(UsdGeom.Tokens.uniform).Set([(0.8, 0.1, 0.1), (0.1, 0.1, 0.8)])
    stage.GetRootLayer().Save()
    with snell.usd.open(tmp_path / "faces.usda", device=device) as opened:
        rgba = opened.render(48, 24, method="trace")
    left, right = rgba[12, 16, :3], rgba[12, 32, :3]
    # Lit alike, each face shows its own colour: highlights add the same to every channel.
    assert left[0] > 2 * left[2] and right[2] > 2 * right[0], (left, right)
    np.testing.assert_allclose([left[1], right[1]], [left[2], right[0]], rtol=0.02)
    np.testing.assert_allclose(left[0] - left[2], right[2] - right[0], rtol=0.02)


def test_an_emissive_color_is_read(tmp_path):
    def build(stage, prim):
        bind(prim, preview_material(stage, "/World/Lamp", emissiveColor=(2.0, 1.0, 0.5)))

    np.testing.assert_allclose(material_of(read_quad(tmp_path, build)).fields["emissive"], (2.0, 1.0, 0.5))


def test_an_emissive_texture_without_a_bias_folds_its_scale_into_the_emissive_factor(tmp_path):
    rgb = np.random.default_rng(6).integers(0, 256, (4, 4, 3), dtype=np.uint8)
    write_rgba_png(tmp_path / "glow.png", rgb)

    def build(stage, prim):
        material = preview_material(stage, "/World/Lamp")
        texture(stage, material, "./glow.png", input_name="emissiveColor", scale=(4.0, 2.0, 0.5, 1.0))
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    record = material_of(contents)
    assert record.fields["emissive"] == (4.0, 2.0, 0.5)  # brighter than 1 stays exact: the bytes are the file's
    np.testing.assert_array_equal(contents.materials.textures[record.slots["emissive"].index].rgba[..., :3], rgb)
    assert not contents.problems.items


def test_an_emissive_texture_with_a_bias_is_stored_over_its_largest_value(tmp_path):
    grey = np.array([[[0, 64, 128], [191, 255, 10]]], np.uint8)
    write_rgba_png(tmp_path / "glow.png", grey)

    def build(stage, prim):
        material = preview_material(stage, "/World/Lamp")
        texture(stage, material, "./glow.png", input_name="emissiveColor", sourceColorSpace="raw",
                scale=(3.0, 1.0, 1.0, 1.0), bias=(0.5, 0.0, 0.1, 0.0))
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    record = material_of(contents)
    expected = grey / 255.0 * np.array([3.0, 1.0, 1.0]) + np.array([0.5, 0.0, 0.1])
    np.testing.assert_allclose(record.fields["emissive"], expected.reshape(-1, 3).max(axis=0).clip(1.0), rtol=1e-6)
    texels = contents.materials.textures[record.slots["emissive"].index].rgba[..., :3] / 255.0
    decoded = np.where(texels <= 0.04045, texels / 12.92, ((texels + 0.055) / 1.055) ** 2.4)
    np.testing.assert_allclose(decoded * record.fields["emissive"], expected, rtol=0.01, atol=0.002)


def test_a_normal_map_is_stored_as_data_snell_decodes_to_the_specs_normal(tmp_path):
    rgb = np.random.default_rng(7).integers(0, 256, (4, 4, 3), dtype=np.uint8)
    write_rgba_png(tmp_path / "n.png", rgb)

    def build(scale, bias):
        def inner(stage, prim):
            material = preview_material(stage, "/World/M")
            texture(stage, material, "./n.png", input_name="normal", scale=scale, bias=bias)  # sourceColorSpace auto
            bind(prim, material)
        return inner

    # The specification's 8-bit convention: v = 2 byte/255 - 1, so the bytes are kept (not read as sRGB).
    contents = read_quad(tmp_path, build((2.0, 2.0, 2.0, 1.0), (-1.0, -1.0, -1.0, 0.0)))
    record = material_of(contents)
    assert record.fields["normal_scale"] == 1.0 and not contents.problems.items
    np.testing.assert_array_equal(contents.materials.textures[record.slots["normal"].index].rgba[..., :3], rgb)
    # Any other scale and bias: the bytes hold (v + 1) / 2.
    contents = read_quad(tmp_path, build((1.0, 1.5, 1.0, 1.0), (-0.5, -0.5, 0.0, 0.0)))
    v = rgb / 255.0 * np.array([1.0, 1.5, 1.0]) - np.array([0.5, 0.5, 0.0])
    texels = contents.materials.textures[material_of(contents).slots["normal"].index].rgba[..., :3]
    np.testing.assert_allclose(2.0 * texels / 255.0 - 1.0, v.clip(-1, 1), atol=1.0 / 255 + 1e-9)


def test_a_normal_map_scaled_beyond_the_usual_one_is_the_usual_one_with_a_normal_scale(tmp_path):
    rgb = np.random.default_rng(8).integers(0, 256, (4, 4, 3), dtype=np.uint8)
    write_rgba_png(tmp_path / "n.png", rgb)

    def build(stage, prim):
        material = preview_material(stage, "/World/M")
        texture(stage, material, "./n.png", input_name="normal", sourceColorSpace="raw", scale=(5.0, 5.0, 2.0, 1.0),
                bias=(-2.5, -2.5, -1.0, 0.0))
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    record = material_of(contents)
    assert record.fields["normal_scale"] == 2.5
    np.testing.assert_array_equal(contents.materials.textures[record.slots["normal"].index].rgba[..., :3], rgb)


def test_a_normal_from_something_other_than_a_texture_is_a_warning_naming_the_input(tmp_path):
    def build(stage, prim):
        from pxr import Sdf

        material = preview_material(stage, "/World/M")
        reader = UsdShade.Shader.Define(stage, "/World/M/Normals")
        reader.CreateIdAttr("UsdPrimvarReader_normal")
        reader.CreateInput("varname", Sdf.ValueTypeNames.Token).Set("n")
        connect(material, "normal", reader, "result")
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    assert "normal" not in material_of(contents).slots
    assert ("/World/M/Surface: inputs:normal is connected to /World/M/Normals (UsdPrimvarReader_normal, output "
            "result), which snell cannot evaluate") in messages(contents)


def test_another_surface_shader_is_a_warning(tmp_path):
    def build(stage, prim):
        material = preview_material(stage, "/World/X")
        UsdShade.Shader(stage.GetPrimAtPath("/World/X/Surface")).SetShaderId("ND_gltf_pbr_surfaceshader")
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    assert "/World/X/Surface: the surface has id 'ND_gltf_pbr_surfaceshader'" in messages(contents)
    np.testing.assert_allclose(material_of(contents).fields["base_color"], (0.18, 0.18, 0.18, 1.0), rtol=1e-6)


def test_a_metallic_surface_is_a_warning(tmp_path):
    contents = read_quad(tmp_path, lambda stage, prim: bind(prim, preview_material(stage, "/World/Gold",
                                                                                   metallic=1.0)))
    assert "/World/Gold/Surface: inputs:metallic is 1" in messages(contents)


def test_an_srgb_texture_passes_through_byte_for_byte(tmp_path):
    rgba = np.random.default_rng(1).integers(0, 256, (4, 6, 4), dtype=np.uint8)
    write_rgba_png(tmp_path / "t.png", rgba)

    def build(stage, prim):
        material = preview_material(stage, "/World/T")
        texture(stage, material, "./t.png", sourceColorSpace="sRGB")
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    record = material_of(contents)
    assert record.slots["base_color"].index == 0 and record.fields["base_color"] == (1, 1, 1, 1)
    np.testing.assert_array_equal(contents.materials.textures[0].rgba[..., :3], rgba[..., :3])
    assert (contents.materials.textures[0].rgba[..., 3] == 255).all()


def test_scale_and_bias_apply_in_linear_light_after_the_colour_space(tmp_path):
    grey = np.array([[[0, 64, 128], [191, 255, 10]]], np.uint8)
    write_rgba_png(tmp_path / "g.png", grey)

    def build(stage, prim):
        material = preview_material(stage, "/World/T")
        texture(stage, material, "./g.png", sourceColorSpace="raw", scale=(0.5, 0.5, 0.5, 1.0),
                bias=(0.1, 0.0, 0.0, 0.0))
        bind(prim, material)

    texels = read_quad(tmp_path, build).materials.textures[0].rgba[..., :3].astype(float) / 255
    linear = grey / 255.0 * 0.5 + np.array([0.1, 0.0, 0.0])  # raw: the file's values are linear already
    expected = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * np.clip(linear, 0, 1) ** (1 / 2.4) - 0.055)
    np.testing.assert_allclose(texels, expected, atol=0.5 / 255 + 1e-9)


def test_texture_coordinates_flip_v_as_st_starts_at_the_lower_left(tmp_path):
    write_rgba_png(tmp_path / "t.png", np.zeros((2, 2, 3), np.uint8))

    def build(stage, prim):
        material = preview_material(stage, "/World/T")
        texture(stage, material, "./t.png")
        bind(prim, material)

    part = read_quad(tmp_path, build).sources[0].parts[0]
    st = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], np.float32)  # the quad's st at points 0..3
    np.testing.assert_allclose(part.uvs, np.stack([st[:, 0], 1 - st[:, 1]], axis=1)[part.vertex_point])


def test_a_transform2d_is_the_slots_texture_transform_in_snells_uv_space(tmp_path):
    write_rgba_png(tmp_path / "t.png", np.zeros((2, 2, 3), np.uint8))
    rotation, scale, translation = 35.0, (1.5, 0.5), (0.25, -0.4)

    def build(stage, prim):
        material = preview_material(stage, "/World/T")
        transform2d(texture(stage, material, "./t.png"), rotation, scale, translation)
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    part = contents.sources[0].parts[0]
    quad_st = np.array([(0, 0), (1, 0), (1, 1), (0, 1)], np.float32)[part.vertex_point]
    np.testing.assert_allclose(part.uvs, np.stack([quad_st[:, 0], 1 - quad_st[:, 1]], 1))  # the mesh keeps its st
    # Where snell reads any st through the material's transform is where USD reads it, in snell's (s, 1 - t).
    st = np.random.default_rng(9).uniform(-2, 2, (16, 2))
    a = np.radians(rotation)
    usd = (st * scale) @ np.array([[np.cos(a), -np.sin(a)], [np.sin(a), np.cos(a)]]).T + translation
    t = material_of(contents).snell_material().base_color_transform
    c, s = np.cos(t.rotation), np.sin(t.rotation)
    khr = np.array([[c, s], [-s, c]]) @ np.diag(t.scale)  # KHR_texture_transform: rotate(rotation) scale(scale)
    uv = np.stack([st[:, 0], 1 - st[:, 1]], 1) @ khr.T + np.asarray(t.offset)
    np.testing.assert_allclose(uv, np.stack([usd[:, 0], 1 - usd[:, 1]], 1), atol=1e-6)


def test_the_primvar_reader_picks_the_texture_coordinates(tmp_path):
    write_rgba_png(tmp_path / "t.png", np.zeros((2, 2, 3), np.uint8))

    def build(stage, prim):
        from pxr import Sdf, UsdGeom

        other = UsdGeom.PrimvarsAPI(prim).CreatePrimvar("uv2", Sdf.ValueTypeNames.TexCoord2fArray, "vertex")
        other.Set([(0.5, 0.5)] * 4)
        material = preview_material(stage, "/World/T")
        texture(stage, material, "./t.png", varname="uv2")
        bind(prim, material)

    np.testing.assert_allclose(read_quad(tmp_path, build).sources[0].parts[0].uvs, 0.5)


def test_textures_of_one_material_reading_other_primvars_read_the_first_ones_with_a_warning(tmp_path):
    write_rgba_png(tmp_path / "t.png", np.zeros((2, 2, 3), np.uint8))

    def build(stage, prim):
        from pxr import Sdf, UsdGeom

        UsdGeom.PrimvarsAPI(prim).CreatePrimvar("uv2", Sdf.ValueTypeNames.TexCoord2fArray, "vertex").Set(
            [(0.5, 0.5)] * 4)
        material = preview_material(stage, "/World/T")
        texture(stage, material, "./t.png")
        glow = texture(stage, material, "./t.png", input_name="emissiveColor")
        other = UsdShade.Shader.Define(stage, "/World/T/Reader2")
        other.CreateIdAttr("UsdPrimvarReader_float2")
        other.CreateInput("varname", Sdf.ValueTypeNames.Token).Set("uv2")
        glow.GetInput("st").ConnectToSource(other.ConnectableAPI(), "result")
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    assert contents.sources[0].parts[0].uvs.max() == 1.0  # primvars:st, not uv2's constant 0.5
    assert ("/World/T/Texture_emissiveColor: reads primvars:uv2, but the material's other textures read "
            "primvars:st; snell's meshes carry one UV set: primvars:st is used") in messages(contents)


def textured(path: str):
    """A build of read_quad's that binds a preview material whose diffuse texture is `path`."""
    def build(stage, prim):
        material = preview_material(stage, "/World/T")
        texture(stage, material, path)
        bind(prim, material)

    return build


def test_a_missing_texture_is_a_warning_naming_the_file_and_its_fallback_is_drawn(tmp_path):
    def build(stage, prim):
        from pxr import Gf, Sdf

        material = preview_material(stage, "/World/T")
        image = texture(stage, material, "./nowhere.png")
        image.CreateInput("fallback", Sdf.ValueTypeNames.Float4).Set(Gf.Vec4f(0.25, 0.5, 0.75, 1.0))
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    assert not contents.problems.errors
    assert ("/World/T/Texture_diffuseColor: texture file ./nowhere.png not found (it resolves to nothing from "
            f"{tmp_path / 'quad.usda'}): the texture's fallback (0.25, 0.5, 0.75, 1) is used") in messages(contents)
    np.testing.assert_allclose(material_of(contents).fields["base_color"], (0.25, 0.5, 0.75, 1.0), rtol=1e-6)


def test_a_missing_texture_is_an_error_when_strict(tmp_path):
    with pytest.raises(snell.usd.StageError, match="nowhere.png not found"):
        read_quad(tmp_path, textured("./nowhere.png"), strict=True)
    contents = read_quad(tmp_path, textured("./nowhere.png"), missing_textures_fail=True)
    assert [w.prim for w in contents.problems.errors] == ["/World/T/Texture_diffuseColor"]


def test_a_udim_texture_is_a_warning(tmp_path):
    contents = read_quad(tmp_path, textured("./skin.<UDIM>.png"))
    assert "is a UDIM set" in messages(contents) and not contents.problems.errors


def test_clamp_and_mirror_wraps_are_snells_samplers(tmp_path):
    write_rgba_png(tmp_path / "t.png", np.zeros((2, 2, 3), np.uint8))

    def build(stage, prim):
        from pxr import UsdGeom

        UsdGeom.PrimvarsAPI(prim).GetPrimvar("st").Set([(0, 0), (3, 0), (3, 3), (0, 3)])
        material = preview_material(stage, "/World/T")
        texture(stage, material, "./t.png", wrapS="clamp", wrapT="mirror")
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    assert [t.wraps for t in contents.materials.textures] == [("clamp", "mirror")] and not contents.problems.items


def test_a_black_wrap_is_a_warning_only_where_the_textures_st_leaves_the_unit_square(tmp_path):
    write_rgba_png(tmp_path / "t.png", np.zeros((2, 2, 3), np.uint8))

    def build(scale):
        def inner(stage, prim):
            material = preview_material(stage, "/World/T")
            transform2d(texture(stage, material, "./t.png", wrapS="repeat", wrapT="black"), scale=(1.0, scale))
            bind(prim, material)
        return inner

    assert "wrap" not in messages(read_quad(tmp_path, build(1.0)))
    assert ("/World/T/Texture_diffuseColor: wrap 'black' where /World/Quad's st (through its UsdTransform2d) leaves "
            "[0, 1]: snell has no black border: the texture repeats there") in messages(read_quad(tmp_path, build(2)))


def test_a_geom_subset_gets_its_own_snell_mesh_and_material(tmp_path):
    from pxr import UsdGeom

    stage = new_stage(tmp_path / "s.usda")
    strip = mesh(stage, "/World/Strip", [(x, y, 0) for y in (0, 1) for x in range(4)], [4, 4, 4],
                 [0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6])
    glass = preview_material(stage, "/World/Glass", opacity=0.0)
    bind(strip.GetPrim(), preview_material(stage, "/World/Wall"))
    subset = UsdGeom.Subset.CreateGeomSubset(strip, "tip", "face", [1], "materialBind")
    bind(subset.GetPrim(), glass)
    stage.GetRootLayer().Save()
    contents = snell.usd.read(tmp_path / "s.usda")
    meshes = contents.snell_meshes()
    assert [m.name for m in meshes] == ["/World/Strip", "/World/Strip (tip)"]
    assert [contents.materials.records[m.material].path for m in meshes] == ["/World/Wall", "/World/Glass"]
    assert [len(m.indices) for m in meshes] == [4, 2]


def test_a_texture_inside_a_usdz_package_is_read(tmp_path):
    from pxr import UsdUtils

    rgba = np.random.default_rng(2).integers(0, 256, (3, 5, 3), dtype=np.uint8)
    write_rgba_png(tmp_path / "inside.png", rgba)
    read_quad(tmp_path, lambda stage, prim: bind(prim, _textured(stage, "./inside.png")))
    assert UsdUtils.CreateNewUsdzPackage(str(tmp_path / "quad.usda"), str(tmp_path / "quad.usdz"))
    (tmp_path / "inside.png").unlink()  # only the package's copy is left
    contents = snell.usd.read(tmp_path / "quad.usdz")
    contents.snell_meshes()
    assert not contents.problems.items
    np.testing.assert_array_equal(contents.materials.textures[0].rgba[..., :3], rgba)


def _textured(stage, file: str):
    material = preview_material(stage, "/World/T")
    texture(stage, material, file, sourceColorSpace="sRGB")
    return material
