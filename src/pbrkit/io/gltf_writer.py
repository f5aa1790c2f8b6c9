"""Writing binary glTF 2.0 (``.glb``) files of triangle meshes with
metallic-roughness materials: what pbrkit generates itself (the demo's
procedural model) in the format every viewer loads.

The layout is the glTF 2.0 specification's (Khronos, 2021): sec. 4.4 (the
binary container: a 12-byte header, a JSON chunk padded with spaces and a BIN
chunk padded with zeros, each to 4 bytes), sec. 3.6 (one buffer; a bufferView
and an accessor per attribute, float32 VEC3 POSITION with its min / max, VEC3
NORMAL, VEC2 TEXCOORD_0, VEC4 TANGENT (xyz unit, w = +-1 the bitangent's sign),
uint32 indices), sec. 3.9 (materials'
``pbrMetallicRoughness`` factors, ``emissiveFactor`` and an optional ``normalTexture``),
sec. 3.8 (textures: each :class:`GltfTexture` an 8-bit PNG embedded in a bufferView of
the BIN chunk, with an image, a sampler and a texture of its own, texture ``k`` the k-th
given; materials name them by ``"index"`` in ``normalTexture`` and in their
extensions' textureInfo objects, e.g. ``clearcoatNormalTexture``), sec. 3.10 (an
optional perspective camera in a node of its own, :class:`GltfCamera`) and sec. 3.12
(extensions: a material's
``extensions`` object is written as given, e.g. ``{"KHR_materials_clearcoat":
{"clearcoatFactor": 1.0}}``, and every extension name any material uses is listed
in ``extensionsUsed``; ``extensionsRequired`` is written only for the names passed
as ``extensions_required``).  JSON keys are sorted and numbers written by Python's
shortest round-trip repr, so the same meshes give the same bytes.
"""

from __future__ import annotations

import json
import math
import numbers
import struct
from dataclasses import dataclass

import numpy as np

from ..core.atomic import write_bytes
from .png import png_file_bytes

__all__ = ["GltfCamera", "GltfPrimitive", "GltfTexture", "glb_bytes", "write_glb"]

_FLOAT, _UINT = 5126, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_GLB_MAGIC, _CHUNK_JSON, _CHUNK_BIN = b"glTF", 0x4E4F534A, 0x004E4942
_NEAREST, _LINEAR, _REPEAT = 9728, 9729, 10497
#: glTF sampler enums (sec. 5.26): magFilter, minFilter, wrapS / wrapT
_MAG_FILTERS = (_NEAREST, _LINEAR)
_MIN_FILTERS = (_NEAREST, _LINEAR, 9984, 9985, 9986, 9987)
_WRAPS = (33071, 33648, _REPEAT)


@dataclass(frozen=True)
class GltfPrimitive:
    """One mesh primitive: ``positions`` (V, 3), ``normals`` (V, 3) unit,
    optional ``texcoords`` (V, 2), ``indices`` (T, 3) counter-clockwise
    triangles, and its material's ``base_color`` (linear RGB or RGBA),
    ``metallic``, ``roughness``, ``emissive`` (``emissiveFactor``, linear RGB in
    [0, 1], written when not black), ``name`` and ``extensions`` (the material's glTF
    ``extensions`` object: extension name -> JSON object of strings, booleans,
    finite numbers, lists and objects; None for none; a textureInfo in it, an object
    under a key ending in ``Texture``, names one of :func:`glb_bytes`'s ``textures`` by
    its ``index``), optional ``tangents`` (V, 4): glTF's TANGENT, xyz unit and orthogonal
    to the normal, w = +-1 (B = w N x T), and optional ``normal_texture``: the material's
    normalTextureInfo (``{"index": k, "scale": s}``).  A material with textures needs
    ``texcoords`` (their ``texCoord`` 0 or absent: TEXCOORD_0 is the one set written)."""

    positions: np.ndarray
    normals: np.ndarray
    indices: np.ndarray
    texcoords: np.ndarray | None = None
    base_color: tuple = (1.0, 1.0, 1.0)
    metallic: float = 0.0
    roughness: float = 0.5
    name: str = "material"
    extensions: dict | None = None
    emissive: tuple = (0.0, 0.0, 0.0)
    tangents: np.ndarray | None = None
    normal_texture: dict | None = None


@dataclass(frozen=True)
class GltfTexture:
    """A texture embedded as an 8-bit PNG: ``image`` (H, W) or (H, W, C) of integers in
    [0, 255], C = 1 grey, 2 grey and alpha, 3 RGB or 4 RGBA (the values written as they
    are, no colour chunk: glTF says which uses are sRGB), row 0 the image's top (UV v = 0),
    and its sampler's ``mag_filter``, ``min_filter``, ``wrap_s``, ``wrap_t`` (glTF's OpenGL
    enums; by default LINEAR magnification and minification, which reads no mip maps, and
    REPEAT)."""

    image: np.ndarray
    mag_filter: int = _LINEAR
    min_filter: int = _LINEAR
    wrap_s: int = _REPEAT
    wrap_t: int = _REPEAT


@dataclass(frozen=True)
class GltfCamera:
    """A perspective camera (glTF sec. 5.12): ``yfov`` in radians, ``aspect_ratio``
    (None: the viewport's), ``znear``, ``zfar`` (None: infinite), placed by its node's
    ``translation`` and unit quaternion ``rotation`` (x, y, z, w); unrotated it looks
    down -Z with +Y up."""

    yfov: float
    aspect_ratio: float | None = None
    znear: float = 0.01
    zfar: float | None = None
    translation: tuple = (0.0, 0.0, 0.0)
    rotation: tuple = (0.0, 0.0, 0.0, 1.0)


def _json_value(value, where):
    """``value`` as plain JSON (Python numbers, strings, lists, dicts); ``ValueError``
    naming ``where`` for anything else or a non-finite number."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        if not math.isfinite(float(value)):
            raise ValueError(f"{where} must be finite; got {value!r}")
        return float(value)
    if isinstance(value, dict):
        out = {}
        for key, item in value.items():
            if not isinstance(key, str):
                raise ValueError(f"{where}: keys must be strings; got {key!r}")
            out[key] = _json_value(item, f"{where}.{key}")
        return out
    if isinstance(value, (list, tuple, np.ndarray)):
        return [_json_value(item, f"{where}[{i}]") for i, item in enumerate(value)]
    raise ValueError(f"{where} must be JSON (numbers, strings, lists, objects); got {type(value).__name__}")


def _material_extensions(prim, k):
    if prim.extensions is None:
        return None
    where = f"primitive {k}: material extensions"
    if not isinstance(prim.extensions, dict):
        raise ValueError(f"{where} must be a dict of extension name -> object; got {type(prim.extensions).__name__}")
    out = _json_value(prim.extensions, where)
    for name, obj in out.items():
        if not name or not isinstance(obj, dict):
            raise ValueError(f"{where}.{name} must be an object under a non-empty name")
    return out


def _png(texture, k):
    """The deterministic PNG bytes of :class:`GltfTexture` ``texture`` (filter 0 rows)."""
    a = np.asarray(texture.image)
    if a.ndim == 2:
        a = a[..., None]
    if a.ndim != 3 or a.shape[2] not in (1, 2, 3, 4) or a.shape[0] < 1 or a.shape[1] < 1:
        raise ValueError(f"texture {k}: image must have shape (H, W) or (H, W, 1..4); got {a.shape}")
    if not (np.issubdtype(a.dtype, np.integer) and a.min() >= 0 and a.max() <= 255):
        raise ValueError(f"texture {k}: image must hold integers in [0, 255]; got {a.dtype}")
    for name, value, allowed in (("mag_filter", texture.mag_filter, _MAG_FILTERS),
                                 ("min_filter", texture.min_filter, _MIN_FILTERS),
                                 ("wrap_s", texture.wrap_s, _WRAPS), ("wrap_t", texture.wrap_t, _WRAPS)):
        if value not in allowed:
            raise ValueError(f"texture {k}: {name} must be one of {allowed}; got {value!r}")
    height, width, channels = a.shape
    rows = a.astype(np.uint8).reshape(height, width * channels)
    filtered = np.concatenate([np.zeros((height, 1), np.uint8), rows], axis=1)
    return png_file_bytes(width, height, 8, {1: 0, 2: 4, 3: 2, 4: 6}[channels], filtered)


def _texture_infos(value, count, where):
    """How many textureInfo objects (an object under a key ending in ``Texture``) the JSON
    ``value`` holds, each checked to name one of ``count`` textures by an integer
    ``index`` and to use TEXCOORD_0 (``texCoord`` 0 or absent)."""
    found = 0
    if isinstance(value, dict):
        for key, item in value.items():
            if key.endswith("Texture"):
                index = item.get("index") if isinstance(item, dict) else None
                if not (isinstance(index, int) and not isinstance(index, bool) and 0 <= index < count):
                    raise ValueError(f"{where}.{key} must be a textureInfo whose index names one of the {count} "
                                     f"textures; got {item!r}")
                if item.get("texCoord", 0) != 0:
                    raise ValueError(f"{where}.{key}: texCoord must be 0 (TEXCOORD_0 is the one set written)")
                found += 1
            found += _texture_infos(item, count, f"{where}.{key}")
    return found


def _camera(camera):
    yfov, znear = float(camera.yfov), float(camera.znear)
    if not (math.isfinite(yfov) and 0.0 < yfov < math.pi):
        raise ValueError(f"camera yfov must lie in (0, pi) radians; got {camera.yfov!r}")
    if not (math.isfinite(znear) and znear > 0.0):
        raise ValueError(f"camera znear must be positive; got {camera.znear!r}")
    perspective = {"yfov": yfov, "znear": znear}
    if camera.aspect_ratio is not None:
        aspect = float(camera.aspect_ratio)
        if not (math.isfinite(aspect) and aspect > 0.0):
            raise ValueError(f"camera aspect_ratio must be positive; got {camera.aspect_ratio!r}")
        perspective["aspectRatio"] = aspect
    if camera.zfar is not None:
        zfar = float(camera.zfar)
        if not (math.isfinite(zfar) and zfar > znear):
            raise ValueError(f"camera zfar must exceed znear; got {camera.zfar!r}")
        perspective["zfar"] = zfar
    t = np.asarray(camera.translation, dtype=np.float64)
    q = np.asarray(camera.rotation, dtype=np.float64)
    if t.shape != (3,) or not np.all(np.isfinite(t)):
        raise ValueError(f"camera translation must be 3 finite numbers; got {camera.translation!r}")
    if q.shape != (4,) or not np.all(np.isfinite(q)) or abs(float(q @ q) - 1.0) > 1e-6:
        raise ValueError(f"camera rotation must be a unit quaternion (x, y, z, w); got {camera.rotation!r}")
    node = {"camera": 0, "translation": [float(x) for x in t], "rotation": [float(x) for x in q]}
    return {"type": "perspective", "perspective": perspective}, node


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
    tangents = None
    if prim.tangents is not None:
        tangents = np.asarray(prim.tangents, dtype=np.float64)
        if tangents.shape != (p.shape[0], 4) or not np.all(np.isfinite(tangents)):
            raise ValueError(f"primitive {k}: tangents must be finite, of shape ({p.shape[0]}, 4); got "
                             f"{tangents.shape}")
        if not (np.allclose(np.linalg.norm(tangents[:, :3], axis=1), 1.0, atol=1e-6)
                and np.all(np.abs(tangents[:, 3]) == 1.0)):
            raise ValueError(f"primitive {k}: tangents must have unit xyz and w = +-1")
    if not all(np.all(np.isfinite(a)) for a in arrays):
        raise ValueError(f"primitive {k}: positions, normals and texcoords must be finite")
    return arrays, i.astype(np.uint32), tangents


def glb_bytes(primitives, camera=None, extensions_required=(), textures=()):
    """The ``.glb`` bytes of one mesh made of ``primitives`` (:class:`GltfPrimitive`),
    in one node of one scene, with ``camera`` (:class:`GltfCamera`) in a second node
    when given and ``textures`` (:class:`GltfTexture`, texture k the k-th) embedded;
    ``extensionsUsed`` lists the materials' extensions, and
    ``extensions_required`` (each also used by a material) goes into
    ``extensionsRequired`` (module docstring)."""
    if not primitives:
        raise ValueError("a glTF mesh needs at least one primitive")
    textures = tuple(textures)
    pngs = [_png(t, k) for k, t in enumerate(textures)]
    used = set()
    blob = bytearray()
    views, accessors, materials, prims = [], [], [], []

    def view(data, target=None):
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)}
                     | ({} if target is None else {"target": target}))
        blob.extend(data)
        blob.extend(b"\0" * (-len(blob) % 4))
        return len(views) - 1

    def add(array, ctype, kind, target, bounds=False):
        data = np.ascontiguousarray(array, dtype=np.float32 if ctype == _FLOAT else np.uint32)
        view(data.tobytes(), target)
        acc = {"bufferView": len(views) - 1, "componentType": ctype, "count": int(data.shape[0]), "type": kind}
        if bounds:
            acc["min"] = [float(x) for x in data.min(axis=0)]
            acc["max"] = [float(x) for x in data.max(axis=0)]
        accessors.append(acc)
        return len(accessors) - 1

    for k, prim in enumerate(primitives):
        arrays, indices, tangents = _check(prim, k)
        attributes = {"POSITION": add(arrays[0], _FLOAT, "VEC3", _ARRAY_BUFFER, bounds=True),
                      "NORMAL": add(arrays[1], _FLOAT, "VEC3", _ARRAY_BUFFER)}
        if len(arrays) > 2:
            attributes["TEXCOORD_0"] = add(arrays[2], _FLOAT, "VEC2", _ARRAY_BUFFER)
        if tangents is not None:
            attributes["TANGENT"] = add(tangents, _FLOAT, "VEC4", _ARRAY_BUFFER)
        index = add(indices.reshape(-1), _UINT, "SCALAR", _ELEMENT_ARRAY_BUFFER)
        color = [float(x) for x in prim.base_color] + ([1.0] if len(prim.base_color) == 3 else [])
        material = {"name": str(prim.name), "pbrMetallicRoughness": {
            "baseColorFactor": color, "metallicFactor": float(prim.metallic), "roughnessFactor": float(prim.roughness)}}
        emissive = np.asarray(prim.emissive, dtype=np.float64)
        if emissive.shape != (3,) or not np.all((emissive >= 0.0) & (emissive <= 1.0)):
            raise ValueError(f"primitive {k}: emissive must be 3 numbers in [0, 1]; got {prim.emissive!r}")
        if np.any(emissive > 0.0):
            material["emissiveFactor"] = [float(x) for x in emissive]
        infos = {}
        if prim.normal_texture is not None:
            material["normalTexture"] = infos["normalTexture"] = _json_value(prim.normal_texture,
                                                                             f"primitive {k}: normal_texture")
        extensions = _material_extensions(prim, k)
        if _texture_infos(infos | (extensions or {}), len(textures), f"primitive {k}: material") and \
                prim.texcoords is None:
            raise ValueError(f"primitive {k}: a material with textures needs texcoords (TEXCOORD_0)")
        if extensions:
            material["extensions"] = extensions
            used.update(extensions)
        materials.append(material)
        prims.append({"attributes": attributes, "indices": index, "material": k, "mode": 4})
    doc = {"asset": {"version": "2.0", "generator": "pbrkit"}, "scene": 0, "scenes": [{"nodes": [0]}],
           "nodes": [{"mesh": 0}], "meshes": [{"primitives": prims}], "materials": materials,
           "accessors": accessors, "bufferViews": views, "buffers": [{"byteLength": len(blob)}]}
    if textures:  # the PNGs after the attributes, in the one buffer
        doc["images"] = [{"bufferView": view(data), "mimeType": "image/png"} for data in pngs]
        doc["samplers"] = [{"magFilter": int(t.mag_filter), "minFilter": int(t.min_filter), "wrapS": int(t.wrap_s),
                            "wrapT": int(t.wrap_t)} for t in textures]
        doc["textures"] = [{"sampler": k, "source": k} for k in range(len(textures))]
        doc["buffers"] = [{"byteLength": len(blob)}]
    if camera is not None:
        perspective, node = _camera(camera)
        doc["cameras"] = [perspective]
        doc["nodes"].append(node)
        doc["scenes"][0]["nodes"].append(1)
    required = sorted(set(extensions_required))
    if set(required) - used:
        raise ValueError(f"extensions_required {sorted(set(required) - used)} are not used by any material")
    if used:
        doc["extensionsUsed"] = sorted(used)
    if required:
        doc["extensionsRequired"] = required
    text = json.dumps(doc, sort_keys=True, separators=(",", ":")).encode("utf-8")
    text += b" " * (-len(text) % 4)
    total = 12 + 8 + len(text) + 8 + len(blob)
    return (struct.pack("<4sII", _GLB_MAGIC, 2, total) + struct.pack("<II", len(text), _CHUNK_JSON) + text
            + struct.pack("<II", len(blob), _CHUNK_BIN) + bytes(blob))


def write_glb(path, primitives, camera=None, extensions_required=(), textures=()):
    """Write :func:`glb_bytes` of ``primitives`` (and ``camera``, ``extensions_required``,
    ``textures``) to ``path`` atomically."""
    write_bytes(path, glb_bytes(primitives, camera, extensions_required, textures))
