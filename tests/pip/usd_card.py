"""The stage both pip tests draw: a 2 m card facing +Z, written by usd-core."""

from __future__ import annotations

from pxr import Gf, Usd, UsdGeom


def define_card(stage: Usd.Stage) -> UsdGeom.Mesh:
    """A Y-up, metre stage's /World/card: one quad from (-1, -1, 0) to (1, 1, 0), not subdivided."""
    UsdGeom.SetStageUpAxis(stage, "Y")
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    card = UsdGeom.Mesh.Define(stage, "/World/card")
    card.CreatePointsAttr([Gf.Vec3f(-1, -1, 0), Gf.Vec3f(1, -1, 0), Gf.Vec3f(1, 1, 0), Gf.Vec3f(-1, 1, 0)])
    card.CreateFaceVertexCountsAttr([4])
    card.CreateFaceVertexIndicesAttr([0, 1, 2, 3])
    card.CreateSubdivisionSchemeAttr("none")
    return card
