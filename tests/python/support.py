"""Helpers for the module's tests: meshes and textures of test scenes (tests/gltf_writer.py writes them as glTF),
PNG files read back, sRGB."""

from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np


def srgb8(linear: np.ndarray) -> np.ndarray:
    """Linear RGB(A) floats to 8-bit sRGB as snell's PNG writer encodes them (alpha linear)."""
    c = np.clip(linear[..., :3].astype(np.float64), 0.0, 1.0)
    s = np.where(c <= 0.0031308, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)
    return np.rint(s * 255.0).astype(np.uint8)


def read_png(path: Path) -> np.ndarray:
    """An 8-bit RGB or RGBA PNG (not interlaced) as a (height, width, channels) uint8 array."""
    data = Path(path).read_bytes()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG file")
    at, idat, header = 8, b"", None
    while at < len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        at += 12 + length
    width, height, depth, colour, _, _, interlace = header
    channels = {2: 3, 6: 4}.get(colour)
    if depth != 8 or channels is None or interlace:
        raise ValueError(f"{path}: only 8-bit RGB(A) PNGs without interlacing are read here")
    raw = np.frombuffer(zlib.decompress(idat), np.uint8)
    stride = width * channels
    rows = raw.reshape(height, stride + 1)
    out = np.zeros((height, stride), np.int32)
    for y in range(height):
        kind, line = rows[y, 0], rows[y, 1:].astype(np.int32)
        up = out[y - 1] if y else np.zeros(stride, np.int32)
        if kind == 0:
            out[y] = line
        elif kind == 1:  # sub: a running sum per channel
            row = line.reshape(width, channels)
            out[y] = (np.cumsum(row, axis=0) % 256).reshape(-1)
        elif kind == 2:
            out[y] = (line + up) % 256
        elif kind in (3, 4):  # average and Paeth look left: one pixel at a time
            row = np.zeros(stride, np.int32)
            for x in range(stride):
                left = row[x - channels] if x >= channels else 0
                if kind == 3:
                    predicted = (left + up[x]) // 2
                else:
                    corner = up[x - channels] if x >= channels else 0
                    p = left + up[x] - corner
                    pa, pb, pc = abs(p - left), abs(p - up[x]), abs(p - corner)
                    predicted = left if pa <= pb and pa <= pc else up[x] if pb <= pc else corner
                row[x] = (line[x] + predicted) % 256
            out[y] = row
        else:
            raise ValueError(f"{path}: unknown PNG filter {kind}")
    return out.astype(np.uint8).reshape(height, width, channels)


def uv_sphere(radius: float, rings: int, segments: int, centre=(0.0, 0.0, 0.0)):
    """A UV sphere: (positions, normals, indices, uvs) as float32/uint32 arrays, outward normals."""
    positions, normals, uvs = [], [], []
    for r in range(rings + 1):
        theta = np.pi * r / rings
        for s in range(segments + 1):
            phi = 2.0 * np.pi * s / segments
            n = (np.sin(theta) * np.cos(phi), np.cos(theta), np.sin(theta) * np.sin(phi))
            normals.append(n)
            positions.append([centre[i] + radius * n[i] for i in range(3)])
            uvs.append((s / segments, r / rings))
    indices = []
    for r in range(rings):
        for s in range(segments):
            a, b = r * (segments + 1) + s, (r + 1) * (segments + 1) + s
            indices += [(a, a + 1, b), (a + 1, b + 1, b)]
    return (
        np.array(positions, np.float32),
        np.array(normals, np.float32),
        np.array(indices, np.uint32),
        np.array(uvs, np.float32),
    )


def quad(size: float, z: float):
    """A square facing +Z at depth z: (positions, normals, indices, uvs)."""
    h = size / 2
    positions = np.array([(-h, -h, z), (h, -h, z), (h, h, z), (-h, h, z)], np.float32)
    normals = np.tile(np.array([0, 0, 1], np.float32), (4, 1))
    indices = np.array([(0, 1, 2), (0, 2, 3)], np.uint32)
    uvs = np.array([(0, 1), (1, 1), (1, 0), (0, 0)], np.float32)
    return positions, normals, indices, uvs


def ripples(size: int = 64, slope: float = 0.6) -> np.ndarray:
    """A tangent-space normal map of ripples across u (and a gentler swell along v), (size, size, 4) uint8."""
    y, x = (np.mgrid[0:size, 0:size] + 0.5) / size
    n = np.stack([-slope * np.cos(6 * np.pi * x), 0.4 * slope * np.sin(4 * np.pi * y), np.ones_like(x)], -1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    rgb = np.rint((n * 0.5 + 0.5) * 255).astype(np.uint8)
    return np.concatenate([rgb, np.full((size, size, 1), 255, np.uint8)], -1)


def holes(size: int = 4) -> np.ndarray:
    """A light grey texture whose alpha is 0 on every other square: (size, size, 4) uint8."""
    y, x = np.mgrid[0:size, 0:size]
    rgba = np.full((size, size, 4), 200, np.uint8)
    rgba[..., 3] = np.where((x + y) % 2 == 0, 0, 255)
    return rgba


def checker(size: int = 64, squares: int = 8) -> np.ndarray:
    """An RGBA checkerboard texture, (size, size, 4) uint8, so refraction shows."""
    y, x = np.mgrid[0:size, 0:size] * squares // size
    on = ((x + y) % 2).astype(bool)
    rgba = np.zeros((size, size, 4), np.uint8)
    rgba[on] = (230, 190, 60, 255)
    rgba[~on] = (40, 70, 160, 255)
    return rgba


def primitive(positions, normals, indices, uvs=None, **fields) -> dict:
    """A mesh primitive for gltf_writer.GltfWriter.mesh from the arrays uv_sphere and quad return."""
    return {"positions": positions, "normals": normals, "indices": indices, "uvs": uvs, **fields}
