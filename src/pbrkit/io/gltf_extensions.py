"""Two glTF 2.0 extensions of the loader: ``KHR_texture_transform`` and ``KHR_mesh_quantization``.

Both are ratified Khronos extensions, read here from their specifications in the
Khronos glTF repository (``extensions/2.0/Khronos/KHR_texture_transform/README.md``
and ``extensions/2.0/Khronos/KHR_mesh_quantization/README.md``).

``KHR_texture_transform`` adds ``offset``, ``rotation``, ``scale`` and an optional
``texCoord`` override to a textureInfo; the texture is looked up at

    uv' = T(offset) R(rotation) S(scale) (u, v, 1)

(:class:`TextureTransform`).  The rotation turns the UVs by ``rotation`` radians
counter-clockwise *in UV space* (u right, v down), which is a clockwise turn of the
image as seen on the model; as a matrix on column vectors

    R = [[cos r,  sin r],
         [-sin r, cos r]]

so u' = cos(r) u + sin(r) v, v' = -sin(r) u + cos(r) v.  This is the direction of the
Khronos reference viewer (glTF-Sample-Viewer, ``source/gltf/material.js``), of the
sample model TextureTransformTest (its "Rotation" quad, 22.5 degrees: the green
marker) and of the specification's own example ("offset [0, 1], rotation pi/2, scale
[0.5, 0.5]" uses "only the lower left quadrant of the source image, rotated clockwise
90 degrees": with this R the unit square maps onto u' in [0, 0.5], v' in [0.5, 1]).
The GLSL listing of the specification, read literally as a column-major ``mat3``,
gives the transpose (a counter-clockwise turn with v up); Khronos glTF issue #1563
records that the listing disagrees with the text, the example and every
implementation, and pbrkit follows the latter.

``KHR_mesh_quantization`` allows further component types for the POSITION, NORMAL,
TANGENT and TEXCOORD_n attributes (its table "Extending Mesh Attributes",
:data:`QUANTIZED_FORMATS`).  Normalised integers are decoded by glTF 2.0 sec. 3.11
(``f = max(c / 127, -1)`` for BYTE, ``c / 255``, ``max(c / 32767, -1)``,
``c / 65535``); non-normalised integers keep their integer value, which a node
transform (positions) or a texture transform (texture coordinates) scales back, as
the extension prescribes.  Without the extension in ``extensionsUsed`` these formats
are refused as before.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..core.checks import is_finite_number
from .gltf_fields import (_BYTE, _COMPONENT_NAMES, _FLOAT, _SHORT, _UBYTE, _UINT, _USHORT, _integer, _json_kind,
                          _object, _shown)

__all__ = [
    "check_texture_info",
    "TEXTURE_TRANSFORM",
    "MESH_QUANTIZATION",
    "TextureTransform",
    "check_texture_transform",
    "texture_transform",
    "CORE_FORMATS",
    "QUANTIZED_FORMATS",
    "attribute_formats",
    "format_text",
]

TEXTURE_TRANSFORM = "KHR_texture_transform"
MESH_QUANTIZATION = "KHR_mesh_quantization"

#: Largest magnitude of an offset or scale component: with texture coordinates of at
#: most 1e6 (``pbrkit.rendering.gltf``) the transformed ones stay well inside the range
#: where texel addressing (int64 texel indices) is exact.
MAX_TRANSFORM = 1e6

# ================================================================ KHR_texture_transform


@dataclass(frozen=True)
class TextureTransform:
    """``KHR_texture_transform`` of one textureInfo (module docstring): offset (2,),
    rotation (radians, counter-clockwise in UV space), scale (2,)."""

    offset: tuple = (0.0, 0.0)
    rotation: float = 0.0
    scale: tuple = (1.0, 1.0)

    @property
    def matrix(self):
        """The 3 x 3 matrix T R S acting on column vectors (u, v, 1)."""
        c, s = math.cos(self.rotation), math.sin(self.rotation)
        t = np.array([[1.0, 0.0, self.offset[0]], [0.0, 1.0, self.offset[1]], [0.0, 0.0, 1.0]])
        r = np.array([[c, s, 0.0], [-s, c, 0.0], [0.0, 0.0, 1.0]])
        k = np.diag([self.scale[0], self.scale[1], 1.0])
        return t @ r @ k

    def apply(self, uv):
        """Texture coordinates uv (N, 2) -> the transformed ones (N, 2), float64."""
        m = self.matrix
        uv = np.asarray(uv, dtype=np.float64)
        return uv @ m[:2, :2].T + m[:2, 2]


def _vector2(value, where):
    if not isinstance(value, list) or len(value) != 2 or not all(is_finite_number(x) and abs(x) <= MAX_TRANSFORM
                                                                 for x in value):
        raise ValueError(f"{where} must be an array of 2 finite numbers in [-{MAX_TRANSFORM:g}, "
                         f"{MAX_TRANSFORM:g}]; got {_shown(value)}")
    return (float(value[0]), float(value[1]))


def check_texture_transform(ext, where):
    """Check a textureInfo's ``extensions.KHR_texture_transform`` object ``ext`` at JSON
    location ``where``: ``offset`` and ``scale`` arrays of 2 finite numbers (at most
    :data:`MAX_TRANSFORM` in magnitude), ``rotation`` a finite number, ``texCoord`` an
    integer >= 0 (the extension's JSON schema).  Raises ValueError naming the field."""
    if not isinstance(ext, dict):
        raise ValueError(f"{where} must be a JSON object; got {_json_kind(ext)}")
    for key in ("offset", "scale"):
        if ext.get(key) is not None:
            _vector2(ext[key], f"{where}.{key}")
    rotation = ext.get("rotation")
    if rotation is not None and not is_finite_number(rotation):
        raise ValueError(f"{where}.rotation must be a finite number (radians); got {_shown(rotation)}")
    tex_coord = ext.get("texCoord")
    if tex_coord is not None and (isinstance(tex_coord, bool) or not isinstance(tex_coord, int) or tex_coord < 0):
        raise ValueError(f"{where}.texCoord must be an integer >= 0; got {_shown(tex_coord)}")


def texture_transform(info):
    """(:class:`TextureTransform` or None, TEXCOORD set) of a checked textureInfo: None
    without the extension or with the identity transform (so such a texture is looked
    up exactly as without it), the set being the extension's ``texCoord`` override if
    given, else the textureInfo's ``texCoord`` (default 0)."""
    tex_coord = info.get("texCoord") or 0
    ext = (info.get("extensions") or {}).get(TEXTURE_TRANSFORM)
    if ext is None:
        return None, tex_coord
    if ext.get("texCoord") is not None:
        tex_coord = ext["texCoord"]
    transform = TextureTransform(_vector2(ext["offset"], "offset") if ext.get("offset") is not None else (0.0, 0.0),
                                 float(ext.get("rotation") or 0.0),
                                 _vector2(ext["scale"], "scale") if ext.get("scale") is not None else (1.0, 1.0))
    if transform == TextureTransform():
        return None, tex_coord
    return transform, tex_coord


# ================================================================ KHR_mesh_quantization

#: Attribute formats of glTF 2.0 sec. 3.7.2.1 (indices: sec. 3.7.2.2): semantic -> (accessor type,
#: allowed (componentType, normalized) pairs).  FLOAT is listed with normalized False and matched
#: whatever its flag says.
CORE_FORMATS = {
    "POSITION": ("VEC3", ((_FLOAT, False),)),
    "NORMAL": ("VEC3", ((_FLOAT, False),)),
    "TANGENT": ("VEC4", ((_FLOAT, False),)),
    "TEXCOORD": ("VEC2", ((_FLOAT, False), (_UBYTE, True), (_USHORT, True))),
    "COLOR3": ("VEC3", ((_FLOAT, False), (_UBYTE, True), (_USHORT, True))),  # COLOR_n as VEC3
    "COLOR4": ("VEC4", ((_FLOAT, False), (_UBYTE, True), (_USHORT, True))),  # COLOR_n as VEC4
    "indices": ("SCALAR", ((_UBYTE, False), (_USHORT, False), (_UINT, False))),
}

#: The extra formats of ``KHR_mesh_quantization`` (its table "Extending Mesh Attributes").
QUANTIZED_FORMATS = {
    "POSITION": tuple((c, n) for c in (_BYTE, _UBYTE, _SHORT, _USHORT) for n in (False, True)),
    "NORMAL": ((_BYTE, True), (_SHORT, True)),
    "TANGENT": ((_BYTE, True), (_SHORT, True)),
    "TEXCOORD": ((_BYTE, False), (_BYTE, True), (_UBYTE, False), (_SHORT, False), (_SHORT, True),
                 (_USHORT, False)),
}


def attribute_formats(semantic, quantized):
    """(accessor type, allowed (componentType, normalized) pairs) of an attribute
    (a key of :data:`CORE_FORMATS`), with the extension's extra ones when ``quantized``."""
    kind, pairs = CORE_FORMATS[semantic]
    if quantized and semantic in QUANTIZED_FORMATS:
        pairs = pairs + QUANTIZED_FORMATS[semantic]
    return kind, pairs


def format_key(accessor):
    """The (componentType, normalized) pair of a checked accessor (FLOAT: normalized False)."""
    component = accessor["componentType"]
    return component, bool(accessor.get("normalized")) and component != _FLOAT


def format_text(kind, pairs, with_flag=True):
    """'VEC3 FLOAT or VEC3 SHORT (normalized) ...' for messages."""
    return " or ".join(f"{kind} {_COMPONENT_NAMES[c]}" + (" (normalized)" if n and with_flag else "")
                       for c, n in pairs)


def check_texture_info(info, where, index):
    """A textureInfo (glTF 2.0 sec. 5.29: ``index`` into textures, ``texCoord``) and its
    ``KHR_texture_transform`` (:func:`check_texture_transform`)."""
    _object(info, where)
    index.required(info, "index", where, "textures")
    if info.get("texCoord") is not None:
        _integer(info["texCoord"], f"{where}.texCoord")
    if info.get("extensions") is not None:
        ext = _object(info["extensions"], f"{where}.extensions").get(TEXTURE_TRANSFORM)
        if ext is not None:
            check_texture_transform(ext, f"{where}.extensions.{TEXTURE_TRANSFORM}")
