"""Writing binary glTF 2.0 (``.glb``) files of triangle meshes with
metallic-roughness materials: what pbrkit generates itself (the demo's
procedural model) in the format every viewer loads.

The layout is the glTF 2.0 specification's (Khronos, 2021): sec. 4.4 (the
binary container: a 12-byte header, a JSON chunk padded with spaces and a BIN
chunk padded with zeros, each to 4 bytes), sec. 3.6 (one buffer; a bufferView
and an accessor per attribute, float32 VEC3 POSITION with its min / max, VEC3
NORMAL, VEC2 TEXCOORD_0, uint32 indices) and sec. 3.9 (materials'
``pbrMetallicRoughness`` factors).  JSON keys are sorted and numbers written
by Python's shortest round-trip repr, so the same meshes give the same bytes.
"""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass

import numpy as np

from ..core.atomic import write_bytes

__all__ = ["GltfPrimitive", "glb_bytes", "write_glb"]

_FLOAT, _UINT = 5126, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_GLB_MAGIC, _CHUNK_JSON, _CHUNK_BIN = b"glTF", 0x4E4F534A, 0x004E4942


@dataclass(frozen=True)
class GltfPrimitive:
    """One mesh primitive: ``positions`` (V, 3), ``normals`` (V, 3) unit,
    optional ``texcoords`` (V, 2), ``indices`` (T, 3) counter-clockwise
    triangles, and its material's ``base_color`` (linear RGB or RGBA),
    ``metallic``, ``roughness`` and ``name``."""

    positions: np.ndarray
    normals: np.ndarray
    indices: np.ndarray
    texcoords: np.ndarray | None = None
    base_color: tuple = (1.0, 1.0, 1.0)
    metallic: float = 0.0
    roughness: float = 0.5
    name: str = "material"


def _check(prim, k):
    p = np.asarray(prim.positions, dtype=np.float64)
    n = np.asarray(prim.normals, dtype=np.float64)
    i = np.asarray(prim.indices)
    if p.ndim != 2 or p.shape[1] != 3 or p.shape[0] < 3:
        raise ValueError(f"primitive {k}: positions must have shape (V >= 3, 3); got {p.shape}")
    if n.shape != p.shape:
        raise ValueError(f"primitive {k}: normals must have the positions' shape {p.shape}; got {n.shape}")
    if i.ndim != 2 or i.shape[1] != 3 or i.shape[0] < 1 or not np.issubdtype(i.dtype, np.integer):
        raise ValueError(f"primitive {k}: indices must be integers of shape (T >= 1, 3); got {i.dtype} {i.shape}")
    if i.min() < 0 or i.max() >= p.shape[0]:
        raise ValueError(f"primitive {k}: indices must lie in [0, {p.shape[0]})")
    arrays = [p, n]
    if prim.texcoords is not None:
        t = np.asarray(prim.texcoords, dtype=np.float64)
        if t.shape != (p.shape[0], 2):
            raise ValueError(f"primitive {k}: texcoords must have shape ({p.shape[0]}, 2); got {t.shape}")
        arrays.append(t)
    if not all(np.all(np.isfinite(a)) for a in arrays):
        raise ValueError(f"primitive {k}: positions, normals and texcoords must be finite")
    return arrays, i.astype(np.uint32)


def glb_bytes(primitives):
    """The ``.glb`` bytes of one mesh made of ``primitives`` (:class:`GltfPrimitive`),
    in one node of one scene (module docstring)."""
    if not primitives:
        raise ValueError("a glTF mesh needs at least one primitive")
    blob = bytearray()
    views, accessors, materials, prims = [], [], [], []

    def add(array, ctype, kind, target, bounds=False):
        data = np.ascontiguousarray(array, dtype=np.float32 if ctype == _FLOAT else np.uint32)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": data.nbytes, "target": target})
        blob.extend(data.tobytes())
        blob.extend(b"\0" * (-len(blob) % 4))
        acc = {"bufferView": len(views) - 1, "componentType": ctype, "count": int(data.shape[0]), "type": kind}
        if bounds:
            acc["min"] = [float(x) for x in data.min(axis=0)]
            acc["max"] = [float(x) for x in data.max(axis=0)]
        accessors.append(acc)
        return len(accessors) - 1

    for k, prim in enumerate(primitives):
        arrays, indices = _check(prim, k)
        attributes = {"POSITION": add(arrays[0], _FLOAT, "VEC3", _ARRAY_BUFFER, bounds=True),
                      "NORMAL": add(arrays[1], _FLOAT, "VEC3", _ARRAY_BUFFER)}
        if len(arrays) > 2:
            attributes["TEXCOORD_0"] = add(arrays[2], _FLOAT, "VEC2", _ARRAY_BUFFER)
        index = add(indices.reshape(-1), _UINT, "SCALAR", _ELEMENT_ARRAY_BUFFER)
        color = [float(x) for x in prim.base_color] + ([1.0] if len(prim.base_color) == 3 else [])
        materials.append({"name": str(prim.name), "pbrMetallicRoughness": {
            "baseColorFactor": color, "metallicFactor": float(prim.metallic), "roughnessFactor": float(prim.roughness)}})
        prims.append({"attributes": attributes, "indices": index, "material": k, "mode": 4})
    doc = {"asset": {"version": "2.0", "generator": "pbrkit"}, "scene": 0, "scenes": [{"nodes": [0]}],
           "nodes": [{"mesh": 0}], "meshes": [{"primitives": prims}], "materials": materials,
           "accessors": accessors, "bufferViews": views, "buffers": [{"byteLength": len(blob)}]}
    text = json.dumps(doc, sort_keys=True, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    total = 12 + 8 + len(text) + 8 + len(blob)
    return (struct.pack("<4sII", _GLB_MAGIC, 2, total) + struct.pack("<II", len(text), _CHUNK_JSON) + text
            + struct.pack("<II", len(blob), _CHUNK_BIN) + bytes(blob))


def write_glb(path, primitives):
    """Write :func:`glb_bytes` of ``primitives`` to ``path`` atomically."""
    write_bytes(path, glb_bytes(primitives))
