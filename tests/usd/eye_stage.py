"""The rigged eye pair as a USD stage and as its glTF twin, from the same numpy arrays.

Each eye is an eyeball mesh whose front faces (a materialBind GeomSubset) are
the cornea's glass, and an iris disc behind it with an iris texture (a PNG
written beside the stage) and a "dilate" blend shape that opens the pupil. A
UsdSkel skeleton turns both eyes (the gaze, joint rotations sampled over
time); the back of each eyeball is weighted partly to the head joint, so
linear blend skinning really blends. Materials are bound for the preview
purpose, with different full-purpose and all-purpose materials that must
lose. A camera, a sphere light (key), a distant light (fill) and a shaped
sphere light (a spot, the rim) light it.

The glTF twin holds the same vertices, skin, morph target, animation,
materials (KHR_materials_transmission and _ior), texture, camera and lights
(KHR_lights_punctual, intensities converted by the rules of docs/usd.md), so
snell.Scene.load renders what snell.usd reads. tests/usd and bench/usd_feed.py
both build it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from gltf_writer import GltfWriter

SEPARATION = 1.25  # each eye's centre is this far from the middle, metres
LIMBUS = math.radians(35.0)  # the angle from the eye's axis where the cornea meets the sclera
CORNEA_RADIUS = 0.75
IRIS_DEPTH = 0.74  # the iris sits this far in front of the eye's centre
CORNEA_IOR = 1.376
TIME_CODES = (1.0, 48.0)
TIME_CODES_PER_SECOND = 24.0
KEY_STEP = 4  # the gaze and the pupil are keyed every 4 time codes
CAMERA_POSITION = (0.0, 0.2, 7.0)
CAMERA_YFOV = 0.6  # radians
FOCAL_LENGTH = 35.0  # tenths of a scene unit, as USD cameras count (millimetres for a centimetre stage)
ASPECT = 4.0 / 3.0

SCLERA = (0.82, 0.78, 0.74)
IRIS_ROUGHNESS = 0.8
CORNEA_ROUGHNESS = 0.05

# Lights: (intensity, exposure, colour, radius) of the key sphere light; the
# fill's (intensity, angle in degrees); the rim spot's (intensity, radius, cone
# angle in degrees, softness).
KEY = dict(intensity=640.0, exposure=1.0, color=(1.0, 0.95, 0.9), radius=0.25, position=(3.0, 4.0, 8.0))
FILL = dict(intensity=40.0, angle=10.0, color=(0.8, 0.85, 1.0), direction=(-0.4, -0.3, -1.0))
RIM = dict(intensity=4775.0, radius=0.1, cone=30.0, softness=0.3, color=(1.0, 1.0, 1.0), position=(-4.0, 3.0, -3.0))


@dataclass
class EyeArrays:
    """One eye's geometry in its own space (centre at the origin, looking down +Z)."""

    ball_points: np.ndarray  # (P, 3) float32
    ball_counts: np.ndarray  # faces' vertex counts
    ball_indices: np.ndarray  # face-vertex point indices
    ball_cornea_faces: np.ndarray  # the faces of the cornea's glass
    ball_normals: np.ndarray  # faceVarying normal values (indexed)
    ball_normal_indices: np.ndarray  # per face-vertex
    ball_head_weight: np.ndarray  # per point: the head joint's weight (the eye joint has 1 minus it)
    iris_points: np.ndarray
    iris_counts: np.ndarray
    iris_indices: np.ndarray
    iris_normals: np.ndarray  # per point
    iris_st: np.ndarray  # per point, USD's st: (0, 0) is the image's lower left
    dilate_indices: np.ndarray  # the points the blend shape moves
    dilate_offsets: np.ndarray  # their offsets


@dataclass
class EyeStage:
    """The files of a written eye pair."""

    usd: Path
    gltf: Path
    texture: Path


def eye_arrays(rings: int = 24, segments: int = 32, iris_rings: int = 10) -> EyeArrays:
    """The eyeball (sclera, and the cornea's dome over its opening) and the iris disc."""
    opening = math.sin(LIMBUS)
    limbus_z = math.cos(LIMBUS)
    centre_z = limbus_z - math.sqrt(CORNEA_RADIUS**2 - opening**2)  # the cornea sphere's centre
    cornea_angle = math.asin(opening / CORNEA_RADIUS)
    limbus_ring = rings // 4
    points = [(0.0, 0.0, centre_z + CORNEA_RADIUS)]
    cornea_normals, sclera_normals = [(0.0, 0.0, 1.0)], [(0.0, 0.0, 1.0)]
    for ring in range(1, rings):
        if ring <= limbus_ring:
            a = cornea_angle * ring / limbus_ring
            radius, z = CORNEA_RADIUS * math.sin(a), centre_z + CORNEA_RADIUS * math.cos(a)
        else:
            theta = LIMBUS + (math.pi - LIMBUS) * (ring - limbus_ring) / (rings - limbus_ring)
            radius, z = math.sin(theta), math.cos(theta)
        for s in range(segments):
            phi = 2 * math.pi * s / segments
            p = (radius * math.cos(phi), radius * math.sin(phi), z)
            points.append(p)
            c = np.subtract(p, (0.0, 0.0, centre_z)) / CORNEA_RADIUS
            cornea_normals.append(tuple(c))
            sclera_normals.append(tuple(np.asarray(p) / np.linalg.norm(p)))
    points.append((0.0, 0.0, -1.0))
    cornea_normals.append((0.0, 0.0, -1.0))
    sclera_normals.append((0.0, 0.0, -1.0))
    P = len(points)

    def ring_start(ring: int) -> int:
        return 1 + (ring - 1) * segments

    faces, cornea = [], []
    for s in range(segments):  # the cornea's apex fan, counter-clockwise seen from +Z
        faces.append((0, ring_start(1) + s, ring_start(1) + (s + 1) % segments))
        cornea.append(True)
    for ring in range(1, rings - 1):
        for s in range(segments):
            a, b = ring_start(ring) + s, ring_start(ring + 1) + s
            c, d = ring_start(ring + 1) + (s + 1) % segments, ring_start(ring) + (s + 1) % segments
            faces.append((a, b, c, d))
            cornea.append(ring < limbus_ring)
    back = P - 1
    for s in range(segments):
        faces.append((ring_start(rings - 1) + s, back, ring_start(rings - 1) + (s + 1) % segments))
        cornea.append(False)
    counts = np.array([len(f) for f in faces], np.int32)
    indices = np.array([i for f in faces for i in f], np.int32)
    cornea = np.array(cornea)
    # faceVarying normals, indexed: the cornea's faces take the cornea sphere's
    # normals and the sclera's the eyeball's, so the limbus is a crease.
    on_cornea = np.repeat(cornea, counts)
    normal_indices = np.where(on_cornea, indices + P, indices).astype(np.int32)
    normals = np.concatenate([np.array(sclera_normals), np.array(cornea_normals)]).astype(np.float32)
    points = np.array(points, np.float32)
    head_weight = np.where(points[:, 2] < -0.5, 0.25, 0.0).astype(np.float32)

    # The iris: a shallow cone facing +Z just behind the limbus, bowed towards the cornea at the pupil.
    outer = math.sin(LIMBUS) * 0.99
    ipoints, st = [(0.0, 0.0, IRIS_DEPTH + 0.04)], [(0.5, 0.5)]
    for ring in range(1, iris_rings + 1):
        r = outer * ring / iris_rings
        for s in range(segments):
            phi = 2 * math.pi * s / segments
            ipoints.append((r * math.cos(phi), r * math.sin(phi), IRIS_DEPTH + 0.04 * (1 - r / outer)))
            st.append((0.5 + 0.5 * ring / iris_rings * math.cos(phi), 0.5 + 0.5 * ring / iris_rings * math.sin(phi)))
    ifaces = [(0, 1 + s, 1 + (s + 1) % segments) for s in range(segments)]
    for ring in range(1, iris_rings):
        base = 1 + (ring - 1) * segments
        for s in range(segments):
            ifaces.append((base + s, base + segments + s, base + segments + (s + 1) % segments,
                           base + (s + 1) % segments))
    ipoints = np.array(ipoints, np.float32)
    # The cone's normals: the slope 0.04 / outer tilts them outwards.
    r = np.hypot(ipoints[:, 0], ipoints[:, 1])
    slope = 0.04 / outer
    inormals = np.stack([ipoints[:, 0] / np.maximum(r, 1e-9) * slope, ipoints[:, 1] / np.maximum(r, 1e-9) * slope,
                         np.ones(len(ipoints))], axis=1)
    inormals[0] = (0.0, 0.0, 1.0)
    inormals /= np.linalg.norm(inormals, axis=1, keepdims=True)
    # The pupil opens: points move outwards, the rim stays (a sparse blend shape: the rim is left out).
    grown = r + 0.7 * r * np.maximum(0.0, 1 - r / outer) ** 1.5
    moved = np.nonzero((r > 0) & (grown - r > 1e-7))[0]
    offsets = np.zeros((len(moved), 3), np.float32)
    offsets[:, 0] = ipoints[moved, 0] * (grown[moved] / r[moved] - 1)
    offsets[:, 1] = ipoints[moved, 1] * (grown[moved] / r[moved] - 1)
    return EyeArrays(
        ball_points=points, ball_counts=counts, ball_indices=indices, ball_cornea_faces=np.nonzero(cornea)[0],
        ball_normals=normals, ball_normal_indices=normal_indices, ball_head_weight=head_weight,
        iris_points=ipoints, iris_counts=np.array([len(f) for f in ifaces], np.int32),
        iris_indices=np.array([i for f in ifaces for i in f], np.int32), iris_normals=inormals.astype(np.float32),
        iris_st=np.array(st, np.float32), dilate_indices=moved.astype(np.int32), dilate_offsets=offsets)


def iris_texture(size: int = 128) -> np.ndarray:
    """A painted iris as (size, size, 4) uint8 sRGB: fibres, an amber collarette, a limbal ring, a black pupil.

    Asymmetric on purpose (a notch at the top right), so a flipped v shows.
    """
    y, x = (np.mgrid[0:size, 0:size] + 0.5) / size * 2.0 - 1.0
    r, angle = np.hypot(x, y), np.arctan2(y, x)
    fibres = 0.5 + 0.5 * np.sin(angle * 31.0 + 3.0 * np.sin(angle * 7.0)) * np.sin(r * 23.0)
    colour = np.stack([0.10 + 0.25 * fibres, 0.30 + 0.25 * fibres, 0.35 + 0.20 * fibres], axis=-1)
    amber = np.clip(1.0 - (r - 0.30) / 0.15, 0.0, 1.0)[..., None]
    colour = colour * (1 - amber) + np.array([0.55, 0.35, 0.10]) * amber * (0.6 + 0.4 * fibres[..., None])
    colour *= np.clip((1.0 - r) / 0.12, 0.25, 1.0)[..., None]
    colour[(x > 0.3) & (y < -0.3) & (r < 0.8)] = (0.9, 0.8, 0.2)  # the notch: row 0 is the top
    colour[r < 0.30] = 0.015
    rgba = np.concatenate([colour, np.ones((size, size, 1))], axis=-1)
    return np.rint(np.clip(rgba, 0, 1) * 255).astype(np.uint8)


def write_png(path: Path, rgba: np.ndarray) -> Path:
    """Writes an 8-bit image through OpenImageIO (row 0 at the top)."""
    import OpenImageIO as oiio

    spec = oiio.ImageSpec(rgba.shape[1], rgba.shape[0], rgba.shape[2], "uint8")
    spec.attribute("oiio:UnassociatedAlpha", 1)  # the values as given: OpenImageIO would unpremultiply them
    out = oiio.ImageOutput.create(str(path))
    assert out is not None and out.open(str(path), spec), oiio.geterror()
    assert out.write_image(rgba), out.geterror()
    out.close()
    return Path(path)


def gaze(t: float) -> tuple[float, float]:
    """The eyes' (yaw, pitch) in radians at time code t."""
    phase = 2 * math.pi * (t - TIME_CODES[0]) / (TIME_CODES[1] - TIME_CODES[0])
    return 0.35 * math.sin(phase), 0.15 * math.sin(2 * phase)


def dilation(t: float) -> float:
    """The pupil's blend shape weight at time code t."""
    return 0.5 - 0.5 * math.cos(2 * math.pi * (t - TIME_CODES[0]) / (TIME_CODES[1] - TIME_CODES[0]))


def key_times() -> list[float]:
    return [float(t) for t in np.arange(TIME_CODES[0], TIME_CODES[1] + KEY_STEP, KEY_STEP)]


def eye_rotation(t: float, side: float) -> np.ndarray:
    """The eye joint's rotation as a unit quaternion (w, x, y, z): yaw about +Y, then pitch about +X."""
    yaw, pitch = gaze(t)
    yaw += 0.04 * side  # a little vergence: the eyes turn in
    qy = np.array([math.cos(yaw / 2), 0.0, math.sin(yaw / 2), 0.0])
    qx = np.array([math.cos(-pitch / 2), math.sin(-pitch / 2), 0.0, 0.0])
    w1, x1, y1, z1 = qy
    w2, x2, y2, z2 = qx
    return np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                     w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])


def look_at_matrix(position, target) -> np.ndarray:
    """A 4x4 (column vectors) whose -Z looks from position to target, +Y up."""
    position, target = np.asarray(position, float), np.asarray(target, float)
    back = position - target
    back /= np.linalg.norm(back)
    right = np.cross((0.0, 1.0, 0.0), back)
    right /= np.linalg.norm(right)
    up = np.cross(back, right)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = right, up, back, position
    return m


def key_candela() -> float:
    """The key's intensity for snell (docs/usd.md: I = L A / 4, A = 4 pi r^2 for a sphere)."""
    luminance = KEY["intensity"] * 2.0 ** KEY["exposure"]
    return luminance * math.pi * KEY["radius"] ** 2


def fill_lux() -> float:
    """The fill's illuminance (docs/usd.md: E = L pi sin^2(angle / 2) for an unnormalized distant light)."""
    return FILL["intensity"] * math.pi * math.sin(math.radians(FILL["angle"]) / 2) ** 2


def rim_candela() -> float:
    return RIM["intensity"] * math.pi * RIM["radius"] ** 2


def write_eye_stage(folder: Path, arrays: EyeArrays | None = None, name: str = "eyes") -> EyeStage:
    """Writes the eye pair as NAME.usda (+ iris.png) and its glTF twin NAME.gltf (+ .bin) into folder."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    arrays = arrays or eye_arrays()
    texture = write_png(folder / "iris.png", iris_texture())
    usd = _write_usd(folder / f"{name}.usda", arrays, texture)
    gltf = _write_gltf(folder / f"{name}.gltf", arrays, texture)
    return EyeStage(usd=usd, gltf=gltf, texture=texture)


def _write_usd(path: Path, a: EyeArrays, texture: Path) -> Path:
    from pxr import Gf, Sdf, Usd, UsdGeom, UsdLux, UsdShade, UsdSkel, Vt

    stage = Usd.Stage.CreateNew(str(path))
    UsdGeom.SetStageUpAxis(stage, UsdGeom.Tokens.y)
    UsdGeom.SetStageMetersPerUnit(stage, 1.0)
    stage.SetStartTimeCode(TIME_CODES[0])
    stage.SetEndTimeCode(TIME_CODES[1])
    stage.SetTimeCodesPerSecond(TIME_CODES_PER_SECOND)
    world = UsdGeom.Xform.Define(stage, "/World")
    stage.SetDefaultPrim(world.GetPrim())

    # Materials: preview ones that must win, full and all-purpose ones that must lose.
    looks = "/World/Looks"
    UsdGeom.Scope.Define(stage, looks)

    def preview_surface(name: str, **inputs) -> UsdShade.Material:
        material = UsdShade.Material.Define(stage, f"{looks}/{name}")
        shader = UsdShade.Shader.Define(stage, f"{looks}/{name}/Surface")
        shader.CreateIdAttr("UsdPreviewSurface")
        for key, value in inputs.items():
            kind = Sdf.ValueTypeNames.Color3f if isinstance(value, tuple) else Sdf.ValueTypeNames.Float
            shader.CreateInput(key, kind).Set(value)
        material.CreateSurfaceOutput().ConnectToSource(shader.ConnectableAPI(), "surface")
        return material

    sclera = preview_surface("Sclera", diffuseColor=SCLERA)  # roughness left at its fallback, 0.5
    cornea = preview_surface("Cornea", diffuseColor=(1.0, 1.0, 1.0), opacity=0.0, ior=CORNEA_IOR,
                             roughness=CORNEA_ROUGHNESS)
    iris = preview_surface("Iris", roughness=IRIS_ROUGHNESS)
    # The iris texture as the simpleShading tutorial wires it: the st reader's
    # varname comes from the material's interface input.
    surface = UsdShade.Shader(stage.GetPrimAtPath(f"{looks}/Iris/Surface"))
    reader = UsdShade.Shader.Define(stage, f"{looks}/Iris/StReader")
    reader.CreateIdAttr("UsdPrimvarReader_float2")
    frame_name = iris.CreateInput("frame:stPrimvarName", Sdf.ValueTypeNames.Token)
    frame_name.Set("st")
    reader.CreateInput("varname", Sdf.ValueTypeNames.Token).ConnectToSource(frame_name)
    image = UsdShade.Shader.Define(stage, f"{looks}/Iris/IrisTexture")
    image.CreateIdAttr("UsdUVTexture")
    image.CreateInput("file", Sdf.ValueTypeNames.Asset).Set(Sdf.AssetPath(f"./{texture.name}"))
    image.CreateInput("sourceColorSpace", Sdf.ValueTypeNames.Token).Set("sRGB")
    image.CreateInput("wrapS", Sdf.ValueTypeNames.Token).Set("repeat")
    image.CreateInput("wrapT", Sdf.ValueTypeNames.Token).Set("repeat")
    image.CreateInput("st", Sdf.ValueTypeNames.Float2).ConnectToSource(reader.ConnectableAPI(), "result")
    image.CreateOutput("rgb", Sdf.ValueTypeNames.Float3)
    surface.CreateInput("diffuseColor", Sdf.ValueTypeNames.Color3f).ConnectToSource(image.ConnectableAPI(), "rgb")
    sclera_full = preview_surface("ScleraFull", diffuseColor=(0.8, 0.1, 0.1))
    cornea_full = preview_surface("CorneaFull", diffuseColor=(0.1, 0.2, 0.9))
    iris_all = preview_surface("IrisAllPurpose", diffuseColor=(0.1, 0.8, 0.1))

    def bind(prim, preview, other, other_purpose) -> None:
        api = UsdShade.MaterialBindingAPI.Apply(prim)
        api.Bind(preview, UsdShade.Tokens.fallbackStrength, UsdShade.Tokens.preview)
        api.Bind(other, UsdShade.Tokens.fallbackStrength, other_purpose)

    # The rig: a skeleton whose eye joints the animation turns.
    root = UsdSkel.Root.Define(stage, "/World/Rig")
    UsdGeom.Xformable(root).AddTranslateOp().Set(Gf.Vec3d(0.0, 0.05, 0.0))
    skel = UsdSkel.Skeleton.Define(stage, "/World/Rig/Skel")
    joints = ["Head", "Head/EyeL", "Head/EyeR"]
    skel.CreateJointsAttr(joints)
    eyes = {"L": SEPARATION, "R": -SEPARATION}
    bind_xforms = [Gf.Matrix4d(1.0)] + [Gf.Matrix4d(1.0).SetTranslate(Gf.Vec3d(x, 0, 0)) for x in eyes.values()]
    skel.CreateBindTransformsAttr(Vt.Matrix4dArray(bind_xforms))
    skel.CreateRestTransformsAttr(Vt.Matrix4dArray(bind_xforms))
    anim = UsdSkel.Animation.Define(stage, "/World/Rig/Skel/Gaze")
    anim.CreateJointsAttr(joints[1:])  # a partial animation: the head keeps its rest pose
    anim.CreateTranslationsAttr(Vt.Vec3fArray([Gf.Vec3f(x, 0, 0) for x in eyes.values()]))
    anim.CreateScalesAttr(Vt.Vec3hArray([Gf.Vec3h(1, 1, 1)] * 2))
    rotations = anim.CreateRotationsAttr()
    anim.CreateBlendShapesAttr(["dilate"])
    weights = anim.CreateBlendShapeWeightsAttr()
    for t in key_times():
        quats = [eye_rotation(t, +1.0), eye_rotation(t, -1.0)]
        rotations.Set(Vt.QuatfArray([Gf.Quatf(*map(float, q)) for q in quats]), Usd.TimeCode(t))
        weights.Set(Vt.FloatArray([dilation(t)]), Usd.TimeCode(t))
    binding = UsdSkel.BindingAPI.Apply(skel.GetPrim())
    binding.CreateAnimationSourceRel().SetTargets([anim.GetPath()])
    UsdSkel.BindingAPI.Apply(root.GetPrim()).CreateSkeletonRel().SetTargets([skel.GetPath()])

    for side, x in eyes.items():
        eye_joint = joints.index(f"Head/Eye{side}")
        ball = UsdGeom.Mesh.Define(stage, f"/World/Rig/Eyeball{side}")
        ball.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(a.ball_points + np.float32([x, 0, 0])))
        ball.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(a.ball_counts))
        ball.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(a.ball_indices))
        ball.CreateSubdivisionSchemeAttr("none")
        normals = UsdGeom.PrimvarsAPI(ball).CreatePrimvar("normals", Sdf.ValueTypeNames.Normal3fArray,
                                                          UsdGeom.Tokens.faceVarying)
        normals.Set(Vt.Vec3fArray.FromNumpy(a.ball_normals))
        normals.SetIndices(Vt.IntArray.FromNumpy(a.ball_normal_indices))
        skin = UsdSkel.BindingAPI.Apply(ball.GetPrim())
        head = a.ball_head_weight
        skin.CreateJointIndicesPrimvar(False, 2).Set(
            Vt.IntArray.FromNumpy(np.tile(np.int32([eye_joint, 0]), len(head))))
        skin.CreateJointWeightsPrimvar(False, 2).Set(
            Vt.FloatArray.FromNumpy(np.stack([1 - head, head], axis=1).reshape(-1).astype(np.float32)))
        subset = UsdGeom.Subset.CreateGeomSubset(ball, "cornea", UsdGeom.Tokens.face,
                                                 Vt.IntArray.FromNumpy(a.ball_cornea_faces.astype(np.int32)),
                                                 UsdShade.Tokens.materialBind, UsdGeom.Tokens.nonOverlapping)
        bind(ball.GetPrim(), sclera, sclera_full, UsdShade.Tokens.full)
        bind(subset.GetPrim(), cornea, cornea_full, UsdShade.Tokens.full)

        disc = UsdGeom.Mesh.Define(stage, f"/World/Rig/Iris{side}")
        disc.CreatePointsAttr(Vt.Vec3fArray.FromNumpy(a.iris_points + np.float32([x, 0, 0])))
        disc.CreateFaceVertexCountsAttr(Vt.IntArray.FromNumpy(a.iris_counts))
        disc.CreateFaceVertexIndicesAttr(Vt.IntArray.FromNumpy(a.iris_indices))
        disc.CreateSubdivisionSchemeAttr("none")
        disc.CreateNormalsAttr(Vt.Vec3fArray.FromNumpy(a.iris_normals))
        disc.SetNormalsInterpolation(UsdGeom.Tokens.vertex)
        st = UsdGeom.PrimvarsAPI(disc).CreatePrimvar("st", Sdf.ValueTypeNames.TexCoord2fArray, UsdGeom.Tokens.vertex)
        st.Set(Vt.Vec2fArray.FromNumpy(a.iris_st))
        st.SetIndices(Vt.IntArray.FromNumpy(np.arange(len(a.iris_st), dtype=np.int32)))
        skin = UsdSkel.BindingAPI.Apply(disc.GetPrim())
        skin.CreateJointsAttr([f"Head/Eye{side}"])  # the mesh's own joint order: index 0 is its eye
        skin.CreateJointIndicesPrimvar(False, 1).Set(Vt.IntArray.FromNumpy(np.zeros(len(a.iris_points), np.int32)))
        skin.CreateJointWeightsPrimvar(False, 1).Set(Vt.FloatArray.FromNumpy(np.ones(len(a.iris_points), np.float32)))
        shape = UsdSkel.BlendShape.Define(stage, f"/World/Rig/Iris{side}/Dilate")
        shape.CreateOffsetsAttr(Vt.Vec3fArray.FromNumpy(a.dilate_offsets))
        shape.CreatePointIndicesAttr(Vt.IntArray.FromNumpy(a.dilate_indices))
        skin.CreateBlendShapesAttr(["dilate"])
        skin.CreateBlendShapeTargetsRel().SetTargets([shape.GetPath()])
        bind(disc.GetPrim(), iris, iris_all, UsdShade.Tokens.allPurpose)

    camera = UsdGeom.Camera.Define(stage, "/World/Camera")
    camera.AddTranslateOp().Set(Gf.Vec3d(*CAMERA_POSITION))
    vertical = 2 * FOCAL_LENGTH * math.tan(CAMERA_YFOV / 2)
    camera.CreateFocalLengthAttr(FOCAL_LENGTH)
    camera.CreateVerticalApertureAttr(vertical)
    camera.CreateHorizontalApertureAttr(vertical * ASPECT)
    camera.CreateClippingRangeAttr(Gf.Vec2f(0.1, 100.0))

    key = UsdLux.SphereLight.Define(stage, "/World/Key")
    key.CreateIntensityAttr(KEY["intensity"])
    key.CreateExposureAttr(KEY["exposure"])
    key.CreateColorAttr(Gf.Vec3f(*KEY["color"]))
    key.CreateRadiusAttr(KEY["radius"])
    key.AddTranslateOp().Set(Gf.Vec3d(*KEY["position"]))
    fill = UsdLux.DistantLight.Define(stage, "/World/Fill")
    fill.CreateIntensityAttr(FILL["intensity"])
    fill.CreateAngleAttr(FILL["angle"])
    fill.CreateColorAttr(Gf.Vec3f(*FILL["color"]))
    fill.AddTransformOp().Set(Gf.Matrix4d(*look_at_matrix((0, 0, 0), FILL["direction"]).T.reshape(-1).tolist()))
    rim = UsdLux.SphereLight.Define(stage, "/World/Rim")
    rim.CreateIntensityAttr(RIM["intensity"])
    rim.CreateRadiusAttr(RIM["radius"])
    rim.CreateTreatAsPointAttr(True)
    rim.CreateColorAttr(Gf.Vec3f(*RIM["color"]))
    shaping = UsdLux.ShapingAPI.Apply(rim.GetPrim())
    shaping.CreateShapingConeAngleAttr(RIM["cone"])
    shaping.CreateShapingConeSoftnessAttr(RIM["softness"])
    rim.AddTransformOp().Set(Gf.Matrix4d(*look_at_matrix(RIM["position"], (0, 0, 0)).T.reshape(-1).tolist()))
    stage.GetRootLayer().Save()
    return path


def _write_gltf(path: Path, a: EyeArrays, texture: Path) -> Path:
    g = GltfWriter()
    sclera = g.material(base_color=(*SCLERA, 1.0), roughness=0.5)
    cornea = g.material(base_color=(1, 1, 1, 1), roughness=CORNEA_ROUGHNESS, transmission=1.0, ior=CORNEA_IOR)
    iris = g.material(roughness=IRIS_ROUGHNESS, texture=texture.name)
    rig = g.node(name="Rig", translation=[0.0, 0.05, 0.0])
    head = g.node(name="Head", parent=rig)
    eye_nodes = {side: g.node(name=f"Eye{side}", parent=head, translation=[x, 0.0, 0.0])
                 for side, x in (("L", SEPARATION), ("R", -SEPARATION))}
    offset = np.float32([0.0, 0.05, 0.0])  # glTF skinned vertices are in the bind pose's world space
    inverse_binds = []
    for node in [head, eye_nodes["L"], eye_nodes["R"]]:
        m = np.eye(4)
        m[:3, 3] = -(np.asarray(g.doc["nodes"][node].get("translation", [0, 0, 0])) + offset)
        inverse_binds.append(m)
    skin = g.skin([head, eye_nodes["L"], eye_nodes["R"]], inverse_binds, skeleton=rig)
    corners_fan = _fan(a.ball_counts)
    iris_corners = _fan(a.iris_counts)
    iris_nodes = {}
    for side, x in (("L", SEPARATION), ("R", -SEPARATION)):
        joint = 1 if side == "L" else 2
        face_of_corner = np.repeat(np.arange(len(a.ball_counts)), a.ball_counts - 2)
        cornea_face = np.zeros(len(a.ball_counts), bool)
        cornea_face[a.ball_cornea_faces] = True
        primitives = []
        for material, faces in ((sclera, ~cornea_face[face_of_corner]), (cornea, cornea_face[face_of_corner])):
            corners = corners_fan[faces]
            keys = np.stack([a.ball_indices[corners], a.ball_normal_indices[corners]], axis=-1).reshape(-1, 2)
            unique, inverse = np.unique(keys, axis=0, return_inverse=True)
            positions = a.ball_points[unique[:, 0]] + np.float32([x, 0, 0]) + offset
            normals = a.ball_normals[unique[:, 1]]
            head_w = a.ball_head_weight[unique[:, 0]]
            joints = np.zeros((len(unique), 4), np.uint16)
            joints[:, 0] = joint
            w = np.zeros((len(unique), 4), np.float32)
            w[:, 0], w[:, 1] = 1 - head_w, head_w
            primitives.append(dict(positions=positions.astype(np.float32), normals=normals.astype(np.float32),
                                   indices=inverse.reshape(-1, 3).astype(np.uint32), material=material,
                                   joints=joints, weights=w))
        g.node(name=f"Eyeball{side}", mesh=g.mesh(primitives), skin=skin)
        joints = np.zeros((len(a.iris_points), 4), np.uint16)
        joints[:, 0] = joint
        w = np.zeros((len(a.iris_points), 4), np.float32)
        w[:, 0] = 1.0
        dense = np.zeros_like(a.iris_points)
        dense[a.dilate_indices] = a.dilate_offsets
        uv = a.iris_st.copy()
        uv[:, 1] = 1.0 - uv[:, 1]  # glTF's v runs down the image
        iris_mesh = g.mesh([dict(positions=a.iris_points + np.float32([x, 0, 0]) + offset, normals=a.iris_normals,
                                 uvs=uv, indices=a.iris_indices[iris_corners].astype(np.uint32), material=iris,
                                 joints=joints, weights=w, targets=[dense])], weights=[0.0])
        iris_nodes[side] = g.node(name=f"Iris{side}", mesh=iris_mesh, skin=skin)
    seconds = [t / TIME_CODES_PER_SECOND for t in key_times()]
    for side, sign in (("L", 1.0), ("R", -1.0)):
        quats = [eye_rotation(t, sign) for t in key_times()]
        g.animate(eye_nodes[side], "rotation", seconds, [[q[1], q[2], q[3], q[0]] for q in quats])
        g.animate(iris_nodes[side], "weights", seconds, [[dilation(t)] for t in key_times()])
    g.camera(CAMERA_YFOV, ASPECT, np.array(CAMERA_POSITION), name="Camera")
    g.light("point", KEY["color"], key_candela(), translation=KEY["position"], name="Key")
    fill = look_at_matrix((0, 0, 0), FILL["direction"])
    g.light("directional", FILL["color"], fill_lux(), matrix=fill, name="Fill")
    rim = look_at_matrix(RIM["position"], (0, 0, 0))
    outer = math.radians(RIM["cone"])
    g.light("spot", RIM["color"], rim_candela(), matrix=rim, name="Rim",
            spot=dict(innerConeAngle=outer * (1 - RIM["softness"]), outerConeAngle=outer))
    return g.write(path)


def _fan(counts: np.ndarray) -> np.ndarray:
    """Fan triangles of polygons as (T, 3) face-vertex (corner) ids."""
    tris = counts - 2
    start = np.cumsum(counts) - counts
    face = np.repeat(np.arange(len(counts)), tris)
    k = np.arange(tris.sum()) - np.repeat(np.cumsum(tris) - tris, tris) + 1
    return np.stack([start[face], start[face] + k, start[face] + k + 1], axis=1)
