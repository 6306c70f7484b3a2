"""snell: refraction through deforming meshes, ray traced by Vulkan compute.

A scene (a glTF file, or meshes from numpy arrays) is drawn by a Renderer on
a Device; each frame updates only what moved::

    import snell

    with snell.Device() as device:
        scene = snell.Scene.load("eye.glb")
        renderer = snell.Renderer(device, scene)
        renderer.set_time(0.5)
        rgba = renderer.render(snell.View(640, 480, camera=0))  # (480, 640, 4) float32

A shot's frames go to every GPU at once with snell.render_frames. Pixels
are scene-linear Rec.709 RGBA, row 0 at the top. Every failure is a
snell.Error whose message names the file, array or option at fault.
docs/python.md covers the module.
"""

from ._snell import (
    DEFAULT_YFOV,
    Camera,
    Device,
    Environment,
    Error,
    Instance,
    Light,
    Material,
    Mesh,
    Renderer,
    Scene,
    SharedImage,
    ShotFrame,
    Subdivision,
    Texture,
    TextureTransform,
    View,
    framing,
    methods,
    read_image_file,
    render_frames,
    version,
    write_png,
)

__version__ = version()

__all__ = [
    "DEFAULT_YFOV",
    "Camera",
    "Device",
    "Environment",
    "Error",
    "Instance",
    "Light",
    "Material",
    "Mesh",
    "Renderer",
    "Scene",
    "SharedImage",
    "ShotFrame",
    "Subdivision",
    "Texture",
    "TextureTransform",
    "View",
    "framing",
    "methods",
    "read_image_file",
    "render_frames",
    "version",
    "write_png",
]
