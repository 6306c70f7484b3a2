"""MaterialX materials: standard_surface and OpenPBR glass, in a .mtlx document a stage references or inline in
the mtlx render context, draw as the same glass written as UsdPreviewSurface.

Each stage is a glass sphere before a wall split red and green (so what the glass bends shows), lit by the
headlight and framed by snell's view of the bounds. The twin binds the sphere to UsdPreviewSurface glass of
the same IOR, roughness and tint (opacity 0 is transmission 1); both render in one device at 64 x 48.
"""

from __future__ import annotations

from pathlib import Path

import MaterialX as mx
import numpy as np
from pxr import Gf, Sdf, UsdGeom, UsdShade

import snell.usd
from conftest import snell_usd, snell_usd_ok, srgb8
from stages import bind, mesh, new_stage, preview_material, quad, texture, write_rgba_png

WIDTH, HEIGHT = 64, 48
TINT = (0.9, 0.75, 0.6)


def glass_scene(path: Path) -> tuple[object, UsdGeom.Sphere]:
    """The wall and the sphere, the sphere unbound."""
    stage = new_stage(path)
    for name, colour, x0 in (("Red", (0.8, 0.1, 0.1), -2.0), ("Green", (0.1, 0.7, 0.1), 0.0)):
        wall = mesh(stage, f"/World/{name}", [(x0, -2, -1.5), (x0 + 2, -2, -1.5), (x0 + 2, 2, -1.5), (x0, 2, -1.5)],
                    [4], [0, 1, 2, 3], normals=[(0, 0, 1)] * 4)
        bind(wall.GetPrim(), preview_material(stage, f"/World/{name}Look", diffuseColor=colour))
    sphere = UsdGeom.Sphere.Define(stage, "/World/Ball")
    sphere.CreateRadiusAttr(0.8)
    return stage, sphere


def preview_glass(folder: Path) -> Path:
    stage, sphere = glass_scene(folder / "preview.usda")
    bind(sphere.GetPrim(), preview_material(stage, "/World/Glass", opacity=0.0, ior=1.45, roughness=0.25,
                                            diffuseColor=TINT))
    stage.GetRootLayer().Save()
    return folder / "preview.usda"


def mtlx_document(path: Path, category: str = "standard_surface", **inputs) -> Path:
    """A .mtlx document with one material, 'glass', whose surface is `category` with these inputs."""
    document = mx.createDocument()
    shader = document.addNode(category, "glass_shader", "surfaceshader")
    for name, value in inputs.items():
        if isinstance(value, tuple):
            shader.setInputValue(name, mx.Color3(*value), "color3")
        elif isinstance(value, bool):
            shader.setInputValue(name, value, "boolean")
        else:
            shader.setInputValue(name, float(value), "float")
    document.addMaterialNode("glass", shader)
    mx.writeToXmlFile(document, str(path))
    return path


def referencing_stage(folder: Path, document: str, target: str = "/World/Looks/Materials/glass") -> Path:
    """The scene with the sphere bound into a .mtlx document referenced at /World/Looks, as USD's own MaterialX
    plugin lays documents out (/MaterialX/Materials/NAME)."""
    stage, sphere = glass_scene(folder / "mtlx.usda")
    stage.DefinePrim("/World/Looks").GetReferences().AddReference(document, "/MaterialX")
    UsdShade.MaterialBindingAPI.Apply(sphere.GetPrim()).GetDirectBindingRel().SetTargets([Sdf.Path(target)])
    stage.GetRootLayer().Save()
    return folder / "mtlx.usda"


def inline_stage(folder: Path, shader_id: str, preview_beside: bool = False, **inputs) -> Path:
    """The scene with the sphere bound to a Material whose mtlx:surface is a shader of `shader_id` (and, beside
    it, a universal surface: opaque blue UsdPreviewSurface)."""
    stage, sphere = glass_scene(folder / "inline.usda")
    material = UsdShade.Material.Define(stage, "/World/Glass")
    shader = UsdShade.Shader.Define(stage, "/World/Glass/Surface")
    shader.CreateIdAttr(shader_id)
    for name, value in inputs.items():
        kind = Sdf.ValueTypeNames.Color3f if isinstance(value, tuple) else Sdf.ValueTypeNames.Float
        shader.CreateInput(name, kind).Set(Gf.Vec3f(*value) if isinstance(value, tuple) else float(value))
    material.CreateSurfaceOutput("mtlx").ConnectToSource(shader.ConnectableAPI(), "out")
    if preview_beside:
        blue = UsdShade.Shader.Define(stage, "/World/Glass/Preview")
        blue.CreateIdAttr("UsdPreviewSurface")
        blue.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).Set(Gf.Vec3f(0.1, 0.1, 0.9))
        material.CreateSurfaceOutput().ConnectToSource(blue.ConnectableAPI(), "surface")
    bind(sphere.GetPrim(), material)
    stage.GetRootLayer().Save()
    return folder / "inline.usda"


def picture(path: Path, device) -> tuple[np.ndarray, list[str]]:
    with snell.usd.open(path, device=device) as stage:
        return srgb8(stage.render(WIDTH, HEIGHT)), [str(w) for w in stage.warnings]


def assert_same_glass(path: Path, twin: Path, device) -> list[str]:
    """The two stages' pictures agree within 1/255 on 99.9% of the pixels, and the glass shows (the scene without
    it differs); returns the first's warnings."""
    drawn, warnings = picture(path, device)
    expected, _ = picture(twin, device)
    close = np.all(np.abs(drawn - expected) <= 1, axis=-1)
    assert close.mean() >= 0.999, f"{(~close).sum()} pixels differ by more than 1/255"
    bare, _ = glass_scene(path.parent / "bare.usda")
    bare.GetRootLayer().Save()
    plain, _ = picture(path.parent / "bare.usda", device)
    assert np.abs(drawn - plain).max() > 20, "the glass changes the picture"
    return warnings


def test_a_standard_surface_glass_in_a_referenced_mtlx_refracts_as_the_same_usd_preview_surface_glass(
        tmp_path, device):
    mtlx_document(tmp_path / "looks.mtlx", transmission=1.0, specular_IOR=1.45, specular_roughness=0.25,
                  transmission_color=TINT)
    warnings = assert_same_glass(referencing_stage(tmp_path, "./looks.mtlx"), preview_glass(tmp_path), device)
    assert not [w for w in warnings if "looks.mtlx" in w or "does not exist" in w], warnings


def test_an_open_pbr_glass_in_a_referenced_mtlx_refracts_as_the_same_usd_preview_surface_glass(tmp_path, device):
    mtlx_document(tmp_path / "looks.mtlx", "open_pbr_surface", transmission_weight=1.0, specular_ior=1.45,
                  specular_roughness=0.25, transmission_color=TINT)
    assert_same_glass(referencing_stage(tmp_path, "./looks.mtlx"), preview_glass(tmp_path), device)


def test_materialxs_own_usd_preview_surface_node_in_a_referenced_mtlx_refracts_as_usds(tmp_path, device):
    mtlx_document(tmp_path / "looks.mtlx", "UsdPreviewSurface", opacity=0.0, ior=1.45, roughness=0.25,
                  diffuseColor=TINT)
    assert_same_glass(referencing_stage(tmp_path, "./looks.mtlx"), preview_glass(tmp_path), device)


def test_an_inline_standard_surface_in_the_mtlx_render_context_refracts_as_the_same_preview_glass(
        tmp_path, device):
    stage = inline_stage(tmp_path, "ND_standard_surface_surfaceshader", transmission=1.0, specular_IOR=1.45,
                         specular_roughness=0.25, transmission_color=TINT)
    assert_same_glass(stage, preview_glass(tmp_path), device)


def test_a_material_with_both_surfaces_draws_its_mtlx_one_as_snells_render_context_asks(tmp_path, device):
    stage = inline_stage(tmp_path, "ND_open_pbr_surface_surfaceshader", preview_beside=True,
                         transmission_weight=1.0, specular_ior=1.45, specular_roughness=0.25, transmission_color=TINT)
    assert_same_glass(stage, preview_glass(tmp_path), device)


def test_info_names_each_materials_source(tmp_path):
    mtlx_document(tmp_path / "looks.mtlx", "open_pbr_surface", transmission_weight=1.0)
    done = snell_usd_ok("info", referencing_stage(tmp_path, "./looks.mtlx"), "--json")
    summaries = done.stdout
    assert "OpenPBR, glass (transmission 1, ior 1.5)" in summaries and "from ./looks.mtlx" in summaries
    assert "UsdPreviewSurface, opaque" in summaries
    inline = snell_usd("info", inline_stage(tmp_path, "ND_standard_surface_surfaceshader", base_color=(0.2, 0.3, 0.4)))
    assert "MaterialX standard_surface, opaque, colour (0.2, 0.3, 0.4)" in inline.stdout, inline.stdout


def test_an_input_snell_does_not_draw_is_one_warning_naming_the_material_and_the_input(tmp_path, device):
    mtlx_document(tmp_path / "looks.mtlx", transmission=1.0, coat=0.5, metalness=0.0)
    _, warnings = picture(referencing_stage(tmp_path, "./looks.mtlx"), device)
    said = [w for w in warnings if "glass_shader" in w]
    assert len(said) == 1 and "inputs:coat is 0.5, which snell does not draw" in said[0], warnings


def test_a_missing_mtlx_document_is_a_warning_and_strict_refuses_it(tmp_path, device):
    stage = referencing_stage(tmp_path, "./gone.mtlx")
    _, warnings = picture(stage, device)
    assert any("MaterialX document ./gone.mtlx not found" in w and "fallbacks" in w for w in warnings), warnings
    done = snell_usd("render", stage, "-o", tmp_path / "gone.png", "--size", "16x12", "--strict")
    assert done.returncode == 1 and "./gone.mtlx" in done.stderr, done.stderr
    assert not (tmp_path / "gone.png").exists()


def test_a_base_colour_image_draws_as_the_same_usd_preview_surface_texture(tmp_path, device):
    y, x = np.mgrid[0:8, 0:8]
    write_rgba_png(tmp_path / "checker.png", np.where(((x + y) % 2)[..., None].astype(bool), np.uint8([230, 190, 60]),
                                                      np.uint8([40, 70, 160])).astype(np.uint8))
    document = mx.createDocument()
    image = document.addNode("image", "checker", "color3")
    image.setInputValue("file", "checker.png", "filename")
    shader = document.addNode("standard_surface", "card_shader", "surfaceshader")
    shader.addInput("base_color", "color3").setNodeName("checker")
    shader.setInputValue("specular_roughness", 0.5, "float")
    document.addMaterialNode("card", shader)
    mx.writeToXmlFile(document, str(tmp_path / "card.mtlx"))

    def card(name: str) -> tuple:
        stage = new_stage(tmp_path / f"{name}.usda")
        return stage, quad(stage, "/World/Card")

    stage, mtlx_card = card("mtlx")
    stage.DefinePrim("/World/Looks").GetReferences().AddReference("./card.mtlx", "/MaterialX")
    UsdShade.MaterialBindingAPI.Apply(mtlx_card.GetPrim()).GetDirectBindingRel().SetTargets(
        [Sdf.Path("/World/Looks/Materials/card")])
    stage.GetRootLayer().Save()
    stage, preview_card = card("preview")
    material = preview_material(stage, "/World/Card/Look", roughness=0.5)
    texture(stage, material, "./checker.png")
    bind(preview_card.GetPrim(), material)
    stage.GetRootLayer().Save()

    drawn, warnings = picture(tmp_path / "mtlx.usda", device)
    expected, _ = picture(tmp_path / "preview.usda", device)
    assert not [w for w in warnings if "card" in w], warnings
    assert np.all(np.abs(drawn - expected) <= 1), f"{np.sum(np.any(np.abs(drawn - expected) > 1, -1))} pixels differ"
    assert len(np.unique(drawn.reshape(-1, 3), axis=0)) > 8, "the checker shows"
