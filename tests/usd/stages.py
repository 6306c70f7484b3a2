"""Small USD stages for single behaviours, written with pxr in the test's folder."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Optional, Sequence

import numpy as np
from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade, Vt


def new_stage(path: Path, up: str = "Y", meters_per_unit: Optional[float] = 1.0,
              time_range: Optional[tuple[float, float]] = None) -> Usd.Stage:
    """An empty stage with a /World default prim (meters_per_unit None: left unauthored)."""
    layer = Sdf.Layer.Find(str(path))
    if layer:  # a test that writes the same file twice: USD still holds the first
        layer.Clear()
        stage = Usd.Stage.Open(layer)
    else:
        stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, up)
    if meters_per_unit is not None:
        UsdGeom.SetStageMetersPerUnit(stage, meters_per_unit)
    if time_range is not None:
        stage.SetStartTimeCode(time_range[0])
        stage.SetEndTimeCode(time_range[1])
    stage.SetDefaultPrim(UsdGeom.Xform.Define(stage, "/World").GetPrim())
    return stage


def mesh(stage: Usd.Stage, path: str, points, counts: Sequence[int], indices: Sequence[int],
         normals=None, normals_interpolation: str = "vertex", st=None, st_interpolation: str = "vertex",
         st_indices=None) -> UsdGeom.Mesh:
    """A polygon mesh (subdivisionScheme none) with optional normals and primvars:st."""
    m = UsdGeom.Mesh.Define(stage, path)
    m.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(np.asarray(points, np.float32)))
    m.CreateFaceVertexCountsAttr(list(map(int, counts)))
    m.CreateFaceVertexIndicesAttr(list(map(int, indices)))
    m.CreateSubdivisionSchemeAttr("none")
    if normals is not None:
        m.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(np.asarray(normals, np.float32)))
        m.SetNormalsInterpolation(normals_interpolation)
    if st is not None:
        primvar = UsdGeom.PrimvarsAPI(m).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, st_interpolation)
        primvar.Set(Vt.Vec2fArray.FromNumpy(np.asarray(st, np.float32)))
        if st_indices is not None:
            primvar.SetIndices(Vt.IntArray(list(map(int, st_indices))))
    return m


def quad(stage: Usd.Stage, path: str, size: float = 2.0, z: float = 0.0, st: bool = True) -> UsdGeom.Mesh:
    """A square facing +Z, st (0, 0) at its lower left."""
    h = size / 2
    points = [(-h, -h, z), (h, -h, z), (h, h, z), (-h, h, z)]
    return mesh(stage, path, points, [4], [0, 1, 2, 3], normals=[(0, 0, 1)] * 4,
                st=[(0, 0), (1, 0), (1, 1), (0, 1)] if st else None)


def sphere_arrays(radius: float = 0.5, rings: int = 12, segments: int = 16, centre=(0.0, 0.0, 0.0)):
    """A UV sphere as (points, counts, indices, normals): quads and pole triangles, counter-clockwise outside."""
    points, normals = [], []
    for r in range(1, rings):
        theta = math.pi * r / rings
        for s in range(segments):
            phi = 2 * math.pi * s / segments
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            normals.append(n)
            points.append(tuple(centre[i] + radius * n[i] for i in range(3)))
    top, bottom = len(points), len(points) + 1
    points += [(centre[0], centre[1] + radius, centre[2]), (centre[0], centre[1] - radius, centre[2])]
    normals += [(0, 1, 0), (0, -1, 0)]
    counts, indices = [], []

    def at(r: int, s: int) -> int:
        return (r - 1) * segments + s % segments

    for s in range(segments):
        counts.append(3)
        indices += [top, at(1, s), at(1, s + 1)]
    for r in range(1, rings - 1):
        for s in range(segments):
            counts.append(4)
            indices += [at(r, s), at(r + 1, s), at(r + 1, s + 1), at(r, s + 1)]
    for s in range(segments):
        counts.append(3)
        indices += [bottom, at(rings - 1, s + 1), at(rings - 1, s)]
    return np.array(points, np.float32), counts, indices, np.array(normals, np.float32)


def preview_material(stage: Usd.Stage, path: str, **inputs) -> UsdShade.Material:
    """A Material whose surface is a UsdPreviewSurface with these constant inputs."""
    material = UsdShade.Material.Define(stage, path)
    shader = UsdShade.Shader.Define(stage, f"{path}/Surface")
    shader.CreateIdAttr("UsdPreviewSurface")
    for name, value in inputs.items():
        if isinstance(value, str):
            kind = Sdf.ValueTypeNames.Token
        elif isinstance(value, tuple):
            kind = Sdf.ValueTypeNames.Normal3f if name == "normal" else Sdf.ValueTypeNames.Color3f
        elif isinstance(value, int) and not isinstance(value, bool):
            kind = Sdf.ValueTypeNames.Int
        else:
            kind = Sdf.ValueTypeNames.Float
        shader.CreateInput(name, kind).Set(value)
    material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
    return material


def texture(stage: Usd.Stage, material: UsdShade.Material, file: str, input_name: str = "diffuseColor",
            varname: str = "st", output: str = "rgb", **texture_inputs) -> UsdShade.Shader:
    """A UsdUVTexture (reading `varname` through a UsdPrimvarReader_float2) into the surface's input."""
    path = material.GetPath()
    reader = UsdShade.Shader.Define(stage, path.AppendChild("Reader"))
    reader.CreateIdAttr("UsdPrimvarReader_float2")
    reader.CreateInput("varname", Sdf.ValueTypeNames.Token).Set(varname)
    image = UsdShade.Shader.Define(stage, path.AppendChild(f"Texture_{input_name}"))
    image.CreateIdAttr("UsdUVTexture")
    image.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(file))
    for name, value in texture_inputs.items():
        kind = Sdf.ValueTypeNames.Token if isinstance(value, str) else Sdf.ValueTypeNames.Float4
        image.CreateInput(name, kind).Set(value if isinstance(value, str) else Gf.Vec4f(*value))
    image.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(reader.ConnectableAPI(), "result")
    connect(material, input_name, image, output)
    return image


def connect(material: UsdShade.Material, input_name: str, shader: UsdShade.Shader, output: str) -> None:
    """Connects the surface's input to a shader's output (rgb: a colour, or a normal; r, g, b, a: a float)."""
    surface = UsdShade.Shader(material.GetPrim().GetStage().GetPrimAtPath(material.GetPath().AppendChild("Surface")))
    kinds = {3: Sdf.ValueTypeNames.Float3, 4: Sdf.ValueTypeNames.Float4}
    shader.CreateOutput(output, kinds.get(len(output), Sdf.ValueTypeNames.Float))
    if len(output) == 1:
        kind = Sdf.ValueTypeNames.Float
    else:
        kind = Sdf.ValueTypeNames.Normal3f if input_name == "normal" else Sdf.ValueTypeNames.Color3f
    surface.CreateInput(input_name, kind).ConnectToSource(shader.ConnectableAPI(), output)


def transform2d(image: UsdShade.Shader, rotation: float = 0.0, scale=(1.0, 1.0),
                translation=(0.0, 0.0)) -> UsdShade.Shader:
    """Puts a UsdTransform2d between a texture and the primvar reader its st reads (rotation in degrees)."""
    st = image.GetInput("st")
    reader, output, _ = st.GetConnectedSource()
    path = image.GetPath().GetParentPath().AppendChild(f"{image.GetPath().name}_transform")
    transform = UsdShade.Shader.Define(image.GetPrim().GetStage(), path)
    transform.CreateIdAttr("UsdTransform2d")
    transform.CreateInput("in", Sdf.ValueTypeNames.Float2).ConnectToSource(reader, output)
    transform.CreateInput("rotation", Sdf.ValueTypeNames.Float).Set(float(rotation))
    transform.CreateInput("scale", Sdf.ValueTypeNames.Float2).Set(Gf.Vec2f(*map(float, scale)))
    transform.CreateInput("translation", Sdf.ValueTypeNames.Float2).Set(Gf.Vec2f(*map(float, translation)))
    transform.CreateOutput("result", Sdf.ValueTypeNames.Float2)
    st.ConnectToSource(transform.ConnectableAPI(), "result")
    return transform


def bind(prim: Usd.Prim, material: UsdShade.Material, purpose: str = UsdShade.Tokens.allPurpose) -> None:
    UsdShade.MaterialBindingAPI.Apply(prim).Bind(material, UsdShade.Tokens.fallbackStrength, purpose)


def sphere_light(stage: Usd.Stage, path: str, position, intensity: float = 500.0, radius: float = 0.25,
                 **attributes) -> UsdLux.SphereLight:
    light = UsdLux.SphereLight.Define(stage, path)
    light.CreateIntensityAttr(intensity)
    light.CreateRadiusAttr(radius)
    for name, value in attributes.items():
        getattr(light, f"Create{name[0].upper()}{name[1:]}Attr")(value)
    light.AddTranslateOp().Set(Gf.Vec3d(*map(float, position)))
    return light


def camera(stage: Usd.Stage, path: str, position=(0.0, 0.0, 5.0), focal_length: float = 35.0,
           aperture=(36.0, 24.0), offset=(0.0, 0.0)) -> UsdGeom.Camera:
    cam = UsdGeom.Camera.Define(stage, path)
    cam.AddTranslateOp().Set(Gf.Vec3d(*map(float, position)))
    cam.CreateFocalLengthAttr(focal_length)
    cam.CreateHorizontalApertureAttr(aperture[0])
    cam.CreateVerticalApertureAttr(aperture[1])
    cam.CreateHorizontalApertureOffsetAttr(offset[0])
    cam.CreateVerticalApertureOffsetAttr(offset[1])
    return cam


def write_rgba_png(path: Path, rgba: np.ndarray) -> Path:
    """An 8-bit PNG of an (h, w, 3 or 4) uint8 array, row 0 at the top."""
    from eye_stage import write_png

    return write_png(path, rgba)


def write_hdr(path: Path, rgb: np.ndarray) -> Path:
    """A Radiance HDR (RGBE, flat scanlines) of an (h, w, 3) float array, row 0 at the top."""
    rgb = np.maximum(np.asarray(rgb, np.float64), 0.0)
    height, width, _ = rgb.shape
    peak = rgb.max(axis=2)
    mantissa, exponent = np.frexp(peak)  # peak = mantissa * 2^exponent, mantissa in [0.5, 1)
    scale = np.where(peak > 1e-32, mantissa * 256.0 / np.where(peak > 1e-32, peak, 1.0), 0.0)
    rgbe = np.zeros((height, width, 4), np.uint8)
    rgbe[..., :3] = np.clip(rgb * scale[..., None], 0, 255).astype(np.uint8)
    rgbe[..., 3] = np.where(peak > 1e-32, exponent + 128, 0).astype(np.uint8)
    header = f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {height} +X {width}\n".encode()
    path.write_bytes(header + rgbe.tobytes())
    return path


def dome_light(stage: Usd.Stage, path: str, texture: Optional[str] = None, version_1: bool = False,
               **attributes) -> UsdLux.DomeLight:
    """A DomeLight (or DomeLight_1) with an optional texture file and LightAPI inputs (intensity, color, ...)."""
    light = (UsdLux.DomeLight_1 if version_1 else UsdLux.DomeLight).Define(stage, path)
    if texture is not None:
        light.CreateTextureFileAttr(Sdf.AssetPath(texture))
    for name, value in attributes.items():
        getattr(light, f"Create{name[0].upper()}{name[1:]}Attr")(value)
    return light
