# SPDX-License-Identifier: GPL-3.0-or-later
"""snell for Blender: a render engine that ray traces glass and eyes, in the viewport and for F12.

snell renders refraction through deforming meshes with Vulkan compute. This
add-on feeds it Blender's evaluated meshes (armatures, shape keys,
modifiers) every frame and draws its image in the Rendered viewport, or
writes it as the render result. It needs the `snell` Python module (in the
extension's wheels, or built with the project: see its README's "In
Blender") and a Vulkan device; when either is missing, the panel and the
console say so and nothing crashes.
"""

bl_info = {
    "name": "snell",
    "author": "the snell authors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Render Properties > Render Engine > snell",
    "description": "Refraction through deforming meshes (eyes, glass), ray traced by Vulkan compute",
    "category": "Render",
}

from . import engine, properties, runtime, shot, ui  # noqa: E402  (bl_info first, as Blender reads it)


def register() -> None:
    properties.register()
    engine.register()
    ui.register()
    shot.register()


def unregister() -> None:
    shot.unregister()
    ui.unregister()
    engine.unregister()
    properties.unregister()
    runtime.release()
