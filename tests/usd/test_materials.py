"""UsdPreviewSurface materials, their bindings and textures, as snell materials."""

from __future__ import annotations

import numpy as np
import pytest
from pxr import UsdShade

import snell.usd
from stages import bind, mesh, new_stage, preview_material, quad, texture, write_rgba_png


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


def test_a_cut_out_opacity_is_opaque_with_a_warning(tmp_path):
    def build(stage, prim):
        bind(prim, preview_material(stage, "/World/Leaf", opacity=0.2, opacityThreshold=0.5))

    contents = read_quad(tmp_path, build)
    assert material_of(contents).fields["transmission"] == 0.0
    assert "/World/Leaf/Surface: opacity 0.2 under opacityThreshold 0.5" in messages(contents)


def test_an_emissive_color_is_read(tmp_path):
    def build(stage, prim):
        bind(prim, preview_material(stage, "/World/Lamp", emissiveColor=(2.0, 1.0, 0.5)))

    np.testing.assert_allclose(material_of(read_quad(tmp_path, build)).fields["emissive"], (2.0, 1.0, 0.5))


def test_a_normal_map_and_an_emissive_texture_are_warnings_naming_the_input(tmp_path):
    write_rgba_png(tmp_path / "n.png", np.full((2, 2, 3), 128, np.uint8))

    def build(stage, prim):
        material = preview_material(stage, "/World/M")
        texture(stage, material, "./n.png", input_name="normal")
        texture(stage, material, "./n.png", input_name="emissiveColor")
        bind(prim, material)

    text = messages(read_quad(tmp_path, build))
    assert "/World/M/Surface: inputs:normal is connected to /World/M/Texture_normal" in text
    assert "/World/M/Surface: inputs:emissiveColor is connected to /World/M/Texture_emissiveColor" in text


def test_another_surface_shader_is_a_warning(tmp_path):
    def build(stage, prim):
        material = preview_material(stage, "/World/X")
        UsdShade.Shader(stage.GetPrimAtPath("/World/X/Surface")).SetShaderId("ND_standard_surface_surfaceshader")
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    assert "/World/X/Surface: the surface has id 'ND_standard_surface_surfaceshader'" in messages(contents)
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
    assert record.texture_index == 0 and record.fields["base_color"] == (1, 1, 1, 1)
    np.testing.assert_array_equal(contents.materials.textures[0][..., :3], rgba[..., :3])
    assert (contents.materials.textures[0][..., 3] == 255).all()


def test_scale_and_bias_apply_in_linear_light_after_the_colour_space(tmp_path):
    grey = np.array([[[0, 64, 128], [191, 255, 10]]], np.uint8)
    write_rgba_png(tmp_path / "g.png", grey)

    def build(stage, prim):
        material = preview_material(stage, "/World/T")
        texture(stage, material, "./g.png", sourceColorSpace="raw", scale=(0.5, 0.5, 0.5, 1.0),
                bias=(0.1, 0.0, 0.0, 0.0))
        bind(prim, material)

    texels = read_quad(tmp_path, build).materials.textures[0][..., :3].astype(float) / 255
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


def test_a_missing_texture_is_an_error_naming_the_file(tmp_path):
    def build(stage, prim):
        material = preview_material(stage, "/World/T")
        texture(stage, material, "./nowhere.png")
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    errors = [str(w) for w in contents.problems.errors]
    assert errors == ["error: /World/T/Texture_diffuseColor: texture file ./nowhere.png not found "
                      f"(it resolves to nothing from {tmp_path / 'quad.usda'})"]
    with pytest.raises(snell.usd.StageError, match="nowhere.png not found"):
        read_quad(tmp_path, build, strict=True)


def test_a_udim_texture_is_a_warning(tmp_path):
    def build(stage, prim):
        material = preview_material(stage, "/World/T")
        texture(stage, material, "./skin.<UDIM>.png")
        bind(prim, material)

    contents = read_quad(tmp_path, build)
    assert "is a UDIM set" in messages(contents) and not contents.problems.errors


def test_a_wrap_snell_cannot_draw_is_a_warning_only_where_st_leaves_the_unit_square(tmp_path):
    write_rgba_png(tmp_path / "t.png", np.zeros((2, 2, 3), np.uint8))

    def build(scale):
        def inner(stage, prim):
            from pxr import UsdGeom

            UsdGeom.PrimvarsAPI(prim).GetPrimvar("st").Set([(0, 0), (scale, 0), (scale, scale), (0, scale)])
            material = preview_material(stage, "/World/T")
            texture(stage, material, "./t.png", wrapS="clamp", wrapT="clamp")
            bind(prim, material)
        return inner

    assert "wrap" not in messages(read_quad(tmp_path, build(1.0)))
    assert "wrap 'clamp' where /World/Quad's st leaves [0, 1]" in messages(read_quad(tmp_path, build(2.0)))


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
    np.testing.assert_array_equal(contents.materials.textures[0][..., :3], rgba)


def _textured(stage, file: str):
    material = preview_material(stage, "/World/T")
    texture(stage, material, file, sourceColorSpace="sRGB")
    return material
