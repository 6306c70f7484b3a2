"""Helpers for the module's tests: scenes written as glTF, PNG files read back, sRGB."""

from __future__ import annotations

import base64
import json
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


class GltfWriter:
    """A minimal glTF 2.0 writer (one .gltf with its buffer inline) for test scenes."""

    def __init__(self) -> None:
        self.doc: dict = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": []}], "nodes": [],
                          "meshes": [], "accessors": [], "bufferViews": [], "materials": []}
        self.blob = bytearray()

    def _accessor(self, array: np.ndarray, kind: str, minmax: bool = False) -> int:
        component = {np.dtype(np.float32): 5126, np.dtype(np.uint32): 5125}[array.dtype]
        while len(self.blob) % 4:
            self.blob.append(0)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": array.nbytes}
        self.blob += np.ascontiguousarray(array).tobytes()
        self.doc["bufferViews"].append(view)
        accessor = {"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": component,
                    "count": int(array.shape[0]) if kind != "SCALAR" or array.ndim == 1 else int(array.size),
                    "type": kind}
        if minmax:
            accessor["min"] = array.min(axis=0).tolist()
            accessor["max"] = array.max(axis=0).tolist()
        self.doc["accessors"].append(accessor)
        return len(self.doc["accessors"]) - 1

    def texture(self, rgba: np.ndarray, wrap: str = "repeat", nearest: bool = False) -> int:
        """An embedded PNG texture with its sampler; returns the texture's index."""
        png = _png_bytes(rgba)
        self.doc.setdefault("images", []).append({"uri": "data:image/png;base64," + base64.b64encode(png).decode()})
        codes = {"repeat": 10497, "clamp": 33071, "mirror": 33648}
        sampler = {"wrapS": codes[wrap], "wrapT": codes[wrap]}
        if nearest:
            sampler["magFilter"] = sampler["minFilter"] = 9728
        self.doc.setdefault("samplers", []).append(sampler)
        self.doc.setdefault("textures", []).append({"source": len(self.doc["images"]) - 1,
                                                    "sampler": len(self.doc["samplers"]) - 1})
        return len(self.doc["textures"]) - 1

    def _uses(self, extension: str) -> None:
        used = self.doc.setdefault("extensionsUsed", [])
        if extension not in used:
            used.append(extension)

    def texture_info(self, index: int, transform: dict | None = None, **fields) -> dict:
        """A material's reference to texture `index`, with a KHR_texture_transform."""
        info = {"index": index, **fields}
        if transform:
            info["extensions"] = {"KHR_texture_transform": transform}
            self._uses("KHR_texture_transform")
        return info

    def material(self, base_color=(1, 1, 1, 1), transmission=0.0, ior=1.5, texture: np.ndarray | None = None,
                 base_info: dict | None = None, emissive=(0.0, 0.0, 0.0), emissive_info: dict | None = None,
                 normal_info: dict | None = None, alpha_mode: str | None = None,
                 alpha_cutoff: float | None = None) -> int:
        """A material; *_info are texture_info() references (texture: the base colour's, repeating)."""
        m: dict = {"pbrMetallicRoughness": {"baseColorFactor": list(base_color), "metallicFactor": 0.0}}
        if transmission > 0:
            m["extensions"] = {"KHR_materials_transmission": {"transmissionFactor": transmission},
                               "KHR_materials_ior": {"ior": ior}}
            self._uses("KHR_materials_transmission")
            self._uses("KHR_materials_ior")
        if texture is not None:
            base_info = {"index": self.texture(texture)}
        if base_info is not None:
            m["pbrMetallicRoughness"]["baseColorTexture"] = base_info
        if any(emissive):
            m["emissiveFactor"] = list(emissive)
        if emissive_info is not None:
            m["emissiveTexture"] = emissive_info
        if normal_info is not None:
            m["normalTexture"] = normal_info
        if alpha_mode is not None:
            m["alphaMode"] = alpha_mode
        if alpha_cutoff is not None:
            m["alphaCutoff"] = alpha_cutoff
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def mesh(self, positions, normals, indices, uvs=None, material=None, morph=None, weights=None) -> int:
        """A mesh of one primitive; morph: (position deltas, normal deltas) of one target."""
        attributes = {"POSITION": self._accessor(positions, "VEC3", True), "NORMAL": self._accessor(normals, "VEC3")}
        if uvs is not None:
            attributes["TEXCOORD_0"] = self._accessor(uvs, "VEC2")
        primitive: dict = {"attributes": attributes, "indices": self._accessor(indices.reshape(-1), "SCALAR")}
        if material is not None:
            primitive["material"] = material
        mesh: dict = {"primitives": [primitive]}
        if morph is not None:
            dp, dn = morph
            primitive["targets"] = [{"POSITION": self._accessor(dp, "VEC3", True),
                                     "NORMAL": self._accessor(dn, "VEC3")}]
            mesh["weights"] = list(weights or [0.0])
        self.doc["meshes"].append(mesh)
        return len(self.doc["meshes"]) - 1

    def node(self, **fields) -> int:
        self.doc["nodes"].append(fields)
        self.doc["scenes"][0]["nodes"].append(len(self.doc["nodes"]) - 1)
        return len(self.doc["nodes"]) - 1

    def camera(self, yfov: float, translation, aspect: float | None = None) -> int:
        perspective = {"yfov": yfov, "znear": 0.01}
        if aspect:
            perspective["aspectRatio"] = aspect
        self.doc.setdefault("cameras", []).append({"type": "perspective", "perspective": perspective})
        return self.node(camera=len(self.doc["cameras"]) - 1, translation=list(translation))

    def weights_animation(self, node: int, times, weights) -> None:
        """Linear keys of a one-target mesh's weight."""
        t = self._accessor(np.array(times, np.float32), "SCALAR", True)
        w = self._accessor(np.array(weights, np.float32), "SCALAR")
        self.doc["animations"] = [{"samplers": [{"input": t, "output": w, "interpolation": "LINEAR"}],
                                   "channels": [{"sampler": 0, "target": {"node": node, "path": "weights"}}]}]

    def write(self, path: Path) -> Path:
        self.doc["buffers"] = [{"byteLength": len(self.blob),
                                "uri": "data:application/octet-stream;base64," + base64.b64encode(self.blob).decode()}]
        Path(path).write_text(json.dumps(self.doc))
        return Path(path)


def _png_bytes(rgba: np.ndarray) -> bytes:
    """An RGBA8 PNG of the array (no filtering), for textures inside test glTF files."""
    height, width, _ = rgba.shape
    raw = b"".join(b"\x00" + rgba[y].tobytes() for y in range(height))

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
