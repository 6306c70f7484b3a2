"""A small glTF 2.0 writer for the test scenes of tests/python and tests/usd.

One .gltf (JSON) and one binary buffer (.bin) beside it: meshes of several
primitives with skins, morph targets (positions, and normals where given) and
two UV sets, node animations, metallic-roughness materials with
KHR_materials_transmission and KHR_materials_ior, base colour, emissive and
normal textures by URI or embedded from an array (each with its sampler's
wraps and filter, its UV set and a KHR_texture_transform), alphaMode and
alphaCutoff, a perspective camera and KHR_lights_punctual lights.
"""

from __future__ import annotations

import base64
import json
import struct
import zlib
from pathlib import Path

import numpy as np

_WRAPS = {"repeat": 10497, "clamp": 33071, "mirror": 33648}
_COMPONENT = {np.dtype(np.float32): 5126, np.dtype(np.uint32): 5125, np.dtype(np.uint16): 5123}
_TYPE = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4", 16: "MAT4"}


class GltfWriter:
    """Builds a glTF document; write() saves it with its buffer."""

    def __init__(self) -> None:
        self.doc: dict = {"asset": {"version": "2.0", "generator": "snell tests"}, "scene": 0,
                          "scenes": [{"nodes": []}], "nodes": [], "meshes": [], "accessors": [],
                          "bufferViews": [], "materials": []}
        self.blob = bytearray()

    def _extension(self, name: str) -> None:
        used = self.doc.setdefault("extensionsUsed", [])
        if name not in used:
            used.append(name)

    def accessor(self, array: np.ndarray, minmax: bool = False, target: int | None = None) -> int:
        """Appends an array to the buffer: rows are elements ((n,) scalars, (n, k) vectors, (n, 4, 4) matrices)."""
        array = np.ascontiguousarray(array)
        width = 1 if array.ndim == 1 else int(np.prod(array.shape[1:]))
        while len(self.blob) % 4:
            self.blob.append(0)
        view = {"buffer": 0, "byteOffset": len(self.blob), "byteLength": array.nbytes}
        if target is not None:
            view["target"] = target
        self.blob += array.tobytes()
        self.doc["bufferViews"].append(view)
        accessor = {"bufferView": len(self.doc["bufferViews"]) - 1, "componentType": _COMPONENT[array.dtype],
                    "count": int(array.shape[0]), "type": _TYPE[width]}
        if minmax:
            flat = array.reshape(len(array), width)
            accessor["min"] = flat.min(axis=0).tolist()
            accessor["max"] = flat.max(axis=0).tolist()
        self.doc["accessors"].append(accessor)
        return len(self.doc["accessors"]) - 1

    def texture(self, image: str | np.ndarray, wrap_s: str = "repeat", wrap_t: str | None = None,
                nearest: bool = False) -> int:
        """An image, by URI or an RGBA8 array embedded as PNG, with a sampler of these wraps (repeat, clamp,
        mirror; wrap_t: wrap_s's unless given), trilinear or nearest; the texture's index."""
        if not isinstance(image, str):
            image = "data:image/png;base64," + base64.b64encode(_png_bytes(image)).decode()
        self.doc.setdefault("images", []).append({"uri": image})
        sampler = {"magFilter": 9728 if nearest else 9729, "minFilter": 9728 if nearest else 9987,
                   "wrapS": _WRAPS[wrap_s], "wrapT": _WRAPS[wrap_t or wrap_s]}
        samplers = self.doc.setdefault("samplers", [])
        if sampler not in samplers:
            samplers.append(sampler)
        self.doc.setdefault("textures", []).append({"source": len(self.doc["images"]) - 1,
                                                    "sampler": samplers.index(sampler)})
        return len(self.doc["textures"]) - 1

    def texture_info(self, index: int, tex_coord: int = 0, transform: dict | None = None, **fields) -> dict:
        """A material's reference to texture `index`: its UV set, a KHR_texture_transform (offset, rotation,
        scale), and fields such as a normal map's scale."""
        info: dict = {"index": index, **fields}
        if tex_coord:
            info["texCoord"] = tex_coord
        if transform:
            info["extensions"] = {"KHR_texture_transform": transform}
            self._extension("KHR_texture_transform")
        return info

    def material(self, base_color=(1, 1, 1, 1), roughness: float = 1.0, transmission: float = 0.0, ior: float = 1.5,
                 texture: str | np.ndarray | None = None, emissive=(0, 0, 0), base_info: dict | None = None,
                 emissive_info: dict | None = None, normal_info: dict | None = None, alpha_mode: str | None = None,
                 alpha_cutoff: float | None = None) -> int:
        """A material; *_info are texture_info() references (texture: a repeating base colour texture)."""
        pbr: dict = {"baseColorFactor": list(base_color), "metallicFactor": 0.0, "roughnessFactor": roughness}
        m: dict = {"pbrMetallicRoughness": pbr}
        if any(emissive):
            m["emissiveFactor"] = list(emissive)
        if transmission > 0:
            m["extensions"] = {"KHR_materials_transmission": {"transmissionFactor": transmission},
                               "KHR_materials_ior": {"ior": ior}}
            self._extension("KHR_materials_transmission")
            self._extension("KHR_materials_ior")
        if texture is not None:
            base_info = {"index": self.texture(texture)}
        for key, info in (("emissiveTexture", emissive_info), ("normalTexture", normal_info)):
            if info is not None:
                m[key] = info
        if base_info is not None:
            pbr["baseColorTexture"] = base_info
        if alpha_mode is not None:
            m["alphaMode"] = alpha_mode
        if alpha_cutoff is not None:
            m["alphaCutoff"] = alpha_cutoff
        self.doc["materials"].append(m)
        return len(self.doc["materials"]) - 1

    def mesh(self, primitives: list[dict], weights: list[float] | None = None, name: str = "") -> int:
        """primitives: dicts of positions, normals, indices ((T, 3) uint32), and optional uvs, uvs1, material,
        joints ((n, 4) uint16), weights ((n, 4) float32) and targets (one per target: its position deltas, or
        its position and normal deltas as a pair)."""
        out = []
        for p in primitives:
            attributes = {"POSITION": self.accessor(np.float32(p["positions"]), minmax=True, target=34962),
                          "NORMAL": self.accessor(np.float32(p["normals"]), target=34962)}
            if p.get("uvs") is not None:
                attributes["TEXCOORD_0"] = self.accessor(np.float32(p["uvs"]), target=34962)
            if p.get("uvs1") is not None:
                attributes["TEXCOORD_1"] = self.accessor(np.float32(p["uvs1"]), target=34962)
            if p.get("joints") is not None:
                attributes["JOINTS_0"] = self.accessor(np.uint16(p["joints"]), target=34962)
                attributes["WEIGHTS_0"] = self.accessor(np.float32(p["weights"]), target=34962)
            primitive: dict = {"attributes": attributes,
                               "indices": self.accessor(np.uint32(p["indices"]).reshape(-1), target=34963)}
            if p.get("material") is not None:
                primitive["material"] = p["material"]
            if p.get("targets"):
                primitive["targets"] = [self._target(t) for t in p["targets"]]
            out.append(primitive)
        mesh: dict = {"primitives": out}
        if name:
            mesh["name"] = name
        if weights is not None:
            mesh["weights"] = list(weights)
        self.doc["meshes"].append(mesh)
        return len(self.doc["meshes"]) - 1

    def _target(self, deltas) -> dict:
        if isinstance(deltas, tuple):
            positions, normals = deltas
            return {"POSITION": self.accessor(np.float32(positions), minmax=True),
                    "NORMAL": self.accessor(np.float32(normals))}
        return {"POSITION": self.accessor(np.float32(deltas), minmax=True)}

    def node(self, parent: int | None = None, matrix: np.ndarray | None = None, **fields) -> int:
        """A node under `parent` (None: a root of the scene); matrix: 4x4 with column vectors."""
        if matrix is not None:
            fields["matrix"] = np.asarray(matrix, float).T.reshape(-1).tolist()  # glTF stores columns
        self.doc["nodes"].append({k: v for k, v in fields.items() if v is not None})
        index = len(self.doc["nodes"]) - 1
        if parent is None:
            self.doc["scenes"][0]["nodes"].append(index)
        else:
            self.doc["nodes"][parent].setdefault("children", []).append(index)
        return index

    def skin(self, joints: list[int], inverse_binds: list[np.ndarray], skeleton: int | None = None) -> int:
        matrices = np.stack([np.asarray(m, np.float32).T for m in inverse_binds])  # column-major, as glTF stores
        skin = {"joints": list(joints), "inverseBindMatrices": self.accessor(matrices.reshape(len(joints), 16))}
        if skeleton is not None:
            skin["skeleton"] = skeleton
        self.doc.setdefault("skins", []).append(skin)
        return len(self.doc["skins"]) - 1

    def animate(self, node: int, path: str, times, values, interpolation: str = "LINEAR") -> None:
        """A channel of the scene's one animation: path is translation, rotation (x, y, z, w), scale or weights."""
        animation = self.doc.setdefault("animations", [{"samplers": [], "channels": []}])[0]
        t = self.accessor(np.float32(times), minmax=True)
        v = self.accessor(np.float32(values).reshape(len(times), -1) if path != "weights"
                          else np.float32(values).reshape(-1))
        animation["samplers"].append({"input": t, "output": v, "interpolation": interpolation})
        sampler = len(animation["samplers"]) - 1
        animation["channels"].append({"sampler": sampler, "target": {"node": node, "path": path}})

    def camera(self, yfov: float, aspect: float | None, position, name: str = "", znear: float = 0.1) -> int:
        """A perspective camera at `position` looking down -Z (aspect None: the image's)."""
        perspective = {"yfov": yfov, "znear": znear}
        if aspect:
            perspective["aspectRatio"] = aspect
        self.doc.setdefault("cameras", []).append({"type": "perspective", "perspective": perspective})
        return self.node(name=name or None, camera=len(self.doc["cameras"]) - 1,
                         translation=[float(c) for c in position])

    def light(self, kind: str, color, intensity: float, translation=None, matrix=None, spot: dict | None = None,
              name: str = "") -> int:
        self._extension("KHR_lights_punctual")
        lights = self.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})["lights"]
        light = {"type": kind, "color": [float(c) for c in color], "intensity": float(intensity)}
        if spot:
            light["spot"] = spot
        lights.append(light)
        return self.node(name=name or None, matrix=matrix,
                         translation=None if translation is None else [float(c) for c in translation],
                         extensions={"KHR_lights_punctual": {"light": len(lights) - 1}})

    def write(self, path: Path) -> Path:
        """Writes path (.gltf) and path with .bin beside it."""
        path = Path(path)
        binary = path.with_suffix(".bin")
        binary.write_bytes(bytes(self.blob))
        self.doc["buffers"] = [{"byteLength": len(self.blob), "uri": binary.name}]
        path.write_text(json.dumps(self.doc, indent=1))
        return path


def _png_bytes(rgba: np.ndarray) -> bytes:
    """An RGBA8 PNG of the array (no filtering), for textures inside test glTF files."""
    height, width, _ = rgba.shape
    raw = b"".join(b"\x00" + rgba[y].tobytes() for y in range(height))

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")
