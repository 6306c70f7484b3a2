# SPDX-License-Identifier: GPL-3.0-or-later
"""snell's image in Blender's OpenGL without a copy: GL_EXT_memory_object_fd.

snell renders into a Vulkan image whose memory it exports as a file
descriptor; OpenGL imports that memory as a texture (the Vulkan counterpart
of the talk's CUDA-OpenGL interop). Blender's Python has no binding for the
extension, so its entry points are looked up in the current GLX context with
ctypes. Where the driver lacks them, or anything here fails, the caller
falls back to uploading pixels.
"""

from __future__ import annotations

import ctypes
import ctypes.util
from typing import Optional

GL_TEXTURE_2D = 0x0DE1
GL_TEXTURE0 = 0x84C0
GL_RGBA16F = 0x881A
GL_TEXTURE_MIN_FILTER = 0x2801
GL_TEXTURE_MAG_FILTER = 0x2800
GL_NEAREST = 0x2600
GL_EXTENSIONS = 0x1F03
GL_NUM_EXTENSIONS = 0x821D
GL_HANDLE_TYPE_OPAQUE_FD_EXT = 0x9586
GL_DEDICATED_MEMORY_OBJECT_EXT = 0x9581
GL_TEXTURE_BINDING_2D = 0x8069


class InteropUnavailable(Exception):
    """This OpenGL cannot import snell's memory; the message says why."""


class GlInterop:
    """The extension's entry points in the current OpenGL context."""

    def __init__(self) -> None:
        name = ctypes.util.find_library("GL") or "libGL.so.1"
        try:
            gl = ctypes.CDLL(name)
        except OSError as error:
            raise InteropUnavailable(f"no libGL ({error})") from None
        if not gl.glXGetCurrentContext():
            raise InteropUnavailable("Blender's OpenGL context is not a GLX one")
        lookup = gl.glXGetProcAddressARB
        lookup.restype = ctypes.c_void_p
        lookup.argtypes = [ctypes.c_char_p]

        def entry(symbol: str, result, *arguments):
            address = lookup(symbol.encode())
            if not address:
                raise InteropUnavailable(f"the driver has no {symbol}")
            return ctypes.CFUNCTYPE(result, *arguments)(address)

        get_integer = entry("glGetIntegerv", None, ctypes.c_uint, ctypes.POINTER(ctypes.c_int))
        get_stringi = entry("glGetStringi", ctypes.c_char_p, ctypes.c_uint, ctypes.c_uint)
        count = ctypes.c_int(0)
        get_integer(GL_NUM_EXTENSIONS, ctypes.byref(count))
        extensions = {get_stringi(GL_EXTENSIONS, i).decode() for i in range(count.value)}
        for needed in ("GL_EXT_memory_object", "GL_EXT_memory_object_fd"):
            if needed not in extensions:
                raise InteropUnavailable(f"the OpenGL driver lacks {needed}")
        self.get_integer = get_integer
        uint_p = ctypes.POINTER(ctypes.c_uint)
        self.create_memory_objects = entry("glCreateMemoryObjectsEXT", None, ctypes.c_int, uint_p)
        self.delete_memory_objects = entry("glDeleteMemoryObjectsEXT", None, ctypes.c_int, uint_p)
        self.memory_object_parameter = entry("glMemoryObjectParameterivEXT", None, ctypes.c_uint, ctypes.c_uint,
                                             ctypes.POINTER(ctypes.c_int))
        self.import_memory_fd = entry("glImportMemoryFdEXT", None, ctypes.c_uint, ctypes.c_uint64, ctypes.c_uint,
                                      ctypes.c_int)
        self.tex_storage_mem_2d = entry("glTexStorageMem2DEXT", None, ctypes.c_uint, ctypes.c_int, ctypes.c_uint,
                                        ctypes.c_int, ctypes.c_int, ctypes.c_uint, ctypes.c_uint64)
        self.gen_textures = entry("glGenTextures", None, ctypes.c_int, uint_p)
        self.delete_textures = entry("glDeleteTextures", None, ctypes.c_int, uint_p)
        self.bind_texture = entry("glBindTexture", None, ctypes.c_uint, ctypes.c_uint)
        self.active_texture = entry("glActiveTexture", None, ctypes.c_uint)
        self.tex_parameteri = entry("glTexParameteri", None, ctypes.c_uint, ctypes.c_uint, ctypes.c_int)
        self.get_error = entry("glGetError", ctypes.c_uint)


class SharedTexture:
    """A snell.SharedImage of one size, imported as an OpenGL texture."""

    def __init__(self, gl: GlInterop, device, width: int, height: int) -> None:
        import snell

        self.gl, self.width, self.height = gl, width, height
        self.image = snell.SharedImage(device, width, height)
        self.memory = ctypes.c_uint(0)
        self.texture = ctypes.c_uint(0)
        gl.get_error()  # clear what came before
        gl.create_memory_objects(1, ctypes.byref(self.memory))
        if self.image.dedicated:
            on = ctypes.c_int(1)
            gl.memory_object_parameter(self.memory.value, GL_DEDICATED_MEMORY_OBJECT_EXT, ctypes.byref(on))
        # OpenGL owns the descriptor from here on.
        gl.import_memory_fd(self.memory.value, self.image.memory_size, GL_HANDLE_TYPE_OPAQUE_FD_EXT,
                            self.image.export_memory())
        previous = ctypes.c_int(0)
        gl.get_integer(GL_TEXTURE_BINDING_2D, ctypes.byref(previous))
        gl.gen_textures(1, ctypes.byref(self.texture))
        gl.bind_texture(GL_TEXTURE_2D, self.texture.value)
        gl.tex_storage_mem_2d(GL_TEXTURE_2D, 1, GL_RGBA16F, width, height, self.memory.value, 0)
        gl.tex_parameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST)
        gl.tex_parameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST)
        gl.bind_texture(GL_TEXTURE_2D, previous.value)
        error = gl.get_error()
        if error:
            self.close()
            raise InteropUnavailable(f"importing snell's image into OpenGL failed (GL error 0x{error:04x})")

    def close(self) -> None:
        if self.texture.value:
            self.gl.delete_textures(1, ctypes.byref(self.texture))
            self.texture = ctypes.c_uint(0)
        if self.memory.value:
            self.gl.delete_memory_objects(1, ctypes.byref(self.memory))
            self.memory = ctypes.c_uint(0)
        self.image.close()


_interop: Optional[GlInterop] = None
_unavailable: Optional[str] = None


def interop() -> Optional[GlInterop]:
    """The current context's entry points, or None (why_not() says why); looked up once."""
    global _interop, _unavailable
    if _interop is None and _unavailable is None:
        try:
            _interop = GlInterop()
        except (InteropUnavailable, AttributeError, OSError) as error:
            _unavailable = str(error)
    return _interop


def why_not() -> Optional[str]:
    return _unavailable


def disable(reason: str) -> None:
    """Stops using interop for this session (after a failure), keeping the reason."""
    global _interop, _unavailable
    _interop, _unavailable = None, reason
