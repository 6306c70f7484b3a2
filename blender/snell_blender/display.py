# SPDX-License-Identifier: GPL-3.0-or-later
"""Getting snell's image onto the viewport: OpenGL interop, or an upload.

Both paths end in one texture, drawn over the region through Blender's
colour management (the engine binds its display-space shader around it).
snell's row 0 is the top of the picture and so is the texture's first row,
so the quad's texture coordinates run top-down.
"""

from __future__ import annotations

from typing import Optional

import blf
import gpu
from gpu_extras.batch import batch_for_shader

from . import compat, gl_interop

PATH_INTEROP = "interop (GL_EXT_memory_object_fd, no copy)"
PATH_UPLOAD = "upload (pixels through the host)"


class Display:
    """Renders views into a texture the viewport can draw, by the best path this driver allows."""

    def __init__(self, device) -> None:
        self.device = device
        self.shared: Optional[gl_interop.SharedTexture] = None
        self.texture = None  # the upload path's GPUTexture
        self.path = PATH_UPLOAD

    def render(self, renderer, view, allow_interop: bool = True) -> None:
        """Renders `view` into this display's texture (waits for the GPU)."""
        gl = gl_interop.interop() if allow_interop else None
        if gl is not None:
            try:
                if self.shared is None or (self.shared.width, self.shared.height) != (view.width, view.height):
                    if self.shared is not None:
                        self.shared.close()
                    self.shared = None
                    self.shared = gl_interop.SharedTexture(gl, self.device, view.width, view.height)
                renderer.render_to(view, self.shared.image)
                self.path = PATH_INTEROP
                return
            except Exception as error:  # snell.Error or an OpenGL failure: upload from now on
                gl_interop.disable(str(error))
                print(f"snell: OpenGL interop is off ({error}); uploading pixels instead")
                if self.shared is not None:
                    self.shared.close()
                    self.shared = None
        rgba = renderer.render(view)
        height, width, _ = rgba.shape
        buffer = gpu.types.Buffer("FLOAT", width * height * 4, rgba.reshape(-1))
        self.texture = gpu.types.GPUTexture((width, height), format="RGBA16F", data=buffer)
        self.path = PATH_UPLOAD

    def draw(self, width: int, height: int) -> None:
        """Draws the texture over the region (between the engine's display-space shader binds)."""
        shader = gpu.shader.from_builtin("IMAGE")
        corners = ((0, 0), (width, 0), (width, height), (0, height))
        flipped = ((0, 1), (1, 1), (1, 0), (0, 0))
        batch = batch_for_shader(shader, "TRI_FAN", {"pos": corners, "texCoord": flipped})
        if self.path == PATH_INTEROP and self.shared is not None:
            # A raw OpenGL texture is bound through the interop's own entry
            # points: bgl, which Blender's draw_texture_2d used, is gone in 5.0.
            gl = self.shared.gl
            gl.active_texture(gl_interop.GL_TEXTURE0)
            gl.bind_texture(gl_interop.GL_TEXTURE_2D, self.shared.texture.value)
            shader.uniform_int("image", 0)
        elif self.texture is not None:
            shader.uniform_sampler("image", self.texture)
        else:
            return
        batch.draw(shader)

    def close(self) -> None:
        if self.shared is not None:
            self.shared.close()
            self.shared = None
        self.texture = None


def begin_colour_managed():
    """Blending for a premultiplied image; returns what to restore."""
    gpu.state.blend_set("ALPHA_PREMULT")
    return None


def end_colour_managed(_previous) -> None:
    gpu.state.blend_set("NONE")


def draw_text(text: str, error: bool = False) -> None:
    """One line at the viewport's bottom left (the overlay, or why nothing is drawn)."""
    font = 0
    compat.blf_size(font, 12)
    blf.color(font, *((1.0, 0.45, 0.4, 1.0) if error else (0.9, 0.9, 0.9, 0.9)))
    blf.position(font, 12, 12, 0)
    blf.enable(font, blf.SHADOW)
    blf.shadow(font, 3, 0.0, 0.0, 0.0, 0.8)
    blf.draw(font, text)
    blf.disable(font, blf.SHADOW)
