"""Writes the trace benchmark's sphere: a glass UV sphere of about N triangles over a checkered floor.

    python3 bench/make_sphere.py 1000000 sphere-1m.gltf
    python3 bench/make_sphere.py 1000000 sphere-1m-wedges.gltf 10
    python3 bench/make_sphere.py --plain 1000000 sphere-1m-plain.gltf

The sphere (IOR 1.5, transmission 1) fills most of a 16:9 frame from its
camera, so nearly every pixel's ray crosses glass twice and lands on the
floor or the sky behind: what `snell bench methods --methods trace,driver-rt`
times the traversal on. Only numpy and the standard library are needed, so it
runs on the GPU machine too.

With WEDGES the same sphere is written as that many instances of one wedge
(a slice between two meridians, rotated into place): the same triangles and
the same picture from a bottom-level tree a WEDGES-th the size, with the top
level above it. Beside the single mesh it tells what the tree's footprint in
the caches costs the trace (issue 40, step 0).

With --plain the floor is grey, without its texture: the trace compiled
without texture sampling, whose registers are the walk's (issue 53, step 5).
"""

from __future__ import annotations

import base64
import json
import math
import sys
from pathlib import Path

import numpy as np


def sphere(triangles: int, wedges: int = 1):
    """A unit UV sphere with rings x 2 rings quads: about `triangles` triangles;
    with wedges > 1 only the first of that many equal slices around the y axis."""
    rings = max(4, int(math.sqrt(triangles / 4)))
    while (2 * rings) % wedges:
        rings += 1
    segments = 2 * rings // wedges
    theta = np.linspace(0.0, math.pi, rings + 1)
    phi = np.linspace(0.0, 2.0 * math.pi / wedges, segments + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    normals = np.stack([np.sin(t) * np.cos(p), np.cos(t), np.sin(t) * np.sin(p)], -1).reshape(-1, 3)
    a = (np.arange(rings)[:, None] * (segments + 1) + np.arange(segments)[None, :]).reshape(-1)
    b = a + segments + 1
    indices = np.concatenate([np.stack([a, b, a + 1], 1), np.stack([a + 1, b, b + 1], 1)]).astype(np.uint32)
    return normals.astype(np.float32), normals.astype(np.float32), indices


def main(argv: list[str]) -> None:
    plain = "--plain" in argv
    argv = [a for a in argv if a != "--plain"]
    if len(argv) not in (2, 3):
        raise SystemExit("usage: make_sphere.py [--plain] TRIANGLES OUT.gltf [WEDGES]")
    wedges = int(argv[2]) if len(argv) == 3 else 1
    positions, normals, indices = sphere(int(argv[0]), wedges)
    floor = np.float32([[-8, -1.2, -8], [8, -1.2, -8], [8, -1.2, 8], [-8, -1.2, 8]])
    floor_normals = np.float32([[0, 1, 0]] * 4)
    floor_uv = np.float32([[0, 0], [8, 0], [8, 8], [0, 8]])
    floor_indices = np.uint32([[0, 2, 1], [0, 3, 2]])
    size = 64
    y, x = np.mgrid[0:size, 0:size] // 8
    checker = np.where(((x + y) % 2 == 0)[..., None], [230, 190, 60, 255], [40, 70, 160, 255]).astype(np.uint8)

    blob = bytearray()
    views, accessors = [], []

    def add(array: np.ndarray, kind: str, bounds: bool = False) -> int:
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": array.nbytes})
        blob.extend(np.ascontiguousarray(array).tobytes())
        accessor = {"bufferView": len(views) - 1, "componentType": 5126 if array.dtype == np.float32 else 5125,
                    "count": int(array.shape[0]) if kind != "SCALAR" else int(array.size), "type": kind}
        if bounds:
            accessor["min"], accessor["max"] = array.min(0).tolist(), array.max(0).tolist()
        accessors.append(accessor)
        return len(accessors) - 1

    def png(rgba: np.ndarray) -> bytes:
        import struct
        import zlib

        h, w, _ = rgba.shape
        raw = b"".join(b"\x00" + rgba[r].tobytes() for r in range(h))

        def chunk(kind: bytes, body: bytes) -> bytes:
            return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

        return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0)) +
                chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))

    glass = {"POSITION": add(positions, "VEC3", True), "NORMAL": add(normals, "VEC3")}
    ground = {"POSITION": add(floor, "VEC3", True), "NORMAL": add(floor_normals, "VEC3"),
              "TEXCOORD_0": add(floor_uv, "VEC2")}
    document = {
        "asset": {"version": "2.0", "generator": "snell bench/make_sphere.py"},
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3] + list(range(4, 3 + wedges))}],
        "nodes": [{"mesh": 0}, {"mesh": 1}, {"camera": 0, "translation": [0.0, 0.3, 2.3], "rotation":
                                              [-0.0499792, 0.0, 0.0, 0.9987503]},
                  {"extensions": {"KHR_lights_punctual": {"light": 0}}, "translation": [2.0, 4.0, 3.0]}] +
                 # Wedge k covers longitudes [k, k + 1) * 2 pi / wedges: a turn about y by -that much.
                 [{"mesh": 0, "rotation": [0.0, -math.sin(math.pi * k / wedges), 0.0, math.cos(math.pi * k / wedges)]}
                  for k in range(1, wedges)],
        "meshes": [{"primitives": [{"attributes": glass, "indices": add(indices.reshape(-1), "SCALAR"),
                                    "material": 0}]},
                   {"primitives": [{"attributes": ground, "indices": add(floor_indices.reshape(-1), "SCALAR"),
                                    "material": 1}]}],
        "materials": [
            {"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [0.97, 0.99, 1.0, 1.0], "roughness": 0.05},
             "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                            "KHR_materials_ior": {"ior": 1.5}}},
            {"name": "floor", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0}},
        ],
        "textures": [{"source": 0}],
        "images": [{"uri": "data:image/png;base64," + base64.b64encode(png(checker)).decode()}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.75, "znear": 0.01, "aspectRatio": 16 / 9}}],
        "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 60.0}]}},
        "accessors": accessors,
        "bufferViews": views,
    }
    document["extensionsUsed"].append("KHR_lights_punctual")
    if plain:
        del document["textures"], document["images"]
        document["materials"][1]["pbrMetallicRoughness"] = {"baseColorFactor": [0.6, 0.6, 0.6, 1.0], "metallicFactor": 0.0}
    out = Path(argv[1])
    (out.with_suffix(".bin")).write_bytes(bytes(blob))
    document["buffers"] = [{"byteLength": len(blob), "uri": out.with_suffix(".bin").name}]
    out.write_text(json.dumps(document))
    what = f"{wedges} wedges of {len(indices)} triangles" if wedges > 1 else f"{len(indices)} triangles"
    print(f"{out}: a glass sphere of {what} over a {'grey' if plain else 'checkered'} floor")


if __name__ == "__main__":
    main(sys.argv[1:])
