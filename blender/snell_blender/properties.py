# SPDX-License-Identifier: GPL-3.0-or-later
"""The add-on's settings: per scene (how glass is drawn), per view layer (which passes), per object (who
subdivides it), per user (where snell is)."""

from __future__ import annotations

import bpy

METHODS = [
    ("trace", "Trace", "Ray traced through the deformed mesh, every refraction (the talk's approach)"),
    ("trace-1", "Trace, one bend", "Ray traced, bending at the first glass face only"),
    ("iris-plane", "Iris plane", "Refracted once onto the plane behind the glass; no trace"),
    ("normal-offset", "Normal offset", "The picture behind the glass displaced by the normal; no trace"),
    ("refraction-map", "Refraction map", "A map baked by the trace once, read as the scene moves"),
    ("none", "None", "Glass seen straight through"),
]


class SnellSceneSettings(bpy.types.PropertyGroup):
    """How snell draws a scene's glass (Render Properties > snell)."""

    method: bpy.props.EnumProperty(name="Method", items=METHODS, default="trace",
                                   description="How refraction through glass is drawn")
    max_interfaces: bpy.props.IntProperty(name="Max Interfaces", default=8, min=0, max=1024,
                                          description="Glass faces a ray may cross before it ends as a miss")
    fresnel: bpy.props.BoolProperty(name="Fresnel", default=True,
                                    description="Glass reflects as well as refracts: highlights, catch lights")
    dispersion: bpy.props.BoolProperty(
        name="Dispersion", default=True,
        description="Dispersive glass splits the colours. Blender's glass shaders have no dispersion input: a "
                    "material disperses by the Dispersion input (20 / Abbe number) of its glTF Material Output node")
    volume: bpy.props.BoolProperty(name="Volume", default=True,
                                   description="Volume Absorption tints the light inside thick glass")
    display: bpy.props.EnumProperty(
        name="Display", default="AUTO",
        items=[("AUTO", "Interop if possible", "OpenGL imports snell's image (GL_EXT_memory_object_fd): no copy"),
               ("UPLOAD", "Upload", "Pixels come back to the host and go up as a texture (always works)")],
        description="How the viewport gets snell's image")
    overlay: bpy.props.BoolProperty(name="Overlay", default=True,
                                    description="A line in the viewport says how the image was drawn and what it cost")


class SnellObjectSettings(bpy.types.PropertyGroup):
    """How snell takes an object (Object Properties > snell)."""

    gpu_subdivision: bpy.props.BoolProperty(
        name="Subdivide on the GPU", default=True,
        description="When the last modifier is a Catmull-Clark Subdivision Surface, send its cage and let snell "
                    "refine it on the GPU each frame (off: Blender subdivides on the CPU, as it does for Cycles)")


# snell's AOVs as render passes: (property, pass name, channel ids, type, description). Depth and
# Normal take Blender's own names, so the compositor's nodes for them take snell's.
PASSES = (
    ("depth", "Depth", "Z", "VALUE", "Camera-space depth of the first surface (1e10 where there is none)"),
    ("normal", "Normal", "XYZ", "VECTOR", "World-space face normal of the first surface"),
    ("instance", "snell Instance", "X", "VALUE", "snell's draw item of the first surface (-1 where there is none)"),
    ("primitive", "snell Primitive", "X", "VALUE", "Triangle of the first surface within its mesh (-1: none)"),
    ("interfaces", "snell Interfaces", "X", "VALUE", "Glass faces the pixel's ray crossed"),
    ("cost", "snell Cost", "X", "VALUE", "Tree nodes the pixel's rays visited"),
)


def _pass_property(name: str, label: str, description: str):
    return bpy.props.BoolProperty(name=label, default=False, description=description)


class SnellViewLayerSettings(bpy.types.PropertyGroup):
    """Which of snell's AOVs a view layer writes as render passes (View Layer Properties > snell Passes)."""

    __annotations__ = {key: _pass_property(key, name, description) for key, name, _, _, description in PASSES}


def enabled_passes(view_layer) -> list:
    """The PASSES entries the view layer asks for."""
    options = getattr(view_layer, "snell", None)
    return [entry for entry in PASSES if options is not None and getattr(options, entry[0])]


class SnellPreferences(bpy.types.AddonPreferences):
    """Where the `snell` Python module is, when it is not installed for Blender's Python."""

    bl_idname = __package__

    module_path: bpy.props.StringProperty(
        name="snell module folder", subtype="DIR_PATH", default="",
        description="The folder holding the snell package (e.g. <checkout>/build/release/python); "
                    "empty: the Python module installed with `cmake --install`")
    device: bpy.props.StringProperty(
        name="Device", default="",
        description="A Vulkan device index or name substring; empty: SNELL_DEVICE, else the first that fits")
    every_gpu: bpy.props.BoolProperty(
        name="Animations on every GPU", default=False,
        description="Ctrl+F12 and Render > snell: Render Animation draw the frames on every GPU at once, one worker "
                    "each (off: on the device above, and Ctrl+F12 is Blender's own animation render)")

    def draw(self, context) -> None:
        from . import runtime

        self.layout.prop(self, "module_path")
        self.layout.prop(self, "device")
        self.layout.prop(self, "every_gpu")
        status = runtime.status()
        self.layout.label(text=status, icon="INFO" if runtime.problem() is None else "ERROR")


def settings(scene) -> SnellSceneSettings:
    return scene.snell


def register() -> None:
    bpy.utils.register_class(SnellSceneSettings)
    bpy.utils.register_class(SnellViewLayerSettings)
    bpy.utils.register_class(SnellObjectSettings)
    bpy.utils.register_class(SnellPreferences)
    bpy.types.Scene.snell = bpy.props.PointerProperty(type=SnellSceneSettings)
    bpy.types.ViewLayer.snell = bpy.props.PointerProperty(type=SnellViewLayerSettings)
    bpy.types.Object.snell = bpy.props.PointerProperty(type=SnellObjectSettings)


def unregister() -> None:
    del bpy.types.Object.snell
    del bpy.types.ViewLayer.snell
    del bpy.types.Scene.snell
    bpy.utils.unregister_class(SnellPreferences)
    bpy.utils.unregister_class(SnellObjectSettings)
    bpy.utils.unregister_class(SnellViewLayerSettings)
    bpy.utils.unregister_class(SnellSceneSettings)
