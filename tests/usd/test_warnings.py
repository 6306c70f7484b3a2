"""What snell reads differently from what the stage says is a warning that names the prim."""

from __future__ import annotations

import pytest
from pxr import Sdf, UsdGeom, UsdShade, Vt

import snell.usd
from conftest import snell_usd
from stages import new_stage, quad


def warnings_of(stage, path) -> list[str]:
    stage.GetRootLayer().Save()
    return [str(w) for w in snell.usd.read(path).problems.items]


def test_a_binding_to_a_material_that_does_not_exist_is_a_warning_naming_the_prim(tmp_path):
    stage = new_stage(tmp_path / "s.usda")
    card = quad(stage, "/World/Card").GetPrim()
    UsdShade.MaterialBindingAPI.Apply(card).GetPrim().CreateRelationship("material:binding").SetTargets(
        [Sdf.Path("/World/Looks/Gone")])
    assert ("/World/Card: material:binding targets /World/Looks/Gone, which does not exist: USD binds nothing "
            "there") in warnings_of(stage, tmp_path / "s.usda")


def test_an_up_axis_neither_y_nor_z_is_a_warning(tmp_path):
    stage = new_stage(tmp_path / "s.usda")
    quad(stage, "/World/Card")
    stage.SetMetadata("upAxis", "X")
    assert any("upAxis 'X' of" in w and "is neither Y nor Z (UsdGeom allows only those): read as Y" in w
               for w in warnings_of(stage, tmp_path / "s.usda"))


def test_a_model_draw_mode_snell_does_not_honour_is_a_warning_naming_the_prim(tmp_path):
    stage = new_stage(tmp_path / "s.usda")
    quad(stage, "/World/Tree/Card")
    tree = stage.GetPrimAtPath("/World/Tree")
    UsdGeom.ModelAPI.Apply(tree).CreateModelDrawModeAttr("cards")
    assert ("/World/Tree: model:drawMode is 'cards', which snell does not honour: the model's own geometry is "
            "drawn") in warnings_of(stage, tmp_path / "s.usda")


CARD = """#usda 1.0
(
    metersPerUnit = 1
    upAxis = "Y"
)

def Mesh "Card"
{
    int[] faceVertexCounts = [4]
    int[] faceVertexIndices = [0, 1, 2, 3]
    %s
}
"""


@pytest.mark.parametrize("declaration, says", [
    ("point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]\n    normal3f normals = (0, 0, 1)",
     "normals is normal3f, not normal3f[]"),
    ("int[] points = [0, 1, 2, 3]", "points is int[], not point3f[]"),
    ("double[] points = [0, 1]", "points is double[], not point3f[]"),
])
def test_an_attribute_of_the_wrong_type_is_one_line_naming_the_file_prim_and_attribute(tmp_path, declaration, says):
    path = tmp_path / "card.usda"
    path.write_text(CARD % declaration)
    done = snell_usd("render", path, "-o", tmp_path / "f.png", "--size", "16x16")
    assert done.returncode == 1 and "Traceback" not in done.stderr, done.stderr
    assert done.stderr.strip().splitlines() == [f"snell-usd: error: {path}: /Card: {says} as UsdGeomMesh has it: "
                                                "the mesh is not drawn"]


def test_when_usd_cannot_open_a_file_its_own_reason_is_kept(tmp_path):
    (tmp_path / "bad.usda").write_text('#usda 1.0\n(\n    framesPerSecond = "fast"\n)\n')
    done = snell_usd("info", tmp_path / "bad.usda")
    assert done.returncode == 1 and "Traceback" not in done.stderr
    assert done.stderr.startswith(f"snell-usd: error: {tmp_path / 'bad.usda'}: not a stage USD opens "
                                  f"({tmp_path / 'bad.usda'}:3:")
    assert "Failed to parse value" in done.stderr and '"fast"' in done.stderr, done.stderr


def _wrong_type(card, name: str, kind, value) -> None:
    """Authors `name` as `kind` in the card's layer, past the schema's type (as a broken exporter would)."""
    spec = card.GetStage().GetRootLayer().GetPrimAtPath(card.GetPath())
    if name in spec.properties:
        spec.RemoveProperty(spec.properties[name])
    Sdf.AttributeSpec(spec, name, kind).default = value


MUTATIONS = {
    "normals of the wrong count": lambda card: card.GetAttribute("normals").Set([(0, 0, 1)] * 3),
    "face indices past the points": lambda card: card.GetAttribute("faceVertexIndices").Set([0, 1, 2, 9]),
    "negative face counts": lambda card: card.GetAttribute("faceVertexCounts").Set([-4]),
    "counts that do not add up": lambda card: card.GetAttribute("faceVertexCounts").Set([3, 3]),
    "st indices out of range": lambda card: UsdGeom.PrimvarsAPI(card).GetPrimvar("st").SetIndices(
        Vt.IntArray([0, 1, 2, 7])),
    "st of the wrong type": lambda card: _wrong_type(card, "primvars:st", Sdf.ValueTypeNames.String, "x"),
    "displayColor of the wrong type": lambda card: _wrong_type(card, "primvars:displayColor",
                                                               Sdf.ValueTypeNames.IntArray, Vt.IntArray([1, 2])),
    "faceVertexCounts of the wrong type": lambda card: _wrong_type(card, "faceVertexCounts",
                                                                   Sdf.ValueTypeNames.Float, 4.0),
    "a binding to nothing": lambda card: UsdShade.MaterialBindingAPI.Apply(card).GetPrim().CreateRelationship(
        "material:binding").SetTargets([Sdf.Path("/Nowhere")]),
    "a reference to itself": lambda card: card.GetReferences().AddReference("./card.usda", "/World/Card"),
    "points with no faces": lambda card: card.GetAttribute("faceVertexCounts").Set([]),
}


@pytest.mark.parametrize("mutation", sorted(MUTATIONS))
def test_a_mutated_stage_reads_or_fails_with_one_line_never_a_traceback_or_a_hang(tmp_path, mutation):
    stage = new_stage(tmp_path / "card.usda")
    card = quad(stage, "/World/Card").GetPrim()
    MUTATIONS[mutation](card)
    stage.GetRootLayer().Save()
    done = snell_usd("info", tmp_path / "card.usda", timeout=60)
    assert done.returncode in (0, 1) and "Traceback" not in done.stderr + done.stdout, done.stderr
    if done.returncode == 1:
        assert "error" in done.stdout + done.stderr
