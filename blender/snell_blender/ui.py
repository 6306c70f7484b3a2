# SPDX-License-Identifier: GPL-3.0-or-later
"""The Render Properties panel: how glass is drawn, and whether snell is ready."""

from __future__ import annotations

import bpy

from . import runtime
from .properties import PASSES
from .runtime import AREA_LIGHT_NOTE

MAX_PROBLEM_LINES = 8
# Blender's Glass, Refraction and Principled BSDFs have no dispersion input (3.4 to 5.2), so the switch reads
# the glTF add-on's group instead, which Blender 5.2's exporter writes as KHR_materials_dispersion.
DISPERSION_NOTE = "Blender's glass has no dispersion: read from glTF Material Output's Dispersion"


class SnellPropertiesPanel:
    """What snell's panels in the Properties editor share: they show while snell is the render engine."""

    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    COMPAT_ENGINES = {"SNELL"}

    @classmethod
    def poll(cls, context) -> bool:
        return context.engine in cls.COMPAT_ENGINES


class SNELL_PT_render(SnellPropertiesPanel, bpy.types.Panel):
    """Render Properties > snell."""

    bl_label = "snell"
    bl_context = "render"

    def draw(self, context) -> None:
        layout = self.layout
        layout.use_property_split = True
        options = context.scene.snell
        problem = runtime.problem()
        layout.label(text=runtime.status(), icon="ERROR" if problem else "INFO")
        layout.prop(options, "method")
        layout.prop(options, "max_interfaces")
        column = layout.column(heading="Optics")
        column.prop(options, "fresnel")
        column.prop(options, "dispersion")
        if options.dispersion:
            column.label(text=DISPERSION_NOTE, icon="INFO")
        column.prop(options, "volume")
        layout.prop(options, "display")
        layout.prop(options, "overlay")
        if any(o.type == "LIGHT" and o.data.type == "AREA" for o in context.scene.objects):
            layout.label(text=AREA_LIGHT_NOTE.capitalize(), icon="LIGHT_AREA")
        problems = runtime.scene_problems()
        if problems:
            box = layout.box()
            box.label(text="Not drawn as in Cycles (the console has each in full):", icon="ERROR")
            for line in problems[:MAX_PROBLEM_LINES]:
                box.label(text=line)
            if len(problems) > MAX_PROBLEM_LINES:
                box.label(text=f"... and {len(problems) - MAX_PROBLEM_LINES} more")
        if problem:
            layout.operator("snell.retry", icon="FILE_REFRESH")


class SNELL_PT_passes(SnellPropertiesPanel, bpy.types.Panel):
    """View Layer Properties > snell Passes: the AOVs this view layer writes as render passes."""

    bl_label = "snell Passes"
    bl_context = "view_layer"

    def draw(self, context) -> None:
        layout = self.layout
        layout.use_property_split = True
        column = layout.column(heading="Passes")
        for key, *_ in PASSES:
            column.prop(context.view_layer.snell, key)
        layout.label(text="From the trace: methods trace, trace-1 and auto", icon="INFO")


class SNELL_PT_object(SnellPropertiesPanel, bpy.types.Panel):
    """Object Properties > snell: whether snell refines the object's subdivision surface."""

    bl_label = "snell"
    bl_context = "object"

    @classmethod
    def poll(cls, context) -> bool:
        return super().poll(context) and context.object is not None and context.object.type == "MESH"

    def draw(self, context) -> None:
        layout = self.layout
        layout.use_property_split = True
        obj = context.object
        layout.prop(obj.snell, "gpu_subdivision")
        last = obj.modifiers[-1] if obj.modifiers else None
        if last is None or last.type != "SUBSURF":
            layout.label(text="Applies when the last modifier is a Subdivision Surface", icon="INFO")
        elif obj.snell.gpu_subdivision:
            layout.label(text=f"snell refines {last.name} on the GPU (render levels {last.render_levels})",
                         icon="MOD_SUBSURF")


class SNELL_OT_retry(bpy.types.Operator):
    """Look for the snell module and a Vulkan device again"""

    bl_idname = "snell.retry"
    bl_label = "Try Again"

    def execute(self, context):
        runtime.retry()
        if runtime.device() is None:
            self.report({"ERROR"}, f"snell: {runtime.problem()}")
            return {"CANCELLED"}
        self.report({"INFO"}, runtime.status())
        return {"FINISHED"}


classes = (SNELL_PT_render, SNELL_PT_passes, SNELL_PT_object, SNELL_OT_retry)


def register() -> None:
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister() -> None:
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
