"""What snell reads differently from what the stage says is a warning that names the prim."""

from __future__ import annotations

from pxr import Sdf, UsdGeom, UsdShade

import snell.usd
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
