"""glTF 2.0 scenes as world-space triangle meshes, materials and lights.

glTF 2.0 files (``.gltf`` with external or data-URI buffers, and ``.glb``)
are read following the glTF 2.0 specification (Khronos, 2021): the default
scene's node hierarchy with matrix or TRS transforms (normals by the
inverse transpose; the determinant's sign flips the tangent handedness),
triangle, strip and fan primitives, accessors with byte strides, normalised
integers and sparse substitution, flat normals when NORMAL is absent, and
the metallic-roughness material with all its textures and vertex colours
(COLOR_0's RGB times the base colour): baseColor (sRGB,
times baseColorFactor), metallicRoughness (G = roughness, B = metallic,
times the factors), normal (tangent space, +X right, +Y up, scaled by
``normalTexture.scale``), occlusion (R, applied as 1 + strength (R - 1))
and emissive (sRGB, times emissiveFactor and
``KHR_materials_emissive_strength``), with the factors of
``KHR_materials_sheen``, ``_clearcoat``, ``_specular``, ``_ior``,
``_iridescence``, ``_transmission``, ``_volume`` and ``_anisotropy`` as the
``gltf`` model's parameters (:mod:`pbrkit.io.gltf_materials`; their textures
per shading point, :attr:`pbrkit.rendering.textures.SurfaceMaterial.extension_textures`,
the clear coat's own normal from clearcoatNormalTexture) and ``KHR_materials_unlit`` as
emission of the base colour.  TANGENT (or MikkTSpace tangents along the normal texture's
UVs, else the clearcoatNormalTexture's, or TEXCOORD_0 for an anisotropic material without
a normal texture) gives the tangent frame of normal maps and of ``KHR_materials_anisotropy``.  ``alphaMode`` MASK and BLEND with ``alphaCutoff`` and the base
colour's alpha (factor and texture) give cutouts and coverage in both render
modes (:mod:`pbrkit.rendering.alpha`).  ``KHR_lights_punctual`` lights are read too, and each textureInfo's ``KHR_texture_transform`` (offset, rotation,
scale, texCoord override) and ``KHR_mesh_quantization``'s attribute formats
are honoured (:mod:`pbrkit.io.gltf_extensions`, after the Khronos
specifications).  Texture sampling follows the glTF sampler: bilinear (or
nearest) filtering of linear texel values at texel centres (sRGB texels are
decoded before filtering, as GPUs do), REPEAT / CLAMP_TO_EDGE /
MIRRORED_REPEAT wrapping, UV (0, 0) at the first (top-left) texel.
Minification filters and mip maps are not used (supersample the camera
instead).

Every file is checked before any of its data is used, so a broken file is
refused with :class:`pbrkit.core.errors.InputError` (one line naming the
file and the JSON location of the problem) instead of a traceback, a
warning or an empty image:

- the container: an empty or truncated ``.glb``, a wrong magic or container
  version, a JSON chunk that is not UTF-8 JSON, JSON that is not an object;
- ``asset.version`` must be 2.x (and ``asset.minVersion``, if given, 2.0);
- every index (scene, node, mesh, accessor, bufferView, buffer, material,
  texture, image, sampler, camera, skin, light, animation sampler) must be an
  integer (not a bool or a float) within its array; the node hierarchy must
  be a forest (no cycles, no node with two parents, scene roots are roots);
- enumerations (componentType, type, mode, sampler filters and wraps,
  alphaMode, light type) and numbers (finite, in the specification's
  ranges) are checked, and every accessor and bufferView must lie inside its
  bufferView and buffer;
- the attributes pbrkit reads must have the specification's formats
  (POSITION and NORMAL VEC3 FLOAT, TANGENT VEC4 FLOAT, TEXCOORD_n VEC2 FLOAT
  or normalised UNSIGNED_BYTE / UNSIGNED_SHORT, indices SCALAR unsigned; with
  ``KHR_mesh_quantization`` in ``extensionsUsed`` also the extension's table),
  finite values, one count per primitive, and indices below that count;
- a file whose default scene holds no triangle mesh (and no light) is
  refused: there is nothing to render.

A model is untrusted input (:mod:`pbrkit.core.inputs`): the file itself must be
a regular file of at most :data:`pbrkit.io.gltf_document.MAX_GLTF_BYTES`; the
buffers and images its URIs name must lie under its folder or a root the user
allows (``allow_roots``), external buffers are read to exactly their
``byteLength``, images are checked by their headers before decoding
(:mod:`pbrkit.io.gltf_resources`); every accessor's memory
(:func:`accessor_bytes`) and the memory of all the meshes the scene places
(:data:`BYTES_PER_VERTEX`, :data:`BYTES_PER_TRIANGLE`, from the accessors'
counts alone) are checked against the memory available before anything is
allocated.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..core.errors import InputError
from ..core.inputs import Confinement, check_allocation, describe, size_text
from ..io.gltf_document import read_gltf_document, validate_gltf_document
from ..io.gltf_extensions import (
    MESH_QUANTIZATION,
    TEXTURE_TRANSFORM,
    attribute_formats,
    format_key,
    format_text,
    texture_transform,
)
from ..io.gltf_fields import _COMPONENT, _COMPONENT_NAMES, _NCOMP
from ..io.gltf_materials import MATERIAL_EXTENSIONS, TEXTURE_USES, UNLIT, material_extension_values, unlit_material
from ..io.gltf_resources import MAX_IMAGE_BYTES, buffer_file_bytes, decode_image, uri_bytes
from .lights import Light
from .scene import MaterialSpec, trs_matrix
from .tangents import mikktspace_tangents
from .textures import (
    _WRAP_REPEAT,
    SurfaceMaterial,
    Texture,
    TextureRef,
)

__all__ = [
    "Mesh",
    "GltfAsset",
    "load_gltf",
]

# ================================================================== glTF


@dataclass
class Mesh:
    """One triangle primitive in world space (float64)."""

    positions: np.ndarray          # (V, 3)
    normals: np.ndarray            # (V, 3) unit
    indices: np.ndarray            # (T, 3) int64
    material: int                  # index into the asset's materials
    texcoords: tuple = ()          # (V, 2) per TEXCOORD_n
    tangents: np.ndarray | None = None  # (V, 4): xyz unit, w = +-1
    colors: np.ndarray | None = None    # (V, 3) COLOR_0's RGB (linear, in [0, 1])
    alphas: np.ndarray | None = None    # (V,) COLOR_0's alpha (VEC4): it multiplies the base colour's


@dataclass
class GltfAsset:
    meshes: list
    materials: list      # SurfaceMaterial
    lights: list         # pbrkit.rendering.lights.Light
    notes: list


_SUPPORTED_REQUIRED = {"KHR_lights_punctual", "KHR_materials_emissive_strength", *MATERIAL_EXTENSIONS,
                       TEXTURE_TRANSFORM, MESH_QUANTIZATION}
#: Largest texture coordinate accepted (beyond it texel addressing loses all precision).
_MAX_TEXCOORD = 1e6
#: Peak bytes per vertex and per triangle of the meshes built from a glTF file and handed
#: to the renderer (:func:`_check_mesh_memory`, before any accessor is read): the accessor
#: data read and converted to float64, the world-space copies of :class:`Mesh`, the
#: float32 / int32 copies and the BVH that Embree builds.  Measured as the growth of the
#: process's peak RSS over ``Geometry`` (Python 3.11, NumPy 2; 500^2 to 1500^2 vertex grids
#: with POSITION, TEXCOORD_0 and uint32 indices, with NORMAL and flat-shaded without it):
#: about 120 bytes per vertex (flat shading: per unshared vertex) and 90 per triangle.  The
#: constants leave room for TANGENT / MikkTSpace tangents and more UV sets (not measured).
BYTES_PER_VERTEX = 200
BYTES_PER_TRIANGLE = 160


def accessor_bytes(accessor):
    """Peak bytes of reading ``accessor`` (glTF 2.0 sec. 3.6.2): its elements copied out
    of the buffer (or zeros), the float64 result, and a sparse substitution's indices,
    values and copy (sec. 3.6.2.3)."""
    count, ncomp = accessor["count"], _NCOMP[accessor["type"]]
    item = np.dtype(_COMPONENT[accessor["componentType"]]).itemsize
    total = count * ncomp * (2 * item + 8)
    sparse = accessor.get("sparse")
    if sparse is not None:
        index_size = np.dtype(_COMPONENT[sparse["indices"]["componentType"]]).itemsize
        total += sparse["count"] * (index_size + 8 + ncomp * item) + count * ncomp * item
    return total

# ============================================================ reading data


class _GltfReader:
    """A checked glTF document (module docstring) and the bytes, images and textures it refers to.
    ``allow_roots``: folders besides the file's own whose files its URIs may name."""

    def __init__(self, path, allow_roots=()):
        self.path = Path(path)
        try:
            self.doc, self.blob = read_gltf_document(self.path)
            validate_gltf_document(self.doc)
        except InputError:
            raise
        except ValueError as exc:
            raise InputError(str(exc), path) from None
        self.confinement = Confinement(self.path.parent, allow_roots)
        self._buffers = {}
        self._images = {}
        self.notes = []
        required = set(self.doc.get("extensionsRequired") or [])
        unsupported = sorted(required - _SUPPORTED_REQUIRED)
        if unsupported:
            raise InputError(f"requires unsupported glTF extension(s): {', '.join(map(describe, unsupported))}", path)
        listed = set(self.doc.get("extensionsUsed") or []) | required
        #: KHR_mesh_quantization's attribute formats are accepted (pbrkit.io.gltf_extensions)
        self.quantized = MESH_QUANTIZATION in listed
        used = sorted(set(self.doc.get("extensionsUsed") or []) - _SUPPORTED_REQUIRED)
        if used:
            self.notes.append(f"ignored optional extension(s): {', '.join(map(describe, used))}")

    def fail(self, problem):
        raise InputError(problem, self.path)

    def items(self, name):
        """The top-level array ``name`` ([] when absent)."""
        return self.doc.get(name) or []

    def check_allocation(self, nbytes, what):
        """:func:`pbrkit.core.inputs.check_allocation` naming this file."""
        return check_allocation(nbytes, what, self.path)

    def buffer(self, index):
        """The bytes of buffers[index], exactly its byteLength (glTF 2.0 sec. 3.6.1.1):
        the .glb's BIN chunk, a data: URI, or a confined external file read no further
        (:func:`pbrkit.io.gltf_resources.buffer_file_bytes`)."""
        if index not in self._buffers:
            b = self.items("buffers")[index]
            where = f"buffers[{index}]"
            length = b["byteLength"]
            try:
                if b.get("uri") is None:
                    if index != 0 or self.blob is None:
                        self.fail(f"{where} has no uri and is not the binary chunk of a .glb (only buffers[0] of "
                                  "a .glb may omit its uri)")
                    data = self.blob
                elif b["uri"].startswith("data:"):
                    data = uri_bytes(b["uri"], f"{where}.uri", self.confinement, None, "")
                else:
                    data = buffer_file_bytes(b["uri"], f"{where}.uri", self.confinement, length, self.path)
            except InputError:
                raise
            except ValueError as exc:
                self.fail(str(exc))
            if len(data) < length:
                self.fail(f"{where} holds {len(data)} bytes, fewer than its byteLength {length} (truncated file?)")
            self._buffers[index] = memoryview(data)[:length]
        return self._buffers[index]

    def view_bytes(self, index):
        v = self.items("bufferViews")[index]
        data = self.buffer(v["buffer"])
        start = v.get("byteOffset") or 0
        return data[start:start + v["byteLength"]], v.get("byteStride")

    def _read_view(self, view, offset, count, dtype, ncomp):
        """(count, ncomp) elements of ``dtype`` from a bufferView (ranges checked by validation)."""
        raw, stride = self.view_bytes(view)
        item = np.dtype(dtype).itemsize * ncomp
        stride = stride or item
        need = offset + (count - 1) * stride + item
        if need > len(raw):  # excluded by validate_gltf_document (_check_ranges); never read past a view
            self.fail(f"bufferViews[{view}] holds {len(raw)} bytes; an accessor needs {need}")
        buf = np.frombuffer(raw, dtype=np.uint8, count=need - offset, offset=offset)
        if stride == item:
            return np.frombuffer(buf.tobytes(), dtype=dtype).reshape(count, ncomp)
        rows = np.lib.stride_tricks.as_strided(buf, shape=(count, item), strides=(stride, 1))
        return np.frombuffer(np.ascontiguousarray(rows).tobytes(), dtype=dtype).reshape(count, ncomp)

    def _zeros(self, index, count, ncomp, dtype):
        """The all-zero data of an accessor without a bufferView (glTF 2.0 sec. 3.6.2.3)."""
        return np.zeros((count, ncomp), dtype=dtype)

    def accessor(self, index, normalize_ints=True):
        """Accessor data as float64 (or int64 for index data with ``normalize_ints=False``),
        shape (count, components); glTF 2.0 sec. 3.6 (normalised integers by sec. 3.11)."""
        a = self.items("accessors")[index]
        dtype = _COMPONENT[a["componentType"]]
        ncomp = _NCOMP[a["type"]]
        self.check_allocation(accessor_bytes(a), f"accessors[{index}] (count {a['count']:,} {a['type']}"
                              f"{', no bufferView' if a.get('bufferView') is None else ''})")
        if a.get("bufferView") is not None:
            data = self._read_view(a["bufferView"], a.get("byteOffset") or 0, a["count"], dtype, ncomp)
        else:
            data = self._zeros(index, a["count"], ncomp, dtype)
        if a.get("sparse") is not None:
            data = self._apply_sparse(index, a, data, dtype, ncomp)
        if not normalize_ints:
            return data.astype(np.int64)
        out = data.astype(np.float64)
        if a.get("normalized") and dtype != np.float32:
            info = np.iinfo(dtype)
            out = out / info.max if info.min == 0 else np.maximum(out / info.max, -1.0)
        return out

    def _apply_sparse(self, index, a, data, dtype, ncomp):
        """``data`` with the sparse substitution of accessors[index] (glTF 2.0 sec. 3.6.2.3)."""
        s = a["sparse"]
        idx_type = _COMPONENT[s["indices"]["componentType"]]
        idx = self._read_view(s["indices"]["bufferView"], s["indices"].get("byteOffset") or 0, s["count"],
                              idx_type, 1)[:, 0].astype(np.int64)
        if np.any(idx >= a["count"]):
            self.fail(f"accessors[{index}].sparse has index {int(idx.max())}, past the accessor's count {a['count']}")
        if np.any(np.diff(idx) <= 0):
            self.fail(f"accessors[{index}].sparse indices must be strictly increasing")
        vals = self._read_view(s["values"]["bufferView"], s["values"].get("byteOffset") or 0, s["count"], dtype,
                               ncomp)
        data = data.copy()
        data[idx] = vals
        return data

    def attribute(self, index, semantic, where):
        """Accessor ``index`` used as ``semantic`` (a key of
        :data:`pbrkit.io.gltf_extensions.CORE_FORMATS`): format (with
        ``KHR_mesh_quantization``'s when the file uses it), count and values checked."""
        a = self.items("accessors")[index]
        kind, pairs = attribute_formats(semantic, self.quantized)
        key = format_key(a)
        if semantic == "indices":
            key = (key[0], False)  # the flag means nothing for indices
        if a["type"] != kind or key not in pairs:
            it = f"{a['type']} {_COMPONENT_NAMES[key[0]]}" + (" (normalized)" if key[1] else "")
            hint = ""
            if not self.quantized and a["type"] == kind and key in attribute_formats(semantic, True)[1]:
                hint = f" (a {MESH_QUANTIZATION} format, but the file does not list that extension in extensionsUsed)"
            self.fail(f"{where} (accessors[{index}]) must be {format_text(kind, pairs, semantic != 'indices')}; "
                      f"it is {it}{hint}")
        if semantic == "indices":
            return self.accessor(index, normalize_ints=False)[:, 0]
        data = self.accessor(index)
        limit = _MAX_TEXCOORD if semantic == "TEXCOORD" else np.finfo(np.float32).max
        bad = ~np.isfinite(data) | (np.abs(data) > limit)
        if np.any(bad):
            self.fail(f"{where} (accessors[{index}]) has {int(bad.sum())} non-finite or out-of-range value(s)")
        return data

    def image(self, index, srgb):
        """Texels (H, W, 4) float32 of image ``index``, sRGB-decoded when ``srgb``."""
        key = (index, srgb)
        if key not in self._images:
            self._images[key] = self._decode_image(index, srgb)
        return self._images[key]

    def _decode_image(self, index, srgb):
        """glTF 2.0 sec. 3.8.4: an image from a bufferView or a uri (data: or a confined
        file), its header checked before decoding (:mod:`pbrkit.io.gltf_resources`)."""
        im = self.items("images")[index]
        where = f"images[{index}]"
        try:
            if im.get("bufferView") is not None:
                data = self.view_bytes(im["bufferView"])[0]
            else:
                data = uri_bytes(im["uri"], f"{where}.uri", self.confinement, MAX_IMAGE_BYTES,
                                 f"an image of at most {size_text(MAX_IMAGE_BYTES)}")
            return decode_image(data, where, srgb, self.path)
        except InputError:
            raise
        except ValueError as exc:
            self.fail(str(exc))

    def texture(self, index, srgb, cache):
        key = (index, srgb)
        if key not in cache:
            t = self.items("textures")[index]
            if t.get("source") is None:
                self.fail(f"textures[{index}] has no source image (texture extensions are not supported)")
            wrap_s = wrap_t = _WRAP_REPEAT
            mag = None
            if t.get("sampler") is not None:
                s = self.items("samplers")[t["sampler"]]
                wrap_s = s.get("wrapS") or _WRAP_REPEAT
                wrap_t = s.get("wrapT") or _WRAP_REPEAT
                mag = s.get("magFilter")
            cache[key] = (len(cache), Texture(self.image(t["source"], srgb), wrap_s, wrap_t, mag))
        return cache[key][0]


# ============================================================ materials


def _texture_ref(reader, info, srgb, cache, strength_key=None):
    """A :class:`TextureRef` for a glTF textureInfo (None when absent)."""
    if info is None:
        return None
    transform, texcoord = texture_transform(info)  # KHR_texture_transform (pbrkit.io.gltf_extensions)
    value = info.get(strength_key) if strength_key is not None else None
    return TextureRef(reader.texture(info["index"], srgb, cache), texcoord, 1.0 if value is None else float(value),
                      transform)


def _gltf_material(reader, index, cache):
    if index is None:
        return SurfaceMaterial(MaterialSpec(name="gltf-default", base_color=(1.0, 1.0, 1.0), metallic=1.0,
                                            roughness=1.0))
    m = reader.items("materials")[index]
    pbr = m.get("pbrMetallicRoughness") or {}
    bc = pbr.get("baseColorFactor") or (1.0, 1.0, 1.0, 1.0)
    metallic = 1.0 if pbr.get("metallicFactor") is None else pbr["metallicFactor"]
    roughness = 1.0 if pbr.get("roughnessFactor") is None else pbr["roughnessFactor"]
    bct = _texture_ref(reader, pbr.get("baseColorTexture"), True, cache)
    mrt = _texture_ref(reader, pbr.get("metallicRoughnessTexture"), False, cache)
    nt = _texture_ref(reader, m.get("normalTexture"), False, cache, "scale")
    ot = _texture_ref(reader, m.get("occlusionTexture"), False, cache, "strength")
    et = _texture_ref(reader, m.get("emissiveTexture"), True, cache)
    emissive = np.asarray(m.get("emissiveFactor") or (0.0, 0.0, 0.0), dtype=float)
    strength = ((m.get("extensions") or {}).get("KHR_materials_emissive_strength") or {}).get("emissiveStrength")
    strength = 1.0 if strength is None else float(strength)
    ext = m.get("extensions") or {}
    khr = material_extension_values(ext, reader.notes, index)  # KHR_materials_* (pbrkit.io.gltf_materials)
    if ext.get(UNLIT) is not None:  # the base colour as emission over a black, non-reflecting surface
        khr.update(unlit_material(bc))
        et, bct, mrt, emissive, strength = bct, None, None, np.ones(3), 1.0
    alpha_mode = m.get("alphaMode") or "OPAQUE"  # cutouts and coverage (pbrkit.rendering.alpha)
    alpha_cutoff = 0.5 if m.get("alphaCutoff") is None else float(m["alphaCutoff"])
    alpha_texture = _texture_ref(reader, pbr.get("baseColorTexture"), True, cache) if alpha_mode != "OPAQUE" \
        else None
    name = m.get("name")  # shown in messages: a short printable one only
    if not (isinstance(name, str) and name and name.isprintable() and len(name) <= 64):
        name = f"gltf-material-{index}"
    values = dict(base_color=tuple(float(x) for x in bc[:3]), metallic=float(metallic), roughness=float(roughness),
                  emissive=tuple(emissive * strength), double_sided=bool(m.get("doubleSided")))
    if ext.get(UNLIT) is not None:
        values.update(emissive=khr.pop("emissive"))
    values.update(khr)
    try:
        spec = MaterialSpec(name=name, **values)
    except ValueError as exc:
        reader.fail(f"materials[{index}]: {exc}")
    # the KHR_materials extension textures (pbrkit.io.gltf_materials.TEXTURE_USES)
    extension_textures = tuple((use, _texture_ref(reader, (ext.get(use[0]) or {}).get(use[1]), use[2], cache,
                                                  "scale" if use[3] == "coat_normal" else None))
                               for use in TEXTURE_USES if (ext.get(use[0]) or {}).get(use[1]) is not None)
    return SurfaceMaterial(spec, bct, mrt, nt, ot, et, alpha_mode=alpha_mode, alpha_cutoff=alpha_cutoff,
                           alpha=float(bc[3]) if len(bc) > 3 else 1.0, alpha_texture=alpha_texture,
                           extension_textures=extension_textures, unlit=ext.get(UNLIT) is not None)


def _texture_refs(material):
    """(name, TextureRef) of the textures a material uses (the baseColorTexture a second
    time for its alpha channel under alphaMode MASK or BLEND)."""
    names = ("baseColorTexture", "metallicRoughnessTexture", "normalTexture", "occlusionTexture", "emissiveTexture",
             "baseColorTexture")
    refs = (material.base_color_texture, material.metallic_roughness_texture, material.normal_texture,
            material.occlusion_texture, material.emissive_texture, material.alpha_texture)
    return [(n, r) for n, r in zip(names, refs) if r is not None] + [
        (f"extensions.{use[0]}.{use[1]}", ref) for use, ref in material.extension_textures]


# ============================================================ geometry


def _node_matrix(node):
    if node.get("matrix") is not None:
        return np.asarray(node["matrix"], dtype=float).reshape(4, 4).T  # column-major in glTF
    q = np.asarray(node.get("rotation") or (0.0, 0.0, 0.0, 1.0), dtype=float)
    return trs_matrix(node.get("translation") or (0.0, 0.0, 0.0), q / np.linalg.norm(q),
                      node.get("scale") or (1.0, 1.0, 1.0))


def _triangles(mode, idx):
    if mode in (None, 4):
        if idx.size % 3:
            raise ValueError("TRIANGLES primitive with an index count not divisible by 3")
        return idx.reshape(-1, 3)
    if mode == 5:  # TRIANGLE_STRIP (glTF 2.0 sec. 3.7.2.1): alternate winding
        k = np.arange(max(idx.size - 2, 0))
        a = idx[k]
        b = np.where(k % 2 == 0, idx[k + 1], idx[k + 2])
        c = np.where(k % 2 == 0, idx[k + 2], idx[k + 1])
        return np.stack([a, b, c], axis=1)
    if mode == 6:  # TRIANGLE_FAN
        k = np.arange(1, max(idx.size - 1, 1))
        return np.stack([np.full(k.size, idx[0]), idx[k], idx[k + 1]], axis=1) if idx.size >= 3 else \
            np.zeros((0, 3), np.int64)
    return None


@dataclass
class _Primitive:
    """One primitive's data in its node's space."""

    positions: np.ndarray
    normals: np.ndarray | None
    tangents: np.ndarray | None
    texcoords: list
    triangles: np.ndarray
    colors: np.ndarray | None = None   # (V, 3) COLOR_0's RGB, or (V, 4) with its alpha (VEC4)


def _read_primitive(reader, prim, where):
    """The checked data of a triangle primitive, or None (with a note) for points and lines."""
    attrs = prim["attributes"]
    if attrs.get("POSITION") is None:
        reader.fail(f"{where} has no POSITION attribute")
    pos = reader.attribute(attrs["POSITION"], "POSITION", f"{where}.attributes.POSITION")
    count = pos.shape[0]
    if prim.get("indices") is not None:
        idx = reader.attribute(prim["indices"], "indices", f"{where}.indices")
        if idx.size and idx.max() >= count:
            reader.fail(f"{where}.indices has index {int(idx.max())}, but POSITION has only {count} vertices")
    else:
        idx = np.arange(count, dtype=np.int64)
    try:
        tri = _triangles(prim.get("mode"), idx)
    except ValueError as exc:
        reader.fail(f"{where}: {exc}")
    if tri is None:
        reader.notes.append(f"{where}: mode {prim.get('mode')} (points/lines) skipped")
        return None

    def read(name, semantic, width):
        if attrs.get(name) is None:
            return None
        data = reader.attribute(attrs[name], semantic, f"{where}.attributes.{name}")
        if data.shape[0] != count:
            reader.fail(f"{where}.attributes.{name} has {data.shape[0]} elements, POSITION has {count} (every "
                        "attribute of a primitive has the same count)")
        return data[:, :width]

    texcoords = []
    while attrs.get(f"TEXCOORD_{len(texcoords)}") is not None:
        texcoords.append(read(f"TEXCOORD_{len(texcoords)}", "TEXCOORD", 2))
    colors = None
    if attrs.get("COLOR_0") is not None:  # VEC3 or VEC4 (glTF 2.0, "Meshes"); RGB multiplies the base colour
        a = reader.items("accessors")[attrs["COLOR_0"]]
        colors = read("COLOR_0", "COLOR4" if a.get("type") == "VEC4" else "COLOR3",
                      4 if a.get("type") == "VEC4" else 3)
        if np.any((colors < 0.0) | (colors > 1.0)):
            reader.fail(f"{where}.attributes.COLOR_0 has values outside [0, 1]")
    return _Primitive(pos, read("NORMAL", "NORMAL", 3), read("TANGENT", "TANGENT", 4), texcoords, tri, colors)


def _flat_shaded(p):
    """glTF 2.0 sec. 3.7.2.1: flat normals when NORMAL is absent -> unshared vertices."""
    corners = p.triangles.reshape(-1)
    pos = p.positions[corners]
    tri = np.arange(pos.shape[0], dtype=np.int64).reshape(-1, 3)
    fn = np.cross(pos[tri[:, 1]] - pos[tri[:, 0]], pos[tri[:, 2]] - pos[tri[:, 0]])
    fn /= np.maximum(np.linalg.norm(fn, axis=1, keepdims=True), 1e-300)
    return _Primitive(pos, np.repeat(fn, 3, axis=0), None if p.tangents is None else p.tangents[corners],
                      [t[corners] for t in p.texcoords], tri, None if p.colors is None else p.colors[corners])


def _world_mesh(p, world, material_index):
    """A :class:`Mesh` of primitive data ``p`` under the 4 x 4 transform ``world``."""
    m3 = world[:3, :3]
    det = float(np.linalg.det(m3))
    normal_matrix = np.linalg.inv(m3).T
    wpos = p.positions @ m3.T + world[:3, 3]
    wn = p.normals @ normal_matrix.T
    wn /= np.maximum(np.linalg.norm(wn, axis=1, keepdims=True), 1e-300)
    wt = None
    if p.tangents is not None:
        t3 = p.tangents[:, :3] @ m3.T
        t3 /= np.maximum(np.linalg.norm(t3, axis=1, keepdims=True), 1e-300)
        w = np.where(p.tangents[:, 3] < 0.0, -1.0, 1.0) * (1.0 if det > 0 else -1.0)
        wt = np.concatenate([t3, w[:, None]], axis=1)
    colors = None if p.colors is None else np.ascontiguousarray(p.colors[:, :3])
    alphas = None if p.colors is None or p.colors.shape[1] < 4 else np.ascontiguousarray(p.colors[:, 3])
    return Mesh(wpos, wn, p.triangles.astype(np.int64), material_index, tuple(p.texcoords), wt, colors, alphas)


def _scene_roots(reader):
    """The root nodes of the default scene (scene 0 without ``scene``; every parentless
    node when the file has no scenes) and a phrase naming where they come from."""
    scenes = reader.items("scenes")
    nodes = reader.items("nodes")
    if scenes:
        k = reader.doc.get("scene") or 0
        return list(scenes[k].get("nodes") or []), f"scene {k}"
    children = {c for n in nodes for c in (n.get("children") or [])}
    return [i for i in range(len(nodes)) if i not in children], "the file's root nodes"


def load_gltf(path, transform=None, allow_roots=()):
    """Read a glTF 2.0 file into world-space triangle meshes, materials and lights.

    ``transform`` (4 x 4) is applied on top of the file's node transforms.  The
    files its URIs name must lie under its own folder or one of ``allow_roots``
    (:mod:`pbrkit.io.gltf_resources`).  Problems (module docstring) raise
    :class:`pbrkit.core.errors.InputError` naming the file."""
    reader = _GltfReader(path, allow_roots)
    try:
        with np.errstate(all="ignore"):  # overflows and the like are detected and reported by _load
            return _load(reader, np.eye(4) if transform is None else np.asarray(transform, dtype=float))
    except MemoryError:
        raise InputError("not enough memory to load this glTF file", path) from None


def _mesh_size(reader, roots):
    """(vertices, triangles) of every mesh the scene's nodes place, from the accessors'
    counts alone (glTF 2.0 sec. 3.7.2: a primitive's vertex count is its POSITION
    count, its triangles a third of its indices for TRIANGLES, two fewer for strips and
    fans; without NORMAL every triangle gets three vertices of its own)."""
    nodes, meshes, accessors = reader.items("nodes"), reader.items("meshes"), reader.items("accessors")
    vertices = triangles = 0
    stack = list(roots)
    while stack:  # the nodes form a forest (checked): every node is met once
        node = nodes[stack.pop()]
        stack.extend(node.get("children") or [])
        for prim in meshes[node["mesh"]]["primitives"] if node.get("mesh") is not None else ():
            position = prim["attributes"].get("POSITION")
            if position is None:
                continue
            v = accessors[position]["count"]
            n = v if prim.get("indices") is None else accessors[prim["indices"]]["count"]
            mode = prim.get("mode")
            t = n // 3 if mode in (None, 4) else max(n - 2, 0) if mode in (5, 6) else 0
            vertices += v + (3 * t if prim["attributes"].get("NORMAL") is None else 0)
            triangles += t
    return vertices, triangles


def _check_mesh_memory(reader, roots, origin):
    """Refuse a file whose meshes would not fit in memory, before reading them
    (:data:`BYTES_PER_VERTEX`, :data:`BYTES_PER_TRIANGLE`)."""
    vertices, triangles = _mesh_size(reader, roots)
    reader.check_allocation(vertices * BYTES_PER_VERTEX + triangles * BYTES_PER_TRIANGLE,
                            f"the meshes of {origin} ({vertices:,} vertices, {triangles:,} triangles)")


def _load(reader, top):
    roots, origin = _scene_roots(reader)
    _check_mesh_memory(reader, roots, origin)
    texture_cache = {}
    materials = [_gltf_material(reader, i, texture_cache) for i in range(len(reader.items("materials")))]
    state = {"default_material": None}
    meshes = []
    lights = []
    light_defs = ((reader.doc.get("extensions") or {}).get("KHR_lights_punctual") or {}).get("lights") or []
    stack = [(i, top) for i in roots]
    while stack:
        ni, parent = stack.pop()
        node = reader.items("nodes")[ni]
        world = parent @ _node_matrix(node)
        if not np.all(np.isfinite(world)):
            reader.fail(f"nodes[{ni}]: its transform (with its parents') is not finite")
        stack.extend((c, world) for c in (node.get("children") or []))
        ext = (node.get("extensions") or {}).get("KHR_lights_punctual")
        if ext is not None:
            lights.append(_gltf_light(reader, light_defs, ext["light"], world))
        if node.get("mesh") is not None:
            meshes.extend(_node_meshes(reader, ni, node["mesh"], world, materials, texture_cache, state))
    if not meshes and not lights:
        reader.fail(_nothing_to_render(reader, origin))
    textures = [t for _, t in sorted(texture_cache.values(), key=lambda e: e[0])]
    for m in materials:
        m.textures = textures
    return GltfAsset(meshes, materials, lights, reader.notes)


def _nothing_to_render(reader, origin):
    """Why a file gave no meshes (and no lights)."""
    if not reader.items("meshes"):
        return "no meshes to render (the file has no meshes)"
    return f"no meshes to render: no node of {origin} holds a mesh with triangles"


def _node_meshes(reader, ni, mesh_index, world, materials, cache, state):
    """The world-space meshes of the primitives of meshes[mesh_index], placed by nodes[ni]."""
    m3 = world[:3, :3]
    if float(np.linalg.det(m3)) == 0.0:
        reader.notes.append(f"node {ni}: singular transform, mesh skipped")
        return []
    out = []
    for pi, prim in enumerate(reader.items("meshes")[mesh_index]["primitives"]):
        where = f"meshes[{mesh_index}].primitives[{pi}]"
        p = _read_primitive(reader, prim, where)
        if p is None:
            continue
        if p.triangles.shape[0] == 0:
            reader.notes.append(f"{where}: no triangles, skipped")
            continue
        if prim.get("targets"):
            reader.notes.append(f"mesh {mesh_index}: morph targets ignored (base shape rendered)")
        if p.normals is None:
            p = _flat_shaded(p)
        mat_index = prim.get("material")
        if mat_index is None:
            if state["default_material"] is None:
                materials.append(_gltf_material(reader, None, cache))
                state["default_material"] = len(materials) - 1
            mat_index = state["default_material"]
        material = materials[mat_index]
        for name, ref in _texture_refs(material):
            if ref.texcoord >= len(p.texcoords):
                reader.fail(f"{where}: materials[{mat_index}].{name} uses TEXCOORD_{ref.texcoord}, which the "
                            "primitive lacks")
        coat_ref = next((ref for use, ref in material.extension_textures if use[3] == "coat_normal"), None)
        if (material.normal_texture is not None or coat_ref is not None) and p.tangents is None:
            # tangents along the UVs the normal texture (else the clearcoatNormalTexture) is looked up
            # at (its KHR_texture_transform applied: an affine map, exact per vertex), as the Khronos
            # sample viewer derives them
            ref = material.normal_texture if material.normal_texture is not None else coat_ref
            p.tangents = mikktspace_tangents(p.positions, p.normals, ref.lookup_uv(p.texcoords[ref.texcoord]),
                                             p.triangles)
        if np.any(np.asarray(material.spec.anisotropy_strength) > 0.0) and p.tangents is None:
            # KHR_materials_anisotropy's direction is relative to the tangents: MikkTSpace's along
            # TEXCOORD_0 (the README asks for TANGENT or a normal texture's), else the frame of
            # pbrkit.brdf.bxdf.tangent_frame (noted)
            if p.texcoords:
                p.tangents = mikktspace_tangents(p.positions, p.normals, p.texcoords[0], p.triangles)
            else:
                reader.notes.append(f"{where}: materials[{mat_index}] is anisotropic but the primitive has no "
                                    "TANGENT or TEXCOORD_0; its anisotropy follows the parallels about +Y")
        mesh = _world_mesh(p, world, mat_index)
        if not np.all(np.isfinite(mesh.positions)) or np.abs(mesh.positions).max() > np.finfo(np.float32).max:
            reader.fail(f"{where}: its vertices placed by nodes[{ni}] are not finite")
        out.append(mesh)
    return out


def _gltf_light(reader, defs, index, world):
    d = defs[index]
    position = world[:3, 3]
    direction = world[:3, :3] @ np.array([0.0, 0.0, -1.0])
    spot = d.get("spot") or {}
    try:
        return Light(type=d["type"], color=tuple(d.get("color") or (1.0, 1.0, 1.0)),
                     intensity=1.0 if d.get("intensity") is None else d["intensity"],
                     position=tuple(position), direction=tuple(direction), range=d.get("range"),
                     inner_cone_angle=0.0 if spot.get("innerConeAngle") is None else spot["innerConeAngle"],
                     outer_cone_angle=np.pi / 4.0 if spot.get("outerConeAngle") is None else spot["outerConeAngle"])
    except (TypeError, ValueError) as exc:
        reader.fail(f"KHR_lights_punctual light {index}: {exc}")
